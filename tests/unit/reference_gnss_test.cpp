// Real GNSS on simulated drives (issue 58): the GNSS/INS reference CSV (columns by name, GPST to
// UTC, NED attitude to the vehicle body), a receiver's errors against it replayed at the epochs it
// solved (gaps kept, sigmas and quality kept), and GNSS solutions read as position tracks.
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "io/geo_track.hpp"
#include "io/gps_time.hpp"
#include "io/input_error.hpp"
#include "io/reference_csv.hpp"
#include "sim/gnss_replay.hpp"
#include "support/fixtures.hpp"

namespace gvio {
namespace {
using testing::HasSubstr;
namespace fs = std::filesystem;

constexpr std::int64_t kS = 1'000'000'000;
constexpr const char* kHeader =
    "GPS TOW (s),GPS Week,Latitude (deg),Longitude (deg),Ellipsoid Height (m),ECEF X (m),ECEF Y "
    "(m),ECEF Z (m),Roll (deg),Pitch (deg),Heading (deg),East Velocity (m/s),North Velocity "
    "(m/s),Up Velocity (m/s)\n";

std::string row(double tow, double lat, double lon, double h, double roll, double pitch,
                double heading) {
  return fmt::format("{:.1f}, 2270, {:.9f}, {:.9f}, {:.3f}, 0, 0, 0, {}, {}, {}, 0, 0, 0\n", tow,
                     lat, lon, h, roll, pitch, heading);
}

std::string readError(const std::string& text) {
  test::TempDir dir("refcsv_bad");
  test::writeText(dir.path() / "ref.csv", text);
  try {
    io::readReferenceCsv(dir.path() / "ref.csv");
  } catch (const io::InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(ReferenceCsv, ColumnsByNameTimesInUtcAndTheBodyFromNedAttitude) {
  test::TempDir dir("refcsv");
  const fs::path file = dir.path() / "reference.csv";
  test::writeText(file, std::string(kHeader) + row(194670.0, 35.0, 136.0, 40.0, 0, 0, 90) +
                            row(194670.2, 35.0, 136.00001, 40.0, 0, 10, 0) +
                            row(194670.4, 35.0, 136.00002, 40.0, 10, 0, 0));
  ASSERT_TRUE(io::looksLikeReferenceCsv(file));
  const io::ReferenceCsv ref = io::readReferenceCsv(file);
  ASSERT_EQ(ref.epochs.size(), 3U);
  ASSERT_TRUE(ref.has_attitude);
  // GPS week 2270, TOW 194670 s: 2023-07-11 06:04:30 GPST = 06:04:12 UTC (18 leap seconds).
  const std::int64_t gpst = io::gpsWeekTowToGpstUnixNs(2270, 194670 * kS);
  EXPECT_EQ(ref.epochs[0].t_ns, gpst - 18 * kS);
  EXPECT_EQ(ref.epochs[1].t_ns - ref.epochs[0].t_ns, 200'000'000);
  const fusion::EnuFrame enu(ref.epochs[0].lla);
  const Trajectory poses = io::referenceBodyPoses(ref, enu);
  // Heading 90 degrees (east): the body's x axis points east, z up.
  EXPECT_TRUE(poses.poses[0].linear().col(0).isApprox(Eigen::Vector3d::UnitX(), 1e-12));
  EXPECT_TRUE(poses.poses[0].linear().col(2).isApprox(Eigen::Vector3d::UnitZ(), 1e-12));
  EXPECT_NEAR(poses.poses[0].translation().norm(), 0.0, 1e-9);
  // Heading north, pitch +10 (nose up): x north and up.
  const Eigen::Vector3d x1 = poses.poses[1].linear().col(0);
  EXPECT_NEAR(x1.y(), std::cos(10.0 * M_PI / 180.0), 1e-12);
  EXPECT_NEAR(x1.z(), std::sin(10.0 * M_PI / 180.0), 1e-12);
  EXPECT_NEAR(poses.poses[1].translation().x(), 0.91, 0.01);  // 1e-5 deg of longitude at 35 N
  // Roll +10 (right side down): the body's y axis (left) rises.
  EXPECT_GT(poses.poses[2].linear().col(1).z(), 0.17);
}

TEST(ReferenceCsv, BadFilesNameTheFileAndLine) {
  EXPECT_THAT(readError("GPS TOW (s),Latitude (deg),Longitude (deg),Ellipsoid Height (m)\n"),
              HasSubstr("ref.csv:1: no 'GPS Week' column"));
  EXPECT_THAT(readError("GPS TOW (s),GPS Week,Latitude (deg),Longitude (deg),Ellipsoid Height "
                        "(m),Roll (deg),Pitch (deg)\n"),
              HasSubstr("all three columns or none"));
  EXPECT_THAT(readError(std::string(kHeader) + row(10.0, 35, 136, 40, 0, 0, 0) +
                        row(10.0, 35, 136, 40, 0, 0, 0)),
              HasSubstr("ref.csv:3: times must increase"));
  EXPECT_THAT(readError(std::string(kHeader) + "10.0, 2270, 95.0, 136, 40, 0,0,0, 0,0,0, 0,0,0\n"),
              HasSubstr("ref.csv:2: latitude/longitude out of range"));
  EXPECT_THAT(readError(std::string(kHeader) + "10.0, 2270, 35.0\n"),
              HasSubstr("ref.csv:2: 3 fields"));
  EXPECT_THAT(readError(std::string(kHeader)), HasSubstr("no epochs"));
  test::TempDir dir("refcsv_tum");
  test::writeText(dir.path() / "a.tum", "1.0 0 0 0 0 0 0 1\n");
  EXPECT_FALSE(io::looksLikeReferenceCsv(dir.path() / "a.tum"));
}

// The reference moves east at 10 m/s; fixes 2 m north of it, one between two epochs, one outside
// the reference and one in a gap of the reference.
TEST(GnssReplay, ErrorsAgainstTheReferenceReplayedOnTheTruth) {
  const fusion::EnuFrame enu({35.0, 136.0, 40.0});
  std::vector<std::int64_t> ref_t;
  std::vector<Eigen::Vector3d> ref_p;
  for (int i = 0; i <= 10; ++i) {
    if (i == 6) continue;  // a 0.4 s gap: still interpolated
    ref_t.push_back(i * 200'000'000LL);
    ref_p.emplace_back(2.0 * i, 0.0, 0.0);
  }
  ref_t.push_back(5 * kS);  // then a 3 s gap
  ref_p.emplace_back(50.0, 0.0, 0.0);
  const auto fixAt = [&](std::int64_t t, const Eigen::Vector3d& p_enu, int quality) {
    GnssFix f;
    f.t_ns = t;
    const fusion::Lla lla = enu.toLla(p_enu);
    f.lat_deg = lla.lat_deg;
    f.lon_deg = lla.lon_deg;
    f.h_ellipsoid_m = lla.h_ellipsoid_m;
    f.sigma_h_m = 0.5;
    f.sigma_v_m = 0.9;
    f.quality = quality;
    return f;
  };
  const std::vector<GnssFix> solution = {
      fixAt(300'000'000, {3.0, 2.0, 0.0}, 4),    // between epochs 1 and 2 (x 3 m)
      fixAt(1200'000'000, {12.0, 2.0, 1.0}, 5),  // in the 0.4 s gap (x 12 m)
      fixAt(3 * kS, {0.0, 0.0, 0.0}, 1),         // in the 3 s gap
      fixAt(7 * kS, {0.0, 0.0, 0.0}, 1)};        // after the reference
  const sim::RealGnssErrors errors = sim::realGnssErrors(solution, ref_t, ref_p, enu);
  ASSERT_EQ(errors.errors.size(), 2U);
  EXPECT_EQ(errors.in_reference_gap, 1U);
  EXPECT_EQ(errors.outside_reference, 1U);
  EXPECT_TRUE(errors.errors[0].error_enu.isApprox(Eigen::Vector3d(0, 2, 0), 1e-6));
  EXPECT_TRUE(errors.errors[1].error_enu.isApprox(Eigen::Vector3d(0, 2, 1), 1e-6));

  // Replayed on a drive 100 m west of the reference, with a lever arm and an outage over the
  // second fix.
  sim::GnssSimOptions options;
  options.lever_arm_b = Eigen::Vector3d(0, 0, 0.8);
  options.outages_ns = {{1100'000'000, 1300'000'000}};
  const auto truth = [](std::int64_t t) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = Eigen::Vector3d(-100.0 + 10.0 * static_cast<double>(t) * 1e-9, 0, 0);
    return T;
  };
  const auto fixes = sim::replayGnss(truth, 0, 10 * kS, enu, options, errors);
  ASSERT_EQ(fixes.size(), 1U);
  EXPECT_EQ(fixes[0].fix.t_ns, 300'000'000);
  EXPECT_EQ(fixes[0].fix.quality, 4);
  EXPECT_EQ(fixes[0].fix.sigma_h_m, 0.5);
  EXPECT_TRUE(fixes[0].p_enu_true.isApprox(Eigen::Vector3d(-97.0, 0.0, 0.8), 1e-9));
  const Eigen::Vector3d p =
      enu.toEnu({fixes[0].fix.lat_deg, fixes[0].fix.lon_deg, fixes[0].fix.h_ellipsoid_m});
  EXPECT_TRUE(p.isApprox(Eigen::Vector3d(-97.0, 2.0, 0.8), 1e-6));
  // Only the fixes within the simulated span are replayed.
  EXPECT_TRUE(sim::replayGnss(truth, 400'000'000, 10 * kS, enu, {}, errors).size() == 1U);
  EXPECT_TRUE(sim::replayGnss(truth, 2 * kS, 10 * kS, enu, {}, errors).empty());
}

TEST(GeoTrack, FormatsToldByTheContent) {
  test::TempDir dir("geotrack");
  const auto format = [&](const std::string& name, const std::string& text) {
    test::writeText(dir.path() / name, text);
    return io::geoTrackFormat(dir.path() / name);
  };
  EXPECT_EQ(format("a.nmea", "$GPGGA,1*00\n"), "nmea");
  EXPECT_EQ(format("a.pos", "% header\n"), "rtklib-pos");
  EXPECT_EQ(format("a.csv", "#timestamp [ns],lat_deg,lon_deg,height_m,sigma_h_m,sigma_v_m\n"),
            "gnss-csv");
  EXPECT_EQ(format("r.csv", std::string(kHeader)), "reference-csv");
  EXPECT_EQ(format("a.tum", "1.0 0 0 0 0 0 0 1\n"), "");
  EXPECT_EQ(format("e.csv", "#timestamp,p_x,p_y,p_z,q_w,q_x,q_y,q_z\n1,0,0,0,1,0,0,0\n"), "");

  test::writeText(dir.path() / "r.csv", std::string(kHeader) + row(10.0, 35, 136, 40, 0, 0, 0) +
                                            row(11.0, 35.00001, 136, 41, 0, 0, 0));
  const io::GeoTrack track = io::readGeoTrack(dir.path() / "r.csv", io::ReaderConfig{});
  EXPECT_EQ(track.format, "reference-csv");
  EXPECT_TRUE(track.quality.empty());
  const Trajectory p = io::geoTrackPositions(track, fusion::EnuFrame(track.lla[0]));
  EXPECT_NEAR(p.poses[1].translation().y(), 1.109, 0.002);  // 1e-5 deg of latitude
  EXPECT_NEAR(p.poses[1].translation().z(), 1.0, 1e-3);
  EXPECT_THROW(io::readGeoTrack(dir.path() / "a.tum", io::ReaderConfig{}), io::InputError);
  EXPECT_EQ(io::qualityName(4), "RTK fixed");
  EXPECT_EQ(io::qualityName(1), "single");
}

}  // namespace
}  // namespace gvio
