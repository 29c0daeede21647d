// GNSS fixes from a file of their own (issue 16): GPST <-> UTC, RTKLIB .pos (calendar and week +
// seconds time, lat/lon/height and ECEF, quality flags and sigma floors), the format told by the
// content, and bad files named with their line.
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "fusion/geodesy.hpp"
#include "io/gnss_file.hpp"
#include "io/gps_time.hpp"
#include "io/input_error.hpp"
#include "io/nmea.hpp"
#include "io/rtklib_pos.hpp"
#include "io/text.hpp"
#include "support/fixtures.hpp"

namespace gvio::io {
namespace {
using testing::AllOf;
using testing::HasSubstr;
namespace fs = std::filesystem;

constexpr std::int64_t kS = 1'000'000'000;

std::int64_t utc(const std::string& text) {
  std::int64_t t = 0;
  EXPECT_TRUE(kittiTimestampToNs(text, t)) << text;
  return t;
}

constexpr const char* kLlhHeader =
    "% program   : RTKPOST ver.2.4.3 b34\n"
    "% (lat/lon/height=WGS84/ellipsoidal,Q=1:fix,2:float,3:sbas,4:dgps,5:single,6:ppp,ns=# of "
    "satellites)\n"
    "%  GPST                  latitude(deg) longitude(deg)  height(m)   Q  ns   sdn(m)   sde(m)"
    "   sdu(m)  sdne(m)  sdeu(m)  sdun(m) age(s)  ratio\n";

TEST(GpsTime, LeapSecondsSinceTheGpsEpoch) {
  EXPECT_EQ(gpsMinusUtcSeconds(utc("1980-01-06 00:00:00")), 0);
  EXPECT_EQ(gpsMinusUtcSeconds(utc("2011-10-03 12:55:34")), 15);  // KITTI's drives
  EXPECT_EQ(gpsMinusUtcSeconds(utc("2016-12-31 12:00:00")), 17);
  EXPECT_EQ(gpsMinusUtcSeconds(utc("2017-01-01 00:00:17")), 17);  // UTC 23:59:60 still
  EXPECT_EQ(gpsMinusUtcSeconds(utc("2017-01-01 00:00:18")), 18);  // UTC 2017-01-01 00:00:00
  EXPECT_EQ(gpsMinusUtcSeconds(utc("2026-11-25 00:00:00")), 18);
  EXPECT_EQ(gpstToUtcNs(utc("2011-10-03 12:55:49.5")), utc("2011-10-03 12:55:34.5"));
  // GPS week 1656 began on Sunday 2011-10-02 (GPST).
  EXPECT_EQ(gpsWeekTowToGpstUnixNs(1656, 0), utc("2011-10-02 00:00:00"));
  EXPECT_EQ(gpsWeekTowToGpstUnixNs(1656, 133'549 * kS), utc("2011-10-03 13:05:49"));
}

TEST(RtklibPos, LatLonHeightInGpstWithQualitiesAndSigmaFloors) {
  test::TempDir dir("pos_llh");
  const fs::path file = dir.path() / "drive.pos";
  test::writeText(file, std::string(kLlhHeader) +
                            "2011/10/03 12:55:49.000   48.982537273    8.390351723   114.9085   5"
                            "  11   2.0000   1.0000   3.5000   0.0000   0.0000   0.0000   0.00    "
                            "0.0\n"
                            "2011/10/03 12:55:50.000   48.982537300    8.390351800   115.0000   0"
                            "   0   0.0000   0.0000   0.0000   0.0000   0.0000   0.0000   0.00    "
                            "0.0\n"
                            "2011/10/03 12:55:50.500   48.982537400    8.390351900   115.1000   1"
                            "  14   0.0040   0.0030   0.0080   0.0000   0.0000   0.0000   1.00  "
                            "999.9\n");
  const PosFile pos = readRtklibPos(file, ReaderConfig{});
  EXPECT_EQ(pos.time_system, "GPST");
  EXPECT_EQ(pos.position_format, "llh");
  ASSERT_EQ(pos.fixes.size(), 2U);
  EXPECT_EQ(pos.no_solution, 1U);
  ASSERT_EQ(pos.warnings.size(), 1U);
  EXPECT_THAT(pos.warnings[0], HasSubstr("line 5"));
  const GnssFix& single = pos.fixes[0];
  EXPECT_EQ(single.t_ns, utc("2011-10-03 12:55:34"));  // GPST - 15 s
  EXPECT_DOUBLE_EQ(single.lat_deg, 48.982537273);
  EXPECT_DOUBLE_EQ(single.lon_deg, 8.390351723);
  EXPECT_DOUBLE_EQ(single.h_ellipsoid_m, 114.9085);
  EXPECT_EQ(single.quality, 1);
  EXPECT_EQ(single.num_sats, 11);
  EXPECT_NEAR(single.sigma_h_m, std::sqrt(2.5), 1e-12);  // sqrt((2^2 + 1^2) / 2) above 1.5
  EXPECT_DOUBLE_EQ(single.sigma_v_m, 3.5);
  const GnssFix& fixed = pos.fixes[1];
  EXPECT_EQ(fixed.t_ns, utc("2011-10-03 12:55:35.5"));
  EXPECT_EQ(fixed.quality, 4);
  EXPECT_DOUBLE_EQ(fixed.sigma_h_m, 0.02);  // RTKLIB's 3.5 mm raised to the fixed floor
  EXPECT_DOUBLE_EQ(fixed.sigma_v_m, 0.04);  // ... times the vertical factor 2
  EXPECT_EQ(nmeaQualityOfRtklibQ(2), 5);
  EXPECT_EQ(nmeaQualityOfRtklibQ(4), 2);
  EXPECT_EQ(nmeaQualityOfRtklibQ(6), 5);
}

// RTKLIB's sdne (sign(c) sqrt(|c|) of the north-east covariance) with sdn and sde: the fix's
// ellipse. dataset.gnss_ellipse: circle leaves each fix a circle of the same horizontal sigma.
TEST(RtklibPos, TheNorthEastCorrelationGivesTheShape) {
  test::TempDir dir("pos_sdne");
  const fs::path file = dir.path() / "drive.pos";
  test::writeText(file, std::string(kLlhHeader) +
                            "2011/10/03 12:55:49.000   48.982537273    8.390351723   114.9085   5"
                            "  11   2.0000   1.0000   3.5000   1.0000   0.0000   0.0000   0.00    "
                            "0.0\n"
                            "2011/10/03 12:55:50.000   48.982537300    8.390351800   115.0000   5"
                            "  11   2.0000   1.0000   3.5000  -1.0000   0.5000  -0.5000   0.00    "
                            "0.0\n");
  const PosFile pos = readRtklibPos(file, ReaderConfig{});
  ASSERT_EQ(pos.fixes.size(), 2U);
  // cov_en = [1 1; 1 4] (sde^2, sdne^2; sdne^2, sdn^2): trace 5, rho 0.5.
  Eigen::Matrix2d expected;
  expected << 2.0 / 5.0, 2.0 / 5.0, 2.0 / 5.0, 8.0 / 5.0;
  EXPECT_LT((pos.fixes[0].shape_en - expected).norm(), 1e-12);
  EXPECT_NEAR(pos.fixes[0].sigma_h_m, std::sqrt(2.5), 1e-12);
  EXPECT_NEAR(pos.fixes[1].shape_en(0, 1), -2.0 / 5.0, 1e-12);  // a negative sdne
}

TEST(RtklibPos, EcefWithWeekAndSecondsOfWeek) {
  const fusion::Lla lla{48.98253, 8.39035, 116.4};
  const Eigen::Vector3d p = fusion::llaToEcef(lla);
  test::TempDir dir("pos_ecef");
  const fs::path file = dir.path() / "drive.pos";
  test::writeText(
      file, fmt::format("%  GPST                   x-ecef(m)      y-ecef(m)      z-ecef(m)   Q  ns"
                        "   sdx(m)   sdy(m)   sdz(m)  sdxy(m)  sdyz(m)  sdzx(m) age(s)  ratio\n"
                        "1656 133549.250 {:.4f} {:.4f} {:.4f}   2  9   1.0000   1.0000   1.0000"
                        "   0.0000   0.0000   0.0000   0.00    2.1\n",
                        p.x(), p.y(), p.z()));
  const PosFile pos = readRtklibPos(file, ReaderConfig{});
  EXPECT_EQ(pos.position_format, "ecef");
  ASSERT_EQ(pos.fixes.size(), 1U);
  const GnssFix& f = pos.fixes[0];
  EXPECT_EQ(f.t_ns, utc("2011-10-03 13:05:34.25"));
  EXPECT_NEAR(f.lat_deg, lla.lat_deg, 1e-8);
  EXPECT_NEAR(f.lon_deg, lla.lon_deg, 1e-8);
  EXPECT_NEAR(f.h_ellipsoid_m, lla.h_ellipsoid_m, 1e-3);
  EXPECT_EQ(f.quality, 5);
  // An isotropic 1 m ECEF covariance is 1 m in every ENU direction.
  EXPECT_NEAR(f.sigma_h_m, 1.0, 1e-9);
  EXPECT_NEAR(f.sigma_v_m, 1.0, 1e-9);
}

TEST(RtklibPos, UtcTimeAndAHeaderOnlyFile) {
  test::TempDir dir("pos_utc");
  std::string header = kLlhHeader;
  header.replace(header.find("GPST"), 4, "UTC ");
  test::writeText(dir.path() / "a.pos",
                  header +
                      "2011/10/03 12:55:34.123456789 48.9825 8.3903 114.9 5 6 1.6 1.6 3.2 0 0 0"
                      " 0 0\n");
  const PosFile pos = readRtklibPos(dir.path() / "a.pos", ReaderConfig{});
  ASSERT_EQ(pos.fixes.size(), 1U);
  EXPECT_EQ(pos.fixes[0].t_ns, utc("2011-10-03 12:55:34.123456789"));
  test::writeText(dir.path() / "empty.pos", kLlhHeader);
  EXPECT_TRUE(readRtklibPos(dir.path() / "empty.pos", ReaderConfig{}).fixes.empty());
}

std::string posError(const std::string& text) {
  test::TempDir dir("pos_bad");
  const fs::path file = dir.path() / "bad.pos";
  test::writeText(file, text);
  try {
    readRtklibPos(file, ReaderConfig{});
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

// RTKLIB's "Output Velocity": vn ve vu after age and ratio become the fix's speed and course over
// ground (the Nagoya drive's solutions have them).
TEST(RtklibPos, VelocitiesBecomeSpeedAndCourse) {
  test::TempDir dir("pos_velocity");
  const fs::path file = dir.path() / "v.pos";
  test::writeText(
      file,
      "%  GPST                  latitude(deg) longitude(deg)  height(m)   Q  ns   sdn(m)   sde(m)"
      "   sdu(m)  sdne(m)  sdeu(m)  sdun(m) age(s)  ratio    vn(m/s)    ve(m/s)    vu(m/s)      "
      "sdvn     sdve     sdvu    sdvne    sdveu    sdvun\n"
      "2023/07/11 06:04:52.000   35.165392498  136.881438532    39.1758   5  20   3.4222   3.9538"
      "   8.3261   1.5321   1.6609  -1.1737   0.00    0.0    3.00000   -4.00000   0.10000   "
      "0.09824  0.10787  0.25052  0.05435  0.05135  0.05065\n"
      "2023/07/11 06:04:53.000   35.165392498  136.881438532    39.1758   5  20   3.4222   3.9538"
      "   8.3261   1.5321   1.6609  -1.1737   0.00    0.0\n");
  const PosFile pos = readRtklibPos(file, ReaderConfig{});
  ASSERT_EQ(pos.fixes.size(), 2u);
  EXPECT_EQ(pos.with_velocity, 1u);
  EXPECT_NEAR(pos.fixes[0].speed_mps, 5.0, 1e-9);
  EXPECT_NEAR(pos.fixes[0].course_deg, 360.0 - std::atan2(4.0, 3.0) * 180.0 / M_PI, 1e-9);
  EXPECT_TRUE(std::isnan(pos.fixes[1].speed_mps));  // a line without them
  // Without the columns in the header, nothing is taken for a velocity.
  EXPECT_TRUE(std::isnan(readRtklibPos(dir.path() / "v.pos", ReaderConfig{}).fixes[1].course_deg));
}

TEST(RtklibPos, BadFilesNameTheFileAndLine) {
  const std::string line = "2011/10/03 12:55:49.000 48.98 8.39 114.9 5 11 2 1 3 0 0 0 0 0\n";
  EXPECT_THAT(posError("%  GPST  e-baseline(m) n-baseline(m) u-baseline(m) Q ns sde(m) sdn(m) "
                       "sdu(m) sden(m) sdnu(m) sdue(m) age(s) ratio\n" +
                       line),
              AllOf(HasSubstr("bad.pos:2"), HasSubstr("baseline")));
  EXPECT_THAT(posError("%  GPST  latitude(d'\") longitude(d'\") height(m) Q ns sdn(m)\n" + line),
              HasSubstr("degrees-minutes-seconds"));
  EXPECT_THAT(
      posError("% (lat/lon/height=WGS84/geodetic,Q=1:fix)\n" + std::string(kLlhHeader) + line),
      HasSubstr("geoid"));
  EXPECT_THAT(posError(line), HasSubstr("no RTKLIB header"));
  EXPECT_THAT(posError("%  GPST  something(m)\n" + line), HasSubstr("unknown RTKLIB column"));
  EXPECT_THAT(posError(std::string(kLlhHeader) + line + line),
              AllOf(HasSubstr("bad.pos:5"), HasSubstr("does not increase")));
  EXPECT_THAT(posError(std::string(kLlhHeader) +
                       "2011/10/03 12:55:49.000 48.98 8.39 nan 5 11 2 1 3 0 0 0 0 0\n"),
              HasSubstr("bad.pos:4"));
  EXPECT_THAT(posError(std::string(kLlhHeader) + "2011/13/03 12:55:49.000 48.98 8.39 1 5 11 2 1 "
                                                 "3 0 0 0 0 0\n"),
              HasSubstr("malformed time"));
  EXPECT_THAT(posError(std::string(kLlhHeader) + "2011/10/03 12:55:49.000 48.98 8.39 1 5\n"),
              HasSubstr("columns"));
  EXPECT_THAT(posError(std::string(kLlhHeader) + "2011/10/03 12:55:49.000 98.98 8.39 1 5 11 2 1 "
                                                 "3 0 0 0 0 0\n"),
              HasSubstr("out of range"));
  EXPECT_THAT(posError(""), HasSubstr("empty"));
}

TEST(GnssFile, TheFormatIsToldByTheContent) {
  test::TempDir dir("gnss_file");
  const fs::path nmea = dir.path() / "log.txt", csv = dir.path() / "fixes.txt",
                 pos = dir.path() / "solution.txt";
  test::writeText(nmea, withNmeaChecksum("GPRMC,125534.00,A,4858.9522364,N,00823.4211034,E,0.0,"
                                         "0.0,031011,,,A") +
                            "\n" +
                            withNmeaChecksum("GPGGA,125534.00,4858.9522364,N,00823.4211034,E,1,"
                                             "11,1.0,67.908,M,47.000,M,,") +
                            "\n");
  test::writeText(csv,
                  "#timestamp [ns],lat_deg,lon_deg,height_m,sigma_h_m,sigma_v_m\n"
                  "1317646534000000000,48.9825372736,8.3903517234,114.9085,1.5000,3.0000\n");
  test::writeText(pos, std::string(kLlhHeader) +
                           "2011/10/03 12:55:49.000 48.9825372736 8.3903517234 114.9085 5 11 1.5 "
                           "1.5 3.0 0 0 0 0 0\n");
  const GnssFileData a = readGnssFile(nmea, ReaderConfig{});
  const GnssFileData b = readGnssFile(csv, ReaderConfig{});
  const GnssFileData c = readGnssFile(pos, ReaderConfig{});
  EXPECT_EQ(a.format, "nmea");
  EXPECT_EQ(b.format, "csv");
  EXPECT_EQ(c.format, "rtklib-pos");
  ASSERT_EQ(a.fixes.size(), 1U);
  ASSERT_EQ(b.fixes.size(), 1U);
  ASSERT_EQ(c.fixes.size(), 1U);
  // The same instant and place in three formats.
  EXPECT_EQ(a.fixes[0].t_ns, b.fixes[0].t_ns);
  EXPECT_EQ(c.fixes[0].t_ns, b.fixes[0].t_ns);
  EXPECT_NEAR(a.fixes[0].lat_deg, b.fixes[0].lat_deg, 1e-9);
  EXPECT_DOUBLE_EQ(c.fixes[0].lat_deg, b.fixes[0].lat_deg);
  EXPECT_DOUBLE_EQ(c.fixes[0].sigma_h_m, b.fixes[0].sigma_h_m);
  EXPECT_DOUBLE_EQ(c.fixes[0].sigma_v_m, b.fixes[0].sigma_v_m);

  Dataset ds;  // a dataset in 2020: the file's fixes are all outside it
  ds.frames.resize(2);
  ds.frames[0].t_ns = utc("2020-01-01 00:00:00");
  ds.frames[1].t_ns = utc("2020-01-01 00:01:00");
  useGnssFile(ds, pos, ReaderConfig{});
  EXPECT_EQ(ds.gnss.size(), 1U);
  EXPECT_EQ(ds.gnss_source, pos.string());
  ASSERT_EQ(ds.warnings.size(), 1U);
  EXPECT_THAT(ds.warnings[0], HasSubstr("falls within the dataset"));
}

// gvio run --gnss-file: an RTKLIB file holding the same fixes as a CSV gives the same run; a bad
// one exits 2 with one line.
TEST(CliGnssFile, APosFileGivesTheSameRunAsTheSameFixesInCsv) {
  const fs::path drive = test::cachedSimulation(
      fmt::format("--trajectory {}/assets/demo/drive.tum --seconds 20 --seed 9", GVIO_SOURCE_DIR));
  const fs::path csv = drive / "gnss" / "data.csv";
  test::TempDir dir("cli_gnss_file");
  // The CSV's fixes as an RTKLIB single-point solution in GPST.
  // And the same with a north-east correlation of 0.49 (sdne = 0.7 sdn, sdn = sde).
  std::string pos = kLlhHeader, correlated = kLlhHeader;
  LineReader in(csv);
  std::string line;
  while (in.next(line)) {
    if (isBlankOrComment(line)) continue;
    const auto f = splitDelimited(line, ',');
    ASSERT_EQ(f.size(), 6U) << line;
    const std::int64_t t_utc = parseInt64(f[0], in, "t");
    const std::int64_t t_gpst = t_utc + gpsMinusUtcSeconds(t_utc) * kS;  // no leap second near
    const std::string stamp = formatKittiTimestamp(t_gpst);  // "YYYY-MM-DD hh:mm:ss.fffffffff"
    const std::string head =
        fmt::format("{}/{}/{} {} {} {} {} 5 10 {} {} {}", stamp.substr(0, 4), stamp.substr(5, 2),
                    stamp.substr(8, 2), stamp.substr(11), f[1], f[2], f[3], f[4], f[4], f[5]);
    pos += head + " 0 0 0 0 0\n";
    correlated += fmt::format("{} {:.4f} 0 0 0 0\n", head, 0.7 * std::stod(std::string(f[4])));
  }
  test::writeText(dir.path() / "fixes.pos", pos);
  test::writeText(dir.path() / "correlated.pos", correlated);
  const auto run = [&](const fs::path& gnss_file, const std::string& out,
                       const std::string& extra = "") {
    return test::runGvio(
        fmt::format("run --dataset {} --out {} --no-progress --gnss graph --gnss-file {} --set "
                    "map.enabled=false --set loops.enabled=false {} {}",
                    test::quoted(drive), test::quoted(dir.path() / out), test::quoted(gnss_file),
                    test::kSimGeo, extra));
  };
  const test::CommandResult from_csv = run(csv, "csv");
  ASSERT_EQ(from_csv.exit_code, 0) << from_csv.err;
  const test::CommandResult from_pos = run(dir.path() / "fixes.pos", "pos");
  ASSERT_EQ(from_pos.exit_code, 0) << from_pos.err;
  const std::string fused = test::readText(dir.path() / "pos" / "trajectory.tum");
  EXPECT_FALSE(fused.empty());
  EXPECT_EQ(fused, test::readText(dir.path() / "csv" / "trajectory.tum"));
  EXPECT_EQ(test::readText(dir.path() / "pos" / "gnss_fixes.csv"),
            test::readText(dir.path() / "csv" / "gnss_fixes.csv"));
  // The stated ellipses are fused (another trajectory); as circles, the same run as the CSV's.
  const test::CommandResult ellipses = run(dir.path() / "correlated.pos", "ellipses");
  ASSERT_EQ(ellipses.exit_code, 0) << ellipses.err;
  EXPECT_NE(test::readText(dir.path() / "ellipses" / "trajectory.tum"), fused);
  const test::CommandResult circles =
      run(dir.path() / "correlated.pos", "circles", "--set dataset.gnss_ellipse=circle");
  ASSERT_EQ(circles.exit_code, 0) << circles.err;
  EXPECT_EQ(test::readText(dir.path() / "circles" / "trajectory.tum"), fused);

  test::writeText(dir.path() / "bad.pos", "%  GPST  e-baseline(m) n-baseline(m)\n1 2 3\n");
  const test::CommandResult bad = run(dir.path() / "bad.pos", "bad");
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_THAT(bad.err, HasSubstr("bad.pos:2"));
  EXPECT_EQ(std::count(bad.err.begin(), bad.err.end(), '\n'), 1) << bad.err;
}

}  // namespace
}  // namespace gvio::io
