#include "sim/gnss_synth.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "fusion/gnss_covariance.hpp"
#include "io/nmea.hpp"
#include "io/reader_config.hpp"
#include "io/rtklib_pos.hpp"
#include "odometry/error.hpp"

namespace gvio::sim {
namespace {

namespace fs = std::filesystem;

constexpr std::int64_t kNs = 1'000'000'000;
constexpr std::int64_t kT0 = 1'700'000'000 * kNs;  // 2023-11-14 22:13:20 UTC
const fusion::EnuFrame kEnu(fusion::Lla{48.98253, 8.39035, 116.4});

// 10 m/s east from the ENU origin with a constant yaw (body x need not point along the motion).
std::function<Eigen::Isometry3d(std::int64_t)> straightEast(double yaw_rad = 0.0) {
  return [yaw_rad](std::int64_t t_ns) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    T.translation() = Eigen::Vector3d(10.0 * static_cast<double>(t_ns - kT0) * 1e-9, 0.0, 0.0);
    return T;
  };
}

std::vector<GnssSimFix> simulate(GnssNoise noise, double rate_hz, double duration_s,
                                 std::uint64_t seed = 42) {
  GnssSimOptions options;
  options.noise = noise;
  options.rate_hz = rate_hz;
  const auto t1 = kT0 + static_cast<std::int64_t>(duration_s * 1e9);
  return synthesizeGnss(straightEast(), kT0, t1, kEnu, options, seed);
}

std::vector<GnssFix> reported(const std::vector<GnssSimFix>& sims) {
  std::vector<GnssFix> fixes;
  for (const auto& s : sims) fixes.push_back(s.fix);
  return fixes;
}

// Sample standard deviation of one error axis over the fixes that are not outliers.
double inlierStd(const std::vector<GnssSimFix>& sims, int axis) {
  double sum = 0.0, sum_sq = 0.0;
  int n = 0;
  for (const auto& s : sims) {
    if (s.outlier) continue;
    sum += s.error_enu[axis];
    sum_sq += s.error_enu[axis] * s.error_enu[axis];
    ++n;
  }
  const double mean = sum / n;
  return std::sqrt((sum_sq - n * mean * mean) / (n - 1));
}

// Correlation of one error axis with itself `lag` fixes later, over pairs without an outlier.
double autocorrelation(const std::vector<GnssSimFix>& sims, int axis, std::size_t lag) {
  double sum_a = 0.0, sum_b = 0.0, sum_ab = 0.0, sum_aa = 0.0, sum_bb = 0.0;
  int n = 0;
  for (std::size_t i = 0; i + lag < sims.size(); ++i) {
    if (sims[i].outlier || sims[i + lag].outlier) continue;
    const double a = sims[i].error_enu[axis], b = sims[i + lag].error_enu[axis];
    sum_a += a, sum_b += b, sum_ab += a * b, sum_aa += a * a, sum_bb += b * b;
    ++n;
  }
  const double cov = sum_ab / n - (sum_a / n) * (sum_b / n);
  const double var_a = sum_aa / n - (sum_a / n) * (sum_a / n);
  const double var_b = sum_bb / n - (sum_b / n) * (sum_b / n);
  return cov / std::sqrt(var_a * var_b);
}

TEST(SimGnss, ParsesNoiseNames) {
  EXPECT_EQ(parseGnssNoise("none"), GnssNoise::kNone);
  EXPECT_EQ(parseGnssNoise("rtk"), GnssNoise::kRtk);
  EXPECT_EQ(parseGnssNoise("spp"), GnssNoise::kSpp);
  EXPECT_THROW(parseGnssNoise("dgps"), InvalidInput);
}

TEST(SimGnss, FixTimesAndRateValidation) {
  const auto sims = simulate(GnssNoise::kRtk, 5.0, 10.0);
  ASSERT_EQ(sims.size(), 51u);  // [t0, t0 + 10 s] inclusive at 5 Hz
  for (std::size_t i = 0; i < sims.size(); ++i) {
    EXPECT_EQ(sims[i].fix.t_ns, kT0 + static_cast<std::int64_t>(i) * kNs / 5);
  }
  for (const double bad : {0.0, 2.0, 20.0, -1.0}) {
    EXPECT_THROW(simulate(GnssNoise::kRtk, bad, 10.0), InvalidInput) << bad;
  }
}

TEST(SimGnss, NoneIsExactAtTheLeverArm) {
  GnssSimOptions options;
  options.noise = GnssNoise::kNone;
  options.lever_arm_b = Eigen::Vector3d(0.5, -0.3, 1.2);
  const double yaw = 0.7;
  const auto T_w_b_at = straightEast(yaw);
  const auto sims = synthesizeGnss(T_w_b_at, kT0, kT0 + 20 * kNs, kEnu, options, 1);
  ASSERT_EQ(sims.size(), 21u);
  for (const auto& s : sims) {
    const Eigen::Isometry3d T = T_w_b_at(s.fix.t_ns);
    const Eigen::Vector3d expected = T.translation() + T.linear() * options.lever_arm_b;
    EXPECT_LT((s.p_enu_true - expected).norm(), 1e-12);
    EXPECT_EQ(s.error_enu, Eigen::Vector3d::Zero());
    EXPECT_FALSE(s.outlier);
    const fusion::Lla lla{s.fix.lat_deg, s.fix.lon_deg, s.fix.h_ellipsoid_m};
    EXPECT_LT((kEnu.toEnu(lla) - expected).norm(), 1e-6);
    EXPECT_DOUBLE_EQ(s.fix.sigma_h_m, 0.01);
    EXPECT_DOUBLE_EQ(s.fix.sigma_v_m, 0.02);
    EXPECT_EQ(s.fix.quality, 4);
  }
}

TEST(SimGnss, ReportedPositionIsTruthPlusError) {
  for (const auto& s : simulate(GnssNoise::kSpp, 1.0, 100.0)) {
    const fusion::Lla lla{s.fix.lat_deg, s.fix.lon_deg, s.fix.h_ellipsoid_m};
    EXPECT_LT((kEnu.toEnu(lla) - (s.p_enu_true + s.error_enu)).norm(), 1e-6);
  }
}

TEST(SimGnss, RtkStatistics) {
  const auto sims = simulate(GnssNoise::kRtk, 10.0, 1000.0);
  ASSERT_EQ(sims.size(), 10001u);
  const double expected[3] = {0.02, 0.02, 0.04};
  for (int axis = 0; axis < 3; ++axis) {
    const double std_m = inlierStd(sims, axis);
    EXPECT_NEAR(std_m / expected[axis], 1.0, 0.1) << "axis " << axis << " std " << std_m;
  }
  for (const auto& s : sims) {
    EXPECT_FALSE(s.outlier);
    EXPECT_EQ(s.fix.quality, 4);
    EXPECT_DOUBLE_EQ(s.fix.sigma_h_m, 0.02);
    EXPECT_DOUBLE_EQ(s.fix.sigma_v_m, 0.04);
    EXPECT_GE(s.fix.hdop, 0.6);
    EXPECT_LE(s.fix.hdop, 0.9);
    EXPECT_GE(s.fix.num_sats, 14);
    EXPECT_LE(s.fix.num_sats, 20);
  }
}

// White (1.5 m h, 3 m v) plus an independent Gauss-Markov bias (1 m): the inlier variance per axis
// is white^2 + 1. The bias decorrelates over 60 s, so 1000 s holds only ~8 independent bias values
// and the std estimate from it strays up to 22 % over 100 seeds; 20000 s at 1 Hz stays within 4 %.
TEST(SimGnss, SppStatistics) {
  const auto sims = simulate(GnssNoise::kSpp, 1.0, 20000.0);
  const double expected[3] = {std::sqrt(1.5 * 1.5 + 1.0), std::sqrt(1.5 * 1.5 + 1.0),
                              std::sqrt(3.0 * 3.0 + 1.0)};
  for (int axis = 0; axis < 3; ++axis) {
    const double std_m = inlierStd(sims, axis);
    EXPECT_NEAR(std_m / expected[axis], 1.0, 0.1) << "axis " << axis << " std " << std_m;
  }
  for (const auto& s : sims) {
    EXPECT_EQ(s.fix.quality, 1);
    EXPECT_DOUBLE_EQ(s.fix.sigma_h_m, 1.5);
    EXPECT_DOUBLE_EQ(s.fix.sigma_v_m, 3.0);
    EXPECT_GE(s.fix.hdop, 0.8);
    EXPECT_LE(s.fix.hdop, 2.0);
    EXPECT_GE(s.fix.num_sats, 7);
    EXPECT_LE(s.fix.num_sats, 12);
  }
}

TEST(SimGnss, SppOutliers) {
  const auto sims = simulate(GnssNoise::kSpp, 10.0, 1000.0);
  int outliers = 0;
  for (const auto& s : sims) outliers += s.outlier ? 1 : 0;
  const double fraction = static_cast<double>(outliers) / static_cast<double>(sims.size());
  EXPECT_GE(fraction, 0.005);
  EXPECT_LE(fraction, 0.015);
  // An outlier adds 5-30 m on top of a few metres of ordinary error.
  for (const auto& s : sims) {
    if (s.outlier) {
      EXPECT_GT(s.error_enu.norm(), 1.0);
    }
  }
}

// Error = white w + bias b, independent. At lag L: cov = sigma_b^2 exp(-L/tau) (w is white), and
// var = sigma_w^2 + sigma_b^2, so the correlation is exp(-L/tau) / (1 + sigma_w^2) with sigma_b =
// 1 m: at L = tau = 60 s, exp(-1) / 3.25 = 0.113 horizontally and exp(-1) / 10 = 0.037 vertically.
// At 600 s the bias is forgotten (exp(-10)); at 1 s the correlation is nearly 1 / 3.25.
// 100000 s at 1 Hz keeps the estimates within 0.035 of these values for 100 seeds out of 100.
TEST(SimGnss, SppBiasIsGaussMarkovWith60sTimeConstant) {
  const auto sims = simulate(GnssNoise::kSpp, 1.0, 100000.0);
  const double white_sq[3] = {1.5 * 1.5, 1.5 * 1.5, 3.0 * 3.0};
  for (int axis = 0; axis < 3; ++axis) {
    const auto rho = [&](double lag_s) { return std::exp(-lag_s / 60.0) / (1.0 + white_sq[axis]); };
    const double r60 = autocorrelation(sims, axis, 60);
    const double r600 = autocorrelation(sims, axis, 600);
    const double r1 = autocorrelation(sims, axis, 1);
    EXPECT_NEAR(r60, rho(60.0), 0.04) << "axis " << axis;
    EXPECT_NEAR(r600, 0.0, 0.04) << "axis " << axis;
    EXPECT_NEAR(r1, rho(1.0), 0.04) << "axis " << axis;
  }
}

TEST(SimGnss, OutagesRemoveFixes) {
  GnssSimOptions options;
  options.noise = GnssNoise::kSpp;
  options.rate_hz = 10.0;
  options.outages_ns = {{kT0 + 10 * kNs, kT0 + 20 * kNs}, {kT0 + 35 * kNs, kT0 + 40 * kNs}};
  const auto sims = synthesizeGnss(straightEast(), kT0, kT0 + 60 * kNs, kEnu, options, 3);
  // 601 epochs; [10, 20] s holds 101 of them and [35, 40] s 51 (both ends inclusive).
  EXPECT_EQ(sims.size(), 601u - 101u - 51u);
  for (const auto& s : sims) {
    for (const auto& [a, b] : options.outages_ns) {
      EXPECT_FALSE(s.fix.t_ns >= a && s.fix.t_ns <= b) << s.fix.t_ns - kT0;
    }
  }
}

TEST(SimGnss, DeterministicForASeed) {
  const auto a = simulate(GnssNoise::kSpp, 5.0, 200.0, 7);
  const auto b = simulate(GnssNoise::kSpp, 5.0, 200.0, 7);
  const auto c = simulate(GnssNoise::kSpp, 5.0, 200.0, 8);
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(a.size(), c.size());
  bool any_different = false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].error_enu, b[i].error_enu);
    EXPECT_EQ(a[i].fix.lat_deg, b[i].fix.lat_deg);
    EXPECT_EQ(a[i].fix.hdop, b[i].fix.hdop);
    EXPECT_EQ(a[i].outlier, b[i].outlier);
    any_different = any_different || a[i].error_enu != c[i].error_enu;
  }
  EXPECT_TRUE(any_different);
}

TEST(SimGnss, NmeaRoundTrip) {
  const auto fixes = reported(simulate(GnssNoise::kSpp, 10.0, 4.9));
  ASSERT_EQ(fixes.size(), 50u);
  const std::string log = toNmeaLog(fixes);
  EXPECT_EQ(log.substr(0, 7), "$GPGGA,");
  EXPECT_NE(log.find("*", 0), std::string::npos);
  EXPECT_EQ(log.find('\n'), log.find("\r\n") + 1);  // CRLF line endings

  const fs::path file =
      fs::temp_directory_path() / ("gvio_sim_gnss_test_" + std::to_string(::getpid()) + ".nmea");
  std::ofstream(file, std::ios::binary) << log;
  const io::NmeaLog read = io::readNmea(file, io::ReaderConfig{});
  fs::remove(file);

  EXPECT_TRUE(read.warnings.empty());
  EXPECT_EQ(read.bad_checksum, 0u);
  EXPECT_EQ(read.sentences, 150u);
  ASSERT_EQ(read.fixes.size(), fixes.size());
  for (std::size_t i = 0; i < fixes.size(); ++i) {
    const GnssFix& in = fixes[i];
    const GnssFix& out = read.fixes[i];
    EXPECT_EQ(out.t_ns, in.t_ns);
    EXPECT_NEAR(out.lat_deg, in.lat_deg, 1e-8);
    EXPECT_NEAR(out.lon_deg, in.lon_deg, 1e-8);
    EXPECT_NEAR(out.h_ellipsoid_m, in.h_ellipsoid_m, 1e-3);
    EXPECT_DOUBLE_EQ(out.sigma_h_m, in.sigma_h_m);
    EXPECT_DOUBLE_EQ(out.sigma_v_m, in.sigma_v_m);
    EXPECT_EQ(out.quality, in.quality);
    EXPECT_DOUBLE_EQ(out.hdop, in.hdop);
    EXPECT_EQ(out.num_sats, in.num_sats);
  }
}

// Southern/western hemispheres, a time off the 10 ms grid, and RTK sigmas through GST.
TEST(SimGnss, NmeaRoundTripSouthWestAndOddTimes) {
  GnssFix fix;
  fix.t_ns = 946'684'799 * kNs + 123'456'789;  // 1999-12-31 23:59:59.123456789 UTC
  fix.lat_deg = -33.8567844;
  fix.lon_deg = -151.2152967;
  fix.h_ellipsoid_m = -12.3456;
  fix.sigma_h_m = 0.02;
  fix.sigma_v_m = 0.04;
  fix.quality = 4;
  fix.hdop = 0.7;
  fix.num_sats = 9;
  const std::string log = toNmeaLog({fix});
  EXPECT_NE(log.find("GPGGA,235959.123456789,3351.4070640,S,15112.9178020,W,4,09,0.7,-59.346,M,"
                     "47.000,M,,*"),
            std::string::npos)
      << log;
  EXPECT_NE(log.find(",311299,"), std::string::npos) << log;
  EXPECT_NE(log.find("GPGST,235959.123456789,0.02,0.02,0.02,0.0,0.02,0.02,0.04*"),
            std::string::npos)
      << log;

  const fs::path file =
      fs::temp_directory_path() / ("gvio_sim_gnss_test_sw_" + std::to_string(::getpid()) + ".nmea");
  std::ofstream(file, std::ios::binary) << log;
  const io::NmeaLog read = io::readNmea(file, io::ReaderConfig{});
  fs::remove(file);
  ASSERT_EQ(read.fixes.size(), 1u);
  EXPECT_EQ(read.fixes[0].t_ns, fix.t_ns);
  EXPECT_NEAR(read.fixes[0].lat_deg, fix.lat_deg, 1e-8);
  EXPECT_NEAR(read.fixes[0].lon_deg, fix.lon_deg, 1e-8);
  EXPECT_NEAR(read.fixes[0].h_ellipsoid_m, fix.h_ellipsoid_m, 1e-3);
  EXPECT_DOUBLE_EQ(read.fixes[0].sigma_h_m, 0.02);
  EXPECT_DOUBLE_EQ(read.fixes[0].sigma_v_m, 0.04);
}

// The .pos a rig's RTKLIB would write: read back by gvio's reader to the same instants (GPST
// written, leap seconds of 1999 and 2023 applied both ways), positions, quality and satellites.
TEST(SimGnss, RtklibPosRoundTrip) {
  std::vector<GnssFix> fixes = reported(simulate(GnssNoise::kSpp, 10.0, 1.9));
  ASSERT_EQ(fixes.size(), 20u);
  fixes[3].quality = 4;
  fixes[4].quality = 5;
  fixes[5].quality = 2;
  GnssFix odd = fixes.back();
  odd.t_ns = 946'684'799 * kNs + 123'456'789;  // 1999-12-31 23:59:59.123456789 UTC
  odd.lat_deg = -33.8567844;
  odd.lon_deg = -151.2152967;
  const std::string pos = toRtklibPos({odd});
  EXPECT_NE(pos.find("2000/01/01 00:00:12.123456789 "), std::string::npos) << pos;  // GPST +13 s

  const fs::path file =
      fs::temp_directory_path() / ("gvio_sim_gnss_test_" + std::to_string(::getpid()) + ".pos");
  fixes.push_back(odd);
  std::sort(fixes.begin(), fixes.end(), [](auto& a, auto& b) { return a.t_ns < b.t_ns; });
  std::ofstream(file, std::ios::binary) << toRtklibPos(fixes);
  const io::PosFile read = io::readRtklibPos(file, io::ReaderConfig{});
  fs::remove(file);
  EXPECT_EQ(read.time_system, "GPST");
  ASSERT_EQ(read.fixes.size(), fixes.size());
  for (std::size_t i = 0; i < fixes.size(); ++i) {
    EXPECT_EQ(read.fixes[i].t_ns, fixes[i].t_ns);
    EXPECT_NEAR(read.fixes[i].lat_deg, fixes[i].lat_deg, 1e-9);
    EXPECT_NEAR(read.fixes[i].lon_deg, fixes[i].lon_deg, 1e-9);
    EXPECT_NEAR(read.fixes[i].h_ellipsoid_m, fixes[i].h_ellipsoid_m, 1e-4);
    EXPECT_EQ(read.fixes[i].quality, fixes[i].quality);
    EXPECT_EQ(read.fixes[i].num_sats, fixes[i].num_sats);
    // Read sigmas are floored by the quality's UERE (io/rtklib_pos.hpp), never lowered.
    EXPECT_GE(read.fixes[i].sigma_h_m, fixes[i].sigma_h_m - 1e-4);
  }
}

// A replayed receiver's error ellipse survives the files gvio simulate writes: NMEA GST (its axes
// and orientation, written exactly) and RTKLIB's sdn/sde/sdne (4 decimals).
TEST(SimGnss, EllipsesRoundTripThroughNmeaAndPos) {
  std::vector<GnssFix> fixes = reported(simulate(GnssNoise::kSpp, 1.0, 5.5));
  ASSERT_EQ(fixes.size(), 6u);
  for (std::size_t i = 0; i < fixes.size(); ++i) {
    fixes[i].sigma_h_m = 2.0 + 0.5 * static_cast<double>(i);
    fixes[i].shape_en = fusion::horizontalShape(
        fusion::ellipseCovariance(3.0, 1.0, 35.0 * static_cast<double>(i)));  // 0..175 deg
  }
  fixes[2].shape_en.setIdentity();  // a circle stays one
  const fs::path dir =
      fs::temp_directory_path() / ("gvio_sim_ellipse_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::ofstream(dir / "fixes.nmea", std::ios::binary) << toNmeaLog(fixes);
  std::ofstream(dir / "fixes.pos", std::ios::binary) << toRtklibPos(fixes);
  const io::NmeaLog nmea = io::readNmea(dir / "fixes.nmea", io::ReaderConfig{});
  const io::PosFile pos = io::readRtklibPos(dir / "fixes.pos", io::ReaderConfig{});
  fs::remove_all(dir);
  ASSERT_EQ(nmea.fixes.size(), fixes.size());
  ASSERT_EQ(pos.fixes.size(), fixes.size());
  for (std::size_t i = 0; i < fixes.size(); ++i) {
    EXPECT_NEAR(nmea.fixes[i].sigma_h_m, fixes[i].sigma_h_m, 1e-12) << i;
    EXPECT_LT((nmea.fixes[i].shape_en - fixes[i].shape_en).norm(), 1e-9) << i;
    EXPECT_NEAR(pos.fixes[i].sigma_h_m, fixes[i].sigma_h_m, 1e-4) << i;
    EXPECT_LT((pos.fixes[i].shape_en - fixes[i].shape_en).norm(), 1e-3) << i;
  }
  EXPECT_EQ(nmea.fixes[2].shape_en, Eigen::Matrix2d::Identity());
  EXPECT_GT(nmea.fixes[1].shape_en(0, 1), 0.1);   // 35 deg: east and north errors go together
  EXPECT_LT(nmea.fixes[4].shape_en(0, 1), -0.1);  // 140 deg: they go apart
}

TEST(SimGnss, GnssCsvFormat) {
  GnssFix fix;
  fix.t_ns = kT0 + 100'000'000;
  fix.lat_deg = 48.98253;
  fix.lon_deg = 8.39035;
  fix.h_ellipsoid_m = 116.4;
  fix.sigma_h_m = 1.5;
  fix.sigma_v_m = 3.0;
  std::istringstream csv(toGnssCsv({fix, fix}));
  std::string line;
  ASSERT_TRUE(std::getline(csv, line));
  EXPECT_EQ(line, "#timestamp [ns],lat_deg,lon_deg,height_m,sigma_h_m,sigma_v_m");
  ASSERT_TRUE(std::getline(csv, line));
  EXPECT_EQ(line, "1700000000100000000,48.9825300000,8.3903500000,116.4000,1.5000,3.0000");
  int rows = 1;
  while (std::getline(csv, line)) ++rows;
  EXPECT_EQ(rows, 2);
}

// --gnss-noise: degrading exact fixes adds exactly the process's error (same seed, same draws as
// the simulator) and reports the model's sigmas.
TEST(SimGnss, DegradeFixesAddsTheModelError) {
  const std::vector<GnssFix> exact = reported(simulate(GnssNoise::kNone, 1.0, 2000.0));
  const GnssErrorModel spp = GnssErrorModel::preset(GnssNoise::kSpp);
  const DegradedFixes degraded = degradeFixes(exact, spp, 7);
  ASSERT_EQ(degraded.fixes.size(), exact.size());
  const fusion::EnuFrame enu({exact[0].lat_deg, exact[0].lon_deg, exact[0].h_ellipsoid_m});
  GnssErrorProcess process(spp, 7, exact[0].t_ns);
  double sum_sq_east = 0.0;
  int inliers = 0;
  for (std::size_t i = 0; i < exact.size(); ++i) {
    const GnssFix& d = degraded.fixes[i];
    const Eigen::Vector3d moved =
        enu.toEnu({d.lat_deg, d.lon_deg, d.h_ellipsoid_m}) -
        enu.toEnu({exact[i].lat_deg, exact[i].lon_deg, exact[i].h_ellipsoid_m});
    bool outlier = false;
    const Eigen::Vector3d expected = process.draw(exact[i].t_ns, outlier);
    EXPECT_LT((moved - expected).norm(), 1e-6) << i;
    EXPECT_LT((degraded.added_error_enu[i] - expected).norm(), 1e-12);
    EXPECT_EQ(d.t_ns, exact[i].t_ns);
    EXPECT_DOUBLE_EQ(d.sigma_h_m, 1.5);
    EXPECT_DOUBLE_EQ(d.sigma_v_m, 3.0);
    EXPECT_EQ(d.quality, 1);
    if (!outlier) sum_sq_east += expected.x() * expected.x(), ++inliers;
  }
  // White 1.5 m + Gauss-Markov 1 m per horizontal axis: sqrt(1.5^2 + 1^2) = 1.80 m.
  EXPECT_NEAR(std::sqrt(sum_sq_east / inliers), 1.80, 0.2);
  EXPECT_GT(degraded.outliers, 5);
  EXPECT_LT(degraded.outliers, 45);
  EXPECT_TRUE(degradeFixes({}, spp, 7).fixes.empty());
}

TEST(SimGnss, NoiseModelValidation) {
  GnssErrorModel m = GnssErrorModel::preset(GnssNoise::kSpp);
  EXPECT_NO_THROW(m.validate());
  m.bias_tau_s = 0.0;
  EXPECT_THROW(m.validate(), InvalidInput);
  m = GnssErrorModel::preset(GnssNoise::kSpp);
  m.outlier_probability = 1.5;
  EXPECT_THROW(m.validate(), InvalidInput);
  m = GnssErrorModel::preset(GnssNoise::kSpp);
  m.reported_sigma_h_m = 0.0;
  EXPECT_THROW(m.validate(), InvalidInput);
  m = GnssErrorModel::preset(GnssNoise::kSpp);
  m.white_v_m = std::nan("");
  EXPECT_THROW(m.validate(), InvalidInput);
}

}  // namespace
}  // namespace gvio::sim
