// Real receivers through the built binary (issue 58): `gvio simulate --gnss-errors-from` replays a
// solution's errors against a reference CSV on the simulated drive (gaps, quality and the errors
// themselves kept), and `gvio eval` reads GNSS solutions and reference CSVs as position tracks,
// with horizontal / vertical errors overall and per quality flag.
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "fusion/geodesy.hpp"
#include "io/gps_time.hpp"
#include "io/nmea.hpp"
#include "io/text.hpp"
#include "io/trajectory_io.hpp"
#include "sim/gnss_synth.hpp"
#include "support/fixtures.hpp"

namespace gvio::test {
namespace {
using testing::HasSubstr;
namespace fs = std::filesystem;

constexpr std::int64_t kS = 1'000'000'000;
constexpr int kWeek = 2270;
constexpr double kTow0 = 194670.0;  // 2023-07-11 06:04:30 GPST
const fusion::Lla kOrigin{35.1653, 136.8814, 41.0};
// The receiver's error at every epoch (east, north, up).
const Eigen::Vector3d kError(1.5, -0.5, 2.0);

// The rover's single-point fix at t seconds after kTow0 on the drive north: Q 5 (single),
// 9 satellites, 2 m / 4 m sigmas, the position off by kError.
GnssFix roverFix(const fusion::EnuFrame& enu, double t) {
  const fusion::Lla f = enu.toLla(Eigen::Vector3d(0.0, 10.0 * t, 0.0) + kError);
  GnssFix fix;
  fix.t_ns = io::gpstToUtcNs(
      io::gpsWeekTowToGpstUnixNs(kWeek, static_cast<std::int64_t>((kTow0 + t) * 1e9 + 0.5)));
  fix.lat_deg = f.lat_deg;
  fix.lon_deg = f.lon_deg;
  fix.h_ellipsoid_m = f.h_ellipsoid_m;
  fix.sigma_h_m = 2.0;
  fix.sigma_v_m = 4.0;
  fix.num_sats = 9;
  return fix;
}

// A car driving north at 10 m/s from kOrigin for 6 s, at 5 Hz: the reference CSV; and its RTKLIB
// single-point solution at 1 Hz (GPST calendar), each epoch off by kError, the epoch at 3 s
// missing (a gap).
class CliRealGnss : public ::testing::Test {
 protected:
  void SetUp() override {
    const fusion::EnuFrame enu(kOrigin);
    std::string csv =
        "GPS TOW (s),GPS Week,Latitude (deg),Longitude (deg),Ellipsoid Height (m),Roll "
        "(deg),Pitch (deg),Heading (deg),East Velocity (m/s),North Velocity (m/s),Up Velocity "
        "(m/s)\n";
    std::vector<GnssFix> fixes;
    for (int i = 0; i <= 30; ++i) {
      const double t = 0.2 * i;
      const fusion::Lla p = enu.toLla(Eigen::Vector3d(0.0, 10.0 * t, 0.0));
      csv += fmt::format("{:.1f},{},{:.10f},{:.10f},{:.4f},0.0,0.0,0.0,0.0,10.0,0.0\n", kTow0 + t,
                         kWeek, p.lat_deg, p.lon_deg, p.h_ellipsoid_m);
      if (i % 5 != 0 || i == 15) continue;
      fixes.push_back(roverFix(enu, t));
    }
    const std::string pos = sim::toRtklibPos(fixes);
    writeText(p("reference.csv"), csv);
    writeText(p("rover.pos"), pos);
  }
  fs::path p(const std::string& name) const { return dir_.path() / name; }

  TempDir dir_{"clirealgnss"};
};

TEST_F(CliRealGnss, SimulateReplaysTheSolutionsErrorsAndGaps) {
  const auto r = runGvio("simulate --trajectory " + quoted(p("reference.csv")) +
                         " --gnss-errors-from " + quoted(p("rover.pos")) +
                         " --set 'sim.gnss_lever_arm_m=[0,0,0]' --camera mono --seconds 5.5 "
                         "--no-progress --out " +
                         quoted(p("sim")));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr(" 5 GNSS fixes"));  // 0, 1, 2, 4, 5 s: the gap at 3 s stays
  const io::NmeaLog log = io::readNmea(p("sim/gnss/fixes.nmea"), io::ReaderConfig{});
  ASSERT_EQ(log.fixes.size(), 5U);
  const Trajectory truth = io::readTum(p("sim/groundtruth.tum"));
  // The drive is where the reference was recorded: its first epoch is the origin.
  const fusion::EnuFrame enu(kOrigin);
  for (const GnssFix& fix : log.fixes) {
    EXPECT_EQ(fix.quality, 1);
    const auto it = std::lower_bound(truth.t_ns.begin(), truth.t_ns.end(), fix.t_ns);
    ASSERT_NE(it, truth.t_ns.end());
    ASSERT_EQ(*it, fix.t_ns) << "fixes at the receiver's epochs";
    const Eigen::Vector3d p_true =
        truth.poses[static_cast<std::size_t>(it - truth.t_ns.begin())].translation();
    const Eigen::Vector3d error = enu.toEnu({fix.lat_deg, fix.lon_deg, fix.h_ellipsoid_m}) - p_true;
    EXPECT_LT((error - kError).norm(), 0.01) << "at " << io::formatSeconds(fix.t_ns);
  }
  EXPECT_EQ(log.fixes[3].t_ns - log.fixes[2].t_ns, 2 * kS);
  EXPECT_THAT(readText(p("sim/sim.yaml")), HasSubstr("gnss_errors_from: rover.pos"));

  // Without a georeferenced trajectory there is nothing to take errors against.
  Trajectory tum;
  for (int i = 0; i < 20; ++i) {
    tum.t_ns.push_back(i * 100'000'000LL);
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation().x() = i;
    tum.poses.push_back(T);
  }
  io::writeTum(p("drive.tum"), tum);
  const auto bad =
      runGvio("simulate --trajectory " + quoted(p("drive.tum")) + " --gnss-errors-from " +
              quoted(p("rover.pos")) + " --no-progress --out " + quoted(p("sim2")));
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_THAT(bad.err, HasSubstr("--gnss-errors-from needs a georeferenced --trajectory"));
  EXPECT_EQ(std::count(bad.err.begin(), bad.err.end(), '\n'), 1) << bad.err;
}

TEST_F(CliRealGnss, EvalReadsSolutionsAndReferencesAsPositionTracks) {
  const auto r =
      runGvio("eval --ref " + quoted(p("reference.csv")) + " --est " + quoted(p("rover.pos")) +
              " --json " + quoted(p("e.json")) + " --errors-csv " + quoted(p("e.csv")));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("horizontal error (m)"));
  const auto j = nlohmann::json::parse(readText(p("e.json")));
  EXPECT_EQ(j["ape"]["n"].get<int>(), 6);
  EXPECT_NEAR(j["horizontal"]["rmse"].get<double>(), std::hypot(1.5, 0.5), 1e-3);
  EXPECT_NEAR(j["vertical"]["median"].get<double>(), 2.0, 1e-3);
  ASSERT_EQ(j["by_quality"].size(), 1U);
  EXPECT_EQ(j["by_quality"][0]["name"], "single");
  EXPECT_EQ(j["by_quality"][0]["horizontal"]["n"].get<int>(), 6);
  const std::string csv = readText(p("e.csv"));
  EXPECT_THAT(csv, HasSubstr("t_s,ape,dx_m,dy_m,dz_m,quality\n"));
  const auto lines = io::splitDelimited(csv, '\n');
  ASSERT_GE(lines.size(), 7U);
  for (std::size_t i = 1; i < 7; ++i) {
    const auto f = io::splitDelimited(lines[i], ',');
    ASSERT_EQ(f.size(), 6U) << lines[i];
    EXPECT_NEAR(std::stod(std::string(f[2])), 1.5, 1e-3);
    EXPECT_NEAR(std::stod(std::string(f[3])), -0.5, 1e-3);
    EXPECT_NEAR(std::stod(std::string(f[4])), 2.0, 1e-3);
    EXPECT_EQ(f[5], "1");
  }

  // A local trajectory against a GNSS track needs its frame's origin.
  Trajectory tum;
  const fusion::EnuFrame enu(kOrigin);
  for (int i = 0; i <= 30; ++i) {
    const std::int64_t gpst =
        io::gpsWeekTowToGpstUnixNs(kWeek, static_cast<std::int64_t>((kTow0 + 0.2 * i) * 1e9 + 0.5));
    tum.t_ns.push_back(io::gpstToUtcNs(gpst));
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = Eigen::Vector3d(0.3, 2.0 * i, 0.0);
    tum.poses.push_back(T);
  }
  io::writeTum(p("est.tum"), tum);
  const auto no_origin =
      runGvio("eval --ref " + quoted(p("reference.csv")) + " --est " + quoted(p("est.tum")));
  EXPECT_EQ(no_origin.exit_code, 2);
  EXPECT_THAT(no_origin.err, HasSubstr("give that frame's ENU origin with --origin"));
  const auto with_origin =
      runGvio(fmt::format("eval --ref {} --est {} --origin {:.10f},{:.10f},{} --json {}",
                          quoted(p("reference.csv")), quoted(p("est.tum")), kOrigin.lat_deg,
                          kOrigin.lon_deg, kOrigin.h_ellipsoid_m, quoted(p("o.json"))));
  ASSERT_EQ(with_origin.exit_code, 0) << with_origin.err;
  const auto o = nlohmann::json::parse(readText(p("o.json")));
  EXPECT_EQ(o["ape"]["n"].get<int>(), 31);
  EXPECT_NEAR(o["horizontal"]["max"].get<double>(), 0.3, 1e-3);
  EXPECT_TRUE(o["by_quality"].empty());
  const auto full = runGvio("eval --ref " + quoted(p("reference.csv")) + " --est " +
                            quoted(p("rover.pos")) + " --relation full");
  EXPECT_EQ(full.exit_code, 2);
  EXPECT_THAT(full.err, HasSubstr("positions only"));
  const auto bad_origin = runGvio("eval --ref " + quoted(p("reference.csv")) + " --est " +
                                  quoted(p("est.tum")) + " --origin 95,1,2");
  EXPECT_EQ(bad_origin.exit_code, 2);
  EXPECT_THAT(bad_origin.err, HasSubstr("--origin '95,1,2': expected lat,lon,h"));
}

// The same receiver's fixes as a logger writes them in NMEA (GGA + RMC + GST, every RMC with a
// wrong checksum, as a real reference logger's) and in gvio's GNSS CSV, by the simulator's own
// writers: gvio eval reads both, the NMEA log refused until told
// `--set dataset.nmea_checksum=warn`, as gvio run and gvio simulate are.
TEST_F(CliRealGnss, EvalAndSimulateReadNmeaAndCsvSolutionsAsRunDoes) {
  const fusion::EnuFrame enu(kOrigin);
  std::vector<GnssFix> fixes;
  for (int i = 0; i <= 30; i += 5) {
    if (i == 15) continue;  // the gap
    GnssFix fix = roverFix(enu, 0.2 * i);
    fix.hdop = 1.0;
    fixes.push_back(fix);
  }
  const std::string log = sim::toNmeaLog(fixes);
  std::string nmea;
  for (std::string_view line : io::splitDelimited(log, '\n')) {
    std::string sentence(line);
    if (sentence.starts_with("$GPRMC")) {  // the checksum's last digit, before the "\r"
      char& digit = sentence[sentence.find('*') + 2];
      digit = digit == '0' ? '1' : '0';
    }
    if (!sentence.empty()) nmea += sentence + "\n";
  }
  const std::string csv = sim::toGnssCsv(fixes);
  writeText(p("rover.nmea"), nmea);
  writeText(p("rover.csv"), csv);
  const std::string eval = "eval --ref " + quoted(p("reference.csv")) + " --est ";

  const auto refused = runGvio(eval + quoted(p("rover.nmea")));
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_THAT(refused.err, HasSubstr("6 of 6 RMC sentences failed their checksum"));
  EXPECT_THAT(refused.err, HasSubstr("dataset.nmea_checksum: warn"));
  EXPECT_EQ(std::count(refused.err.begin(), refused.err.end(), '\n'), 1) << refused.err;
  for (const std::string& est : {std::string("rover.nmea"), std::string("rover.csv")}) {
    const auto r = runGvio(eval + quoted(p(est)) + " --set dataset.nmea_checksum=warn --json " +
                           quoted(p(est + ".json")));
    ASSERT_EQ(r.exit_code, 0) << est << ": " << r.err;
    const auto j = nlohmann::json::parse(readText(p(est + ".json")));
    EXPECT_EQ(j["ape"]["n"].get<int>(), 6) << est;
    EXPECT_NEAR(j["horizontal"]["rmse"].get<double>(), std::hypot(1.5, 0.5), 1e-3) << est;
    EXPECT_NEAR(j["vertical"]["median"].get<double>(), 2.0, 1e-3) << est;
  }

  // gvio simulate --gnss-errors-from reads the solution as gvio run would, --set included.
  const std::string simulate = "simulate --trajectory " + quoted(p("reference.csv")) +
                               " --gnss-errors-from " + quoted(p("rover.nmea")) +
                               " --set 'sim.gnss_lever_arm_m=[0,0,0]' --camera mono --seconds 5.5 "
                               "--no-progress --out ";
  const auto sim_refused = runGvio(simulate + quoted(p("sim_refused")));
  EXPECT_EQ(sim_refused.exit_code, 2);
  EXPECT_THAT(sim_refused.err, HasSubstr("RMC sentences failed their checksum"));
  const auto sim_warned =
      runGvio(simulate + quoted(p("sim_warned")) + " --set dataset.nmea_checksum=warn");
  ASSERT_EQ(sim_warned.exit_code, 0) << sim_warned.err;
  EXPECT_THAT(sim_warned.out, HasSubstr(" 5 GNSS fixes"));
}

// The real Nagoya files (../shared/data/nagoya2023): the rover's single-point and 5 Hz RTK
// solutions against the GNSS/INS reference give the figures data/README.md states (SPP median
// 2.9 m, RMS 14.3 m, p95 27 m; RTK 1,799 epochs called fixed with a median of 0.07 m).
TEST(CliRealGnssNagoya, TheSolutionsAgainstTheirReference) {
  const fs::path data = sharedData("nagoya2023");
  if (data.empty()) GTEST_SKIP() << "shared data absent: ../shared/data/nagoya2023";
  TempDir dir("clinagoya");
  const auto spp =
      runGvio("eval --ref " + quoted(data / "reference.csv") + " --est " +
              quoted(data / "rover_1Hz_spp.pos") + " --json " + quoted(dir.path() / "spp.json"));
  ASSERT_EQ(spp.exit_code, 0) << spp.err;
  const auto s = nlohmann::json::parse(readText(dir.path() / "spp.json"));
  EXPECT_EQ(s["horizontal"]["n"].get<int>(), 550);
  EXPECT_NEAR(s["horizontal"]["median"].get<double>(), 2.86, 0.01);
  EXPECT_NEAR(s["horizontal"]["rmse"].get<double>(), 14.33, 0.01);
  EXPECT_NEAR(s["horizontal"]["p95"].get<double>(), 27.17, 0.01);
  const auto rtk =
      runGvio("eval --ref " + quoted(data / "reference.csv") + " --est " +
              quoted(data / "rover_rtk.pos") + " --json " + quoted(dir.path() / "rtk.json"));
  ASSERT_EQ(rtk.exit_code, 0) << rtk.err;
  const auto r = nlohmann::json::parse(readText(dir.path() / "rtk.json"));
  ASSERT_EQ(r["by_quality"].size(), 2U);
  EXPECT_EQ(r["by_quality"][0]["name"], "RTK fixed");
  EXPECT_EQ(r["by_quality"][0]["horizontal"]["n"].get<int>(), 1799);
  EXPECT_NEAR(r["by_quality"][0]["horizontal"]["median"].get<double>(), 0.069, 0.001);
  EXPECT_EQ(r["by_quality"][1]["name"], "RTK float");
  EXPECT_EQ(r["by_quality"][1]["horizontal"]["n"].get<int>(), 3596);
}

}  // namespace
}  // namespace gvio::test
