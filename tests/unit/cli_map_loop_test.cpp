// gvio run --two-pass on a simulated loop (issue 8: "two passes over the same place agree within
// 0.5 m median"): a circle driven once and then again for its first seconds, simulated with
// RTK-grade GNSS, run with the graph fusion at the simulator's ENU origin and lever arm; the map
// points of the first seconds of the drive and of the same place one loop later are compared.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <numbers>

#include "io/trajectory_io.hpp"
#include "support/fixtures.hpp"
#include "support/sim_truth.hpp"

namespace gvio::test {
namespace {
namespace fs = std::filesystem;

constexpr double kRadiusM = 20.0;  // loop radius
constexpr double kSpeedMps = 6.5;  // 23 km/h: 2.1 m/s^2 lateral, 0.33 rad/s yaw rate
constexpr double kRedriveS = 7.0;  // driven again after the loop closes
constexpr double kPassStartS = 1.0;
constexpr double kPassS = 5.0;  // each pass: 32 m of road

double loopPeriodS() {
  return 2.0 * std::numbers::pi * kRadiusM / kSpeedMps;
}

// Counter-clockwise from the origin heading east; body x forward, z up, at the demo drive's body
// height; 10 Hz poses, stamps from 0.
Trajectory loopDrive() {
  Trajectory t;
  const double omega = kSpeedMps / kRadiusM;
  const int n = static_cast<int>(std::ceil((loopPeriodS() + kRedriveS) * 10.0));
  for (int i = 0; i <= n; ++i) {
    const double a = omega * 0.1 * i;
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    T.translation() = Eigen::Vector3d(kRadiusM * std::sin(a), kRadiusM * (1.0 - std::cos(a)), 0.93);
    t.poses.push_back(T);
    t.t_ns.push_back(static_cast<std::int64_t>(i) * 100'000'000LL);
  }
  return t;
}

TEST(CliMapLoop, TwoPassesOverTheSamePlaceAgreeWithinHalfAMetreMedian) {
  TempDir tmp("cli_map_loop");
  io::writeTum(tmp.path() / "loop.tum", loopDrive());
  const fs::path sim = tmp.path() / "sim", run = tmp.path() / "run";
  const CommandResult simulated =
      runGvio(fmt::format("simulate --trajectory {} --gnss-noise rtk --seed 3 --out {} -q",
                          quoted(tmp.path() / "loop.tum"), quoted(sim)));
  ASSERT_EQ(simulated.exit_code, 0) << simulated.err;
  const double pass2_start_s = kPassStartS + loopPeriodS();
  const std::string passes =
      fmt::format("{:.3f}:{:.3f},{:.3f}:{:.3f}", kPassStartS, kPassStartS + kPassS, pass2_start_s,
                  pass2_start_s + kPassS);
  const CommandResult r =
      runGvio(fmt::format("run --dataset {} --out {} --no-progress --gnss graph {} --two-pass {}",
                          quoted(sim), quoted(run), readSimTruth(sim).runOptions(), passes));
  ASSERT_EQ(r.exit_code, 0) << r.err;

  const auto report = nlohmann::json::parse(readText(run / "report.json"));
  const auto j = report["map"]["two_pass"];
  ASSERT_TRUE(j.is_object()) << report["map"].dump(2);
  EXPECT_EQ(report["map"]["frame"], "enu");
  EXPECT_GE(j["pass1"]["keyframes"].get<int>(), 5);
  EXPECT_GE(j["pass2"]["keyframes"].get<int>(), 5);
  EXPECT_GT(j["pass1"]["points"].get<int>(), 10000);
  EXPECT_GT(j["pass2"]["points"].get<int>(), 10000);
  // The second pass sees what the first saw: most of its points have a pass-1 point within the
  // overlap radius (1 m, twice the bound, so a map that disagrees by more fails the median).
  EXPECT_GE(j["overlap_fraction"].get<double>(), 0.5);
  EXPECT_EQ(j["overlap_radius_m"], 1.0);
  EXPECT_LE(j["median_m"].get<double>(), 0.5) << j.dump(2);
  EXPECT_EQ(j["meets_target"], j["median_m"].get<double>() <= 0.5);
  std::cout << fmt::format(
      "two passes ({}): {} / {} keyframes, {} / {} points, overlap {:.1f} %, median {:.3f} m, "
      "mean {:.3f} m, p90 {:.3f} m; fused APE {:.3f} m\n",
      passes, j["pass1"]["keyframes"].get<int>(), j["pass2"]["keyframes"].get<int>(),
      j["pass1"]["points"].get<int>(), j["pass2"]["points"].get<int>(),
      100.0 * j["overlap_fraction"].get<double>(), j["median_m"].get<double>(),
      j["mean_m"].get<double>(), j["p90_m"].get<double>(),
      report["evaluation_fused"]["ape_none"]["rmse"].get<double>());
}

TEST(CliMapLoop, BadTwoPassExitsTwoWithOneLine) {
  for (const char* bad : {"5:1,6:8", "1:2", "1:2,3:x", "1:2,3:"}) {
    const CommandResult r =
        runGvio(fmt::format("run --dataset /nonexistent --two-pass {} --no-progress", bad));
    EXPECT_EQ(r.exit_code, 2) << bad;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find("--two-pass"), std::string::npos) << r.err;
  }
}

}  // namespace
}  // namespace gvio::test
