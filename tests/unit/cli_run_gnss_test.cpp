// gvio run with GNSS fusion on simulated drives: georeferenced outputs (trajectory.tum,
// trajectory_lla.csv, georef.json), report fields, the fused accuracy against the ENU truth, and an
// outage reported as such.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>

#include "io/trajectory_io.hpp"
#include "support/fixtures.hpp"

namespace gvio::test {
namespace {
namespace fs = std::filesystem;

class CliRunGnss : public ::testing::Test {
 protected:
  static fs::path drive(const std::string& extra) {
    return cachedSimulation(fmt::format(
        "--trajectory {}/assets/demo/drive.tum --seconds 20 --seed 9 {}", GVIO_SOURCE_DIR, extra));
  }
  CommandResult run(const fs::path& dataset, const std::string& gnss, const fs::path& out) {
    return runGvio(fmt::format("run --dataset {} --out {} --no-progress --gnss {} {}",
                               quoted(dataset), quoted(out), gnss, kSimGeo));
  }
  static nlohmann::json report(const fs::path& out) {
    return nlohmann::json::parse(readText(out / "report.json"));
  }
  TempDir tmp_{"cli_run_gnss"};
};

TEST_F(CliRunGnss, GraphWritesGeoreferencedOutputs) {
  const fs::path out = tmp_.path() / "graph";
  const CommandResult r = run(drive(""), "graph", out);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Trajectory fused = io::readTum(out / "trajectory.tum");
  const Trajectory vio = io::readTum(out / "trajectory_vio.tum");
  EXPECT_EQ(fused.size(), vio.size());
  EXPECT_EQ(fused.t_ns, vio.t_ns);
  // trajectory_lla.csv: a header and one line per pose, near the simulator's origin.
  std::istringstream lla(readText(out / "trajectory_lla.csv"));
  std::string line;
  std::getline(lla, line);
  EXPECT_EQ(line.rfind("# t_s,lat_deg,lon_deg,h_ellipsoid_m", 0), 0U);
  std::size_t rows = 0;
  while (std::getline(lla, line)) {
    double t = 0, lat = 0, lon = 0;
    ASSERT_EQ(std::sscanf(line.c_str(), "%lf,%lf,%lf", &t, &lat, &lon), 3) << line;
    EXPECT_NEAR(lat, 48.98253, 0.01);
    EXPECT_NEAR(lon, 8.39035, 0.01);
    ++rows;
  }
  EXPECT_EQ(rows, fused.size());
  const auto georef = nlohmann::json::parse(readText(out / "georef.json"));
  EXPECT_EQ(georef["enu_origin"]["crs"], "EPSG:4979");
  EXPECT_DOUBLE_EQ(georef["enu_origin"]["lat_deg"].get<double>(), 48.98253);
  EXPECT_EQ(georef["utm"]["zone"], 32);
  EXPECT_EQ(georef["utm"]["epsg"], 32632);
  EXPECT_TRUE(georef.contains("T_enu_w"));
  const auto rep = report(out);
  EXPECT_EQ(rep["gnss"]["mode"], "graph");
  EXPECT_GE(rep["gnss"]["used"].get<int>(), 15);
  EXPECT_TRUE(rep["outages"].empty());
  // SPP-grade fixes (1.5 m / 3 m white + a 1 m Gauss-Markov bias) over 20 s: the fused error is a
  // few metres at most; the bound catches a broken frame or lever arm (tens of metres), and the
  // real accuracy figure comes from the KITTI-00 benchmark.
  ASSERT_TRUE(rep.contains("evaluation_fused")) << rep.dump();
  EXPECT_LT(rep["evaluation_fused"]["ape_none"]["rmse"].get<double>(), 6.0);
}

TEST_F(CliRunGnss, KfBaselineRunsAndReportsOutages) {
  const fs::path out = tmp_.path() / "kf";
  const CommandResult r = run(drive("--gnss-outage 6:13"), "kf", out);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto rep = report(out);
  EXPECT_EQ(rep["gnss"]["mode"], "kf");
  ASSERT_EQ(rep["outages"].size(), 1U) << rep["outages"].dump();
  EXPECT_GE(rep["outages"][0]["duration_s"].get<double>(), 6.0);
  EXPECT_TRUE(fs::exists(out / "trajectory.tum"));
  EXPECT_LT(rep["evaluation_fused"]["ape_none"]["rmse"].get<double>(), 8.0);
}

TEST_F(CliRunGnss, WithoutFixesTheRunIsPureVio) {
  // The real EuRoC clip has no GNSS at all.
  const fs::path euroc = sharedData("euroc_v101_micro");
  if (euroc.empty()) GTEST_SKIP() << "shared data absent: euroc_v101_micro";
  const fs::path out = tmp_.path() / "none";
  const CommandResult r = run(euroc, "graph", out);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_FALSE(fs::exists(out / "trajectory.tum"));
  EXPECT_TRUE(fs::exists(out / "trajectory_vio.tum"));
  EXPECT_EQ(report(out)["gnss"]["mode"], "off");
}

// --gnss-noise spp degrades an exact ("rtk"-free, noise none) simulated source: the fused error
// grows from centimetres to metres, report.json records the model and seed, and the same seed
// reproduces the same run. gnss_fixes.csv lists every fix with its outcome.
TEST_F(CliRunGnss, GnssNoiseDegradesAnAccurateSource) {
  const fs::path dataset = drive("--gnss-noise none");
  const fs::path exact = tmp_.path() / "exact";
  ASSERT_EQ(run(dataset, "graph", exact).exit_code, 0);
  const fs::path spp = tmp_.path() / "spp";
  const std::string noise = " --gnss-noise spp --seed 3";
  const CommandResult r = run(dataset, "graph" + noise, spp);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto rep_exact = report(exact), rep_spp = report(spp);
  EXPECT_FALSE(rep_exact["gnss"].contains("noise_added"));
  EXPECT_EQ(rep_spp["gnss"]["noise_added"]["model"], "spp");
  EXPECT_EQ(rep_spp["gnss"]["noise_added"]["seed"], 3);
  EXPECT_GT(rep_spp["gnss"]["noise_added"]["added_error_rms_m"].get<double>(), 1.0);
  const double ape_exact = rep_exact["evaluation_fused"]["ape_none"]["rmse"].get<double>();
  const double ape_spp = rep_spp["evaluation_fused"]["ape_none"]["rmse"].get<double>();
  EXPECT_LT(ape_exact, 0.3);
  EXPECT_GT(ape_spp, 2.0 * ape_exact);
  const fs::path again = tmp_.path() / "again";
  ASSERT_EQ(run(dataset, "graph" + noise, again).exit_code, 0);
  EXPECT_EQ(readText(again / "trajectory.tum"), readText(spp / "trajectory.tum"));

  std::istringstream fixes(readText(spp / "gnss_fixes.csv"));
  std::string line;
  std::getline(fixes, line);
  EXPECT_EQ(line, "t_s,e_m,n_m,u_m,status");
  int rows = 0, used = 0;
  while (std::getline(fixes, line)) {
    ++rows;
    used += line.ends_with(",used") ? 1 : 0;
  }
  EXPECT_EQ(rows, rep_spp["gnss"]["fixes"].get<int>() - rep_spp["gnss"]["skipped"].get<int>());
  EXPECT_EQ(used, rep_spp["gnss"]["used"].get<int>());
}

TEST_F(CliRunGnss, GnssNoiseFromAFileAndBadSpecs) {
  const fs::path dataset = drive("--gnss-noise none");
  const fs::path model = tmp_.path() / "noise.yaml";
  writeText(model,
            "white_h_m: 0.5\nwhite_v_m: 1.0\nbias_m: 0.0\noutlier_probability: 0\n"
            "reported_sigma_h_m: 0.5\nreported_sigma_v_m: 1.0\n");
  const fs::path out = tmp_.path() / "file";
  const CommandResult r = run(dataset, "graph --gnss-noise " + quoted(model), out);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(report(out)["gnss"]["noise_added"]["outliers"], 0);
  EXPECT_NEAR(report(out)["gnss"]["noise_added"]["white_h_m"].get<double>(), 0.5, 1e-12);

  const CommandResult missing = run(dataset, "graph --gnss-noise nosuch.yaml", tmp_.path() / "m");
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_NE(missing.err.find("nosuch.yaml"), std::string::npos) << missing.err;
  writeText(model, "bias_tau_s: -1\n");
  const CommandResult bad = run(dataset, "graph --gnss-noise " + quoted(model), tmp_.path() / "b");
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("bias_tau_s"), std::string::npos) << bad.err;
}

}  // namespace
}  // namespace gvio::test
