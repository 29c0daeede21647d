#include "io/nmea.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "fusion/gnss_covariance.hpp"
#include "io/input_error.hpp"

namespace gvio::io {
namespace {

namespace fs = std::filesystem;

constexpr std::int64_t kNs = 1'000'000'000;
// Reference sentences from the NMEA 0183 documentation, checksums as published.
constexpr const char* kRefGga = "$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*47";
constexpr const char* kRefRmc =
    "$GPRMC,123519,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W*6A";
constexpr std::int64_t kRefUnixSeconds = 764426119;  // 1994-03-23 12:35:19 UTC

// GGA at time `hhmmss` with a fix near Munich; `quality`, `hdop` as given.
std::string gga(const std::string& hhmmss, const std::string& quality = "1",
                const std::string& hdop = "0.9") {
  return withNmeaChecksum("GNGGA," + hhmmss + ",4807.038,N,01131.000,E," + quality + ",08," + hdop +
                          ",545.4,M,46.9,M,,");
}
std::string rmc(const std::string& hhmmss, const std::string& ddmmyy) {
  return withNmeaChecksum("GNRMC," + hhmmss + ",A,4807.038,N,01131.000,E,0.0,0.0," + ddmmyy +
                          ",,,A");
}

class NmeaTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("gvio_nmea_test_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path write(const std::vector<std::string>& lines, const std::string& eol = "\n") {
    const fs::path file = dir_ / "log.nmea";
    std::ofstream out(file, std::ios::binary);
    for (const auto& line : lines) out << line << eol;
    return file;
  }
  NmeaLog read(const std::vector<std::string>& lines, const std::string& eol = "\n") {
    return readNmea(write(lines, eol), config_);
  }
  // The InputError message reading `lines` throws; fails the test when nothing is thrown.
  std::string errorOf(const std::vector<std::string>& lines) {
    try {
      read(lines);
    } catch (const InputError& e) {
      return e.what();
    }
    ADD_FAILURE() << "no InputError thrown";
    return {};
  }
  std::string fileAt(int line) const {
    return (dir_ / "log.nmea").string() + ":" + std::to_string(line);
  }

  fs::path dir_;
  ReaderConfig config_;
};

TEST(NmeaChecksumTest, MatchesPublishedReferenceChecksums) {
  EXPECT_EQ(nmeaChecksum("GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,"), 0x47);
  EXPECT_EQ(withNmeaChecksum("GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,"),
            kRefGga);
  EXPECT_EQ(withNmeaChecksum("GPRMC,123519,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W"),
            kRefRmc);
}

TEST(NmeaChecksumTest, HexIsUppercaseAndTwoDigits) {
  EXPECT_EQ(nmeaChecksum(""), 0);
  EXPECT_EQ(withNmeaChecksum(""), "$*00");
  EXPECT_EQ(withNmeaChecksum("\x0A"), "$\x0A*0A");
  EXPECT_EQ(withNmeaChecksum("z"), "$z*7A");
}

TEST_F(NmeaTest, ReadsReferenceSentences) {
  const NmeaLog log = read({kRefGga, kRefRmc});
  ASSERT_EQ(log.fixes.size(), 1u);
  const GnssFix& fix = log.fixes[0];
  EXPECT_EQ(fix.t_ns, kRefUnixSeconds * kNs);
  EXPECT_NEAR(fix.lat_deg, 48.1173, 1e-12);
  EXPECT_NEAR(fix.lon_deg, 11.0 + 31.0 / 60.0, 1e-12);
  EXPECT_NEAR(fix.h_ellipsoid_m, 545.4 + 46.9, 1e-9);
  EXPECT_EQ(fix.quality, 1);
  EXPECT_EQ(fix.num_sats, 8);
  EXPECT_DOUBLE_EQ(fix.hdop, 0.9);
  EXPECT_EQ(log.sentences, 2u);
  EXPECT_EQ(log.bad_checksum, 0u);
  EXPECT_EQ(log.no_fix, 0u);
  EXPECT_EQ(log.other_sentences, 0u);
  EXPECT_TRUE(log.warnings.empty());
}

TEST_F(NmeaTest, SouthAndWestAreNegative) {
  const NmeaLog log = read(
      {rmc("120000", "010124"), withNmeaChecksum("GPGGA,120000,3352.1234,S,15112.5000,W,1,10,1.0,"
                                                 "10.0,M,-20.5,M,,")});
  ASSERT_EQ(log.fixes.size(), 1u);
  EXPECT_NEAR(log.fixes[0].lat_deg, -(33.0 + 52.1234 / 60.0), 1e-12);
  EXPECT_NEAR(log.fixes[0].lon_deg, -(151.0 + 12.5 / 60.0), 1e-12);
  EXPECT_NEAR(log.fixes[0].h_ellipsoid_m, 10.0 - 20.5, 1e-12);
}

TEST_F(NmeaTest, FractionalSecondsAreExact) {
  const NmeaLog log = read({rmc("000000.00", "290224"), gga("000000.05"), gga("000000.15")});
  ASSERT_EQ(log.fixes.size(), 2u);
  EXPECT_EQ(log.fixes[0].t_ns, 1709164800 * kNs + 50'000'000);
  EXPECT_EQ(log.fixes[1].t_ns, 1709164800 * kNs + 150'000'000);
}

TEST_F(NmeaTest, RmcAfterItsGgaDatesIt) {
  // Two logs concatenated, four days apart: the RMC of the same epoch (after the GGA) wins over
  // the preceding one, which would put the second fix on 2024-01-01.
  const NmeaLog log =
      read({rmc("120000", "010124"), gga("120000"), gga("120005"), rmc("120005", "050124")});
  ASSERT_EQ(log.fixes.size(), 2u);
  EXPECT_EQ(log.fixes[0].t_ns, (1704110400 + 0) * kNs);              // 2024-01-01 12:00:00
  EXPECT_EQ(log.fixes[1].t_ns, (1704110400 + 4 * 86400 + 5) * kNs);  // 2024-01-05 12:00:05
}

TEST_F(NmeaTest, LogLongerThanADayMatchesTheAdjacentEpoch) {
  // The same time of day occurs on two days: RMC and GST pair with the sentences next to the GGA.
  const NmeaLog log = read(
      {rmc("120000", "010124"), gga("120000"), withNmeaChecksum("GPGST,120000,,,,,1.0,1.0,2.0"),
       rmc("120000", "020124"), gga("120000"), withNmeaChecksum("GPGST,120000,,,,,3.0,3.0,4.0")});
  ASSERT_EQ(log.fixes.size(), 2u);
  EXPECT_EQ(log.fixes[0].t_ns, 1704110400 * kNs);
  EXPECT_EQ(log.fixes[1].t_ns, (1704110400 + 86400) * kNs);
  EXPECT_NEAR(log.fixes[0].sigma_h_m, 1.0, 1e-12);
  EXPECT_NEAR(log.fixes[1].sigma_h_m, 3.0, 1e-12);
}

TEST_F(NmeaTest, MidnightRolloverAfterPrecedingRmc) {
  // Only one RMC, before midnight: a GGA with an earlier time of day is on the next day
  // (here also the next month and year, and 99 means 1999).
  const NmeaLog log = read({rmc("235959", "311299"), gga("235959"), gga("000000"), gga("000001")});
  ASSERT_EQ(log.fixes.size(), 3u);
  EXPECT_EQ(log.fixes[0].t_ns, 946684799 * kNs);
  EXPECT_EQ(log.fixes[1].t_ns, 946684800 * kNs);
  EXPECT_EQ(log.fixes[2].t_ns, 946684801 * kNs);
}

TEST_F(NmeaTest, FollowingRmcOnlyDatesEarlierFixes) {
  const NmeaLog log = read({gga("235958"), gga("235959"), rmc("000001", "010100"), gga("000001")});
  ASSERT_EQ(log.fixes.size(), 3u);
  EXPECT_EQ(log.fixes[0].t_ns, 946684798 * kNs);
  EXPECT_EQ(log.fixes[1].t_ns, 946684799 * kNs);
  EXPECT_EQ(log.fixes[2].t_ns, 946684801 * kNs);
}

TEST_F(NmeaTest, BadChecksumIsSkippedAndReported) {
  config_.nmea_checksum = "skip";
  std::string corrupted = gga("120001");
  corrupted[20] = corrupted[20] == '7' ? '8' : '7';  // a digit of the latitude
  const NmeaLog log = read({rmc("120000", "010124"), gga("120000"), corrupted, gga("120002")});
  ASSERT_EQ(log.fixes.size(), 2u);
  EXPECT_EQ(log.bad_checksum, 1u);
  EXPECT_EQ(log.sentences, 4u);
  ASSERT_EQ(log.warnings.size(), 1u);
  EXPECT_NE(log.warnings[0].find("1 sentence "), std::string::npos) << log.warnings[0];
  EXPECT_NE(log.warnings[0].find("checksum"), std::string::npos) << log.warnings[0];
  EXPECT_NE(log.warnings[0].find("line 3"), std::string::npos) << log.warnings[0];
}

TEST_F(NmeaTest, MissingOrTruncatedChecksumIsSkipped) {
  config_.nmea_checksum = "skip";
  std::string no_checksum = gga("120001");
  no_checksum.resize(no_checksum.size() - 3);
  std::string truncated = gga("120002");
  truncated.resize(truncated.size() - 1);
  const NmeaLog log = read(
      {rmc("120000", "010124"), gga("120000"), no_checksum, truncated, "$GPGGA,120003,4807.038,N"});
  ASSERT_EQ(log.fixes.size(), 1u);
  EXPECT_EQ(log.bad_checksum, 3u);
  ASSERT_EQ(log.warnings.size(), 1u);
  EXPECT_NE(log.warnings[0].find("3 sentences"), std::string::npos) << log.warnings[0];
  EXPECT_NE(log.warnings[0].find("line 3"), std::string::npos) << log.warnings[0];
}

// A real reference logger writes every RMC with a wrong checksum: by default the log is refused
// with the counts per type (not read as a log without dates); `warn` reads the sentences as
// written; one corrupted sentence among many (line noise) is left out with a warning.
TEST_F(NmeaTest, ChecksumsThatFailSystematicallyRefuseTheLogUnlessTold) {
  std::vector<std::string> lines;
  for (int s = 0; s < 60; ++s) {
    const std::string t = fmt::format("1200{:02}", s);
    std::string bad_rmc = rmc(t, "010124");
    bad_rmc.back() = bad_rmc.back() == '0' ? '1' : '0';
    lines.push_back(bad_rmc);
    lines.push_back(gga(t));
  }
  lines.push_back(withNmeaChecksum("PUBX,00,120100,,,,,"));
  const std::string error = errorOf(lines);
  EXPECT_NE(error.find("60 of 60 RMC sentences failed their checksum (first at line 1)"),
            std::string::npos)
      << error;
  EXPECT_NE(error.find("60 GGA (0 without a position), 1 vendor"), std::string::npos) << error;
  EXPECT_NE(error.find("dataset.nmea_checksum: warn"), std::string::npos) << error;

  config_.nmea_checksum = "warn";
  const NmeaLog warned = read(lines);
  EXPECT_EQ(warned.fixes.size(), 60u);
  EXPECT_EQ(warned.bad_checksum, 60u);
  EXPECT_EQ(warned.vendor_sentences, 1u);
  ASSERT_EQ(warned.warnings.size(), 1u);
  EXPECT_NE(warned.warnings[0].find("60 of 60 RMC sentences failed their checksum"),
            std::string::npos)
      << warned.warnings[0];

  // Line noise: one GGA of 240 sentences.
  config_.nmea_checksum = "refuse";
  std::vector<std::string> noisy;
  for (int s = 0; s < 60; ++s) {
    const std::string t = fmt::format("1200{:02}", s);
    noisy.push_back(rmc(t, "010124"));
    noisy.push_back(gga(t));
    noisy.push_back(withNmeaChecksum("GPVTG,,T,,M,0.0,N,0.0,K,A"));
    noisy.push_back(withNmeaChecksum("GPGSV,1,1,00"));
  }
  noisy[5].back() = noisy[5].back() == '0' ? '1' : '0';  // the second GGA
  const NmeaLog log = read(noisy);
  EXPECT_EQ(log.fixes.size(), 59u);
  EXPECT_EQ(log.bad_checksum, 1u);
}

TEST_F(NmeaTest, LowercaseChecksumIsAccepted) {
  const std::string ref_lower =
      "$GPRMC,123519,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W*6a";
  const NmeaLog log = read({kRefGga, ref_lower});
  EXPECT_EQ(log.fixes.size(), 1u);
  EXPECT_EQ(log.bad_checksum, 0u);
}

TEST_F(NmeaTest, GgaWithoutFixIsSkipped) {
  const NmeaLog log =
      read({rmc("120000", "010124"), withNmeaChecksum("GPGGA,,,,,,0,00,99.99,,,,,,"),
            gga("120000", "0"), gga("120001"), withNmeaChecksum("GPGGA,120002,,,,,1,00,,,,,,,")});
  ASSERT_EQ(log.fixes.size(), 1u);
  EXPECT_EQ(log.no_fix, 3u);
  ASSERT_EQ(log.warnings.size(), 1u);
  EXPECT_NE(log.warnings[0].find("3 GGA sentences"), std::string::npos) << log.warnings[0];
  EXPECT_NE(log.warnings[0].find("line 2"), std::string::npos) << log.warnings[0];
}

TEST_F(NmeaTest, GstSigmasAreUsedForTheirEpoch) {
  const NmeaLog log =
      read({rmc("120000", "010124"), gga("120000"),
            withNmeaChecksum("GPGST,120000,1.2,3.0,2.0,45.0,0.3,0.4,0.9"), gga("120001")});
  ASSERT_EQ(log.fixes.size(), 2u);
  EXPECT_NEAR(log.fixes[0].sigma_h_m, std::sqrt((0.09 + 0.16) / 2.0), 1e-12);
  EXPECT_NEAR(log.fixes[0].sigma_v_m, 0.9, 1e-12);
  // No GST for the second epoch: the HDOP model applies.
  EXPECT_NEAR(log.fixes[1].sigma_h_m, 0.9 * config_.nmea_uere_spp_m, 1e-12);
}

// GST's error ellipse (semi-major, semi-minor, orientation of the major axis from true north)
// gives the fix's shape; receivers that leave it empty or zero state a circle.
TEST_F(NmeaTest, GstEllipseGivesTheShape) {
  const NmeaLog log =
      read({rmc("120000", "010124"), gga("120000"),
            withNmeaChecksum("GPGST,120000,1.2,3.0,1.0,45.0,2.24,2.24,4.0"), gga("120001"),
            withNmeaChecksum("GPGST,120001,1.2,,,,2.0,1.0,4.0"), gga("120002"),
            withNmeaChecksum("GPGST,120002,1.2,0.0,0.0,0.0,2.0,1.0,4.0")});
  ASSERT_EQ(log.fixes.size(), 3u);
  const Eigen::Matrix2d expected =
      fusion::horizontalShape(fusion::ellipseCovariance(3.0, 1.0, 45.0));
  EXPECT_LT((log.fixes[0].shape_en - expected).norm(), 1e-12);
  EXPECT_NEAR(log.fixes[0].shape_en(0, 1), 0.8, 1e-12);  // (9 - 1) / 2 over trace / 2 = 5
  EXPECT_NEAR(log.fixes[0].sigma_h_m, 2.24, 1e-12);      // from the latitude/longitude sigmas
  EXPECT_EQ(log.fixes[1].shape_en, Eigen::Matrix2d::Identity());
  EXPECT_EQ(log.fixes[2].shape_en, Eigen::Matrix2d::Identity());
  const std::string error =
      errorOf({rmc("120000", "010124"), gga("120000"),
               withNmeaChecksum("GPGST,120000,1.2,3.0,1.0,north,2.0,1.0,4.0")});
  EXPECT_NE(error.find(fileAt(3)), std::string::npos) << error;
  EXPECT_NE(error.find("ellipse orientation"), std::string::npos) << error;
}

TEST_F(NmeaTest, GstFromAnotherTalkerBeforeTheGgaCounts) {
  const NmeaLog log = read({withNmeaChecksum("GNGST,120000.00,,,,,1.0,1.0,2.0"),
                            rmc("120000.00", "010124"), gga("120000")});
  ASSERT_EQ(log.fixes.size(), 1u);
  EXPECT_NEAR(log.fixes[0].sigma_h_m, 1.0, 1e-12);
  EXPECT_NEAR(log.fixes[0].sigma_v_m, 2.0, 1e-12);
}

TEST_F(NmeaTest, HdopSigmaDependsOnQuality) {
  config_.nmea_vertical_factor = 1.5;
  const NmeaLog log =
      read({rmc("120000", "010124"), gga("120000", "1", "2.0"), gga("120001", "2", "2.0"),
            gga("120002", "4", "2.0"), gga("120003", "5", "2.0"), gga("120004", "6", "2.0"),
            gga("120005", "4", ""), gga("120006", "4", "0.0")});
  ASSERT_EQ(log.fixes.size(), 7u);
  const double expected[] = {
      2.0 * config_.nmea_uere_spp_m,       2.0 * config_.nmea_uere_dgps_m,
      2.0 * config_.nmea_uere_rtk_fixed_m, 2.0 * config_.nmea_uere_rtk_float_m,
      2.0 * config_.nmea_uere_spp_m,       config_.nmea_uere_rtk_fixed_m,
      config_.nmea_uere_rtk_fixed_m};
  for (std::size_t i = 0; i < log.fixes.size(); ++i) {
    EXPECT_NEAR(log.fixes[i].sigma_h_m, expected[i], 1e-12) << "fix " << i;
    EXPECT_NEAR(log.fixes[i].sigma_v_m, 1.5 * expected[i], 1e-12) << "fix " << i;
  }
  EXPECT_EQ(log.fixes[5].hdop, 0.0);  // not reported stays 0
}

TEST_F(NmeaTest, OtherSentencesAndTalkersAreCounted) {
  const NmeaLog log =
      read({withNmeaChecksum("GPGSV,3,1,11,03,03,111,00,04,15,270,00,06,01,010,00,13,06,292,00"),
            withNmeaChecksum("GPVTG,054.7,T,034.4,M,005.5,N,010.2,K"), withNmeaChecksum("PUBX,00"),
            rmc("120000", "010124"),
            withNmeaChecksum("GLGGA,120000,4807.038,N,01131.000,E,1,08,"
                             "0.9,545.4,M,46.9,M,,")});
  EXPECT_EQ(log.fixes.size(), 1u);
  EXPECT_EQ(log.other_sentences, 3u);
  EXPECT_EQ(log.sentences, 5u);
}

TEST_F(NmeaTest, CrlfLineEndingsBomAndBlankLines) {
  const NmeaLog log =
      read({"\xEF\xBB\xBF" + std::string(kRefRmc), "", "  ", std::string(kRefGga) + "  "}, "\r\n");
  ASSERT_EQ(log.fixes.size(), 1u);
  EXPECT_EQ(log.fixes[0].t_ns, kRefUnixSeconds * kNs);
  EXPECT_EQ(log.bad_checksum, 0u);
}

TEST_F(NmeaTest, NoGgaFixIsValidAndEmpty) {
  EXPECT_TRUE(read({}).fixes.empty());
  EXPECT_TRUE(read({withNmeaChecksum("GPGGA,,,,,,0,00,99.99,,,,,,")}).fixes.empty());
}

TEST_F(NmeaTest, NoRmcIsAnError) {
  const std::string error = errorOf({gga("120000"), gga("120001")});
  EXPECT_NE(error.find("no RMC sentence"), std::string::npos) << error;
  EXPECT_EQ(error.find(fileAt(1)), std::string::npos) << error;  // names the file, no line
}

TEST_F(NmeaTest, MalformedGgaNamesTheLine) {
  const std::vector<std::string> bad_bodies = {
      "GPGGA,120001,48x7.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,",  // non-numeric
      "GPGGA,120001,4867.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,",  // minutes >= 60
      "GPGGA,120001,9107.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,",  // latitude > 90
      "GPGGA,120001,4807.038,X,01131.000,E,1,08,0.9,545.4,M,46.9,M,,",  // hemisphere
      "GPGGA,120001,4807.038,N,18131.000,E,1,08,0.9,545.4,M,46.9,M,,",  // longitude > 180
      "GPGGA,126001,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,",  // minute 60
      "GPGGA,120001,4807.038,N,01131.000,E,1,08,0.9,,M,46.9,M,,",       // no altitude
      "GPGGA,120001,4807.038,N,01131.000,E,A,08,0.9,545.4,M,46.9,M,,",  // quality
      "GPGGA,120001,4807.038,N,01131.000,E,1",                          // too few fields
  };
  for (const auto& body : bad_bodies) {
    const std::string error =
        errorOf({rmc("120000", "010124"), gga("120000"), "", withNmeaChecksum(body)});
    EXPECT_NE(error.find(fileAt(4) + ": malformed GGA"), std::string::npos) << body << "\n"
                                                                            << error;
  }
}

TEST_F(NmeaTest, MalformedRmcDateNamesTheLine) {
  const std::string error = errorOf({gga("120000"), rmc("120000", "320124")});
  EXPECT_NE(error.find(fileAt(2) + ": malformed RMC"), std::string::npos) << error;
}

TEST_F(NmeaTest, NonIncreasingTimeNamesTheLine) {
  const std::string error =
      errorOf({rmc("120000", "010124"), gga("120000"), gga("120001"), gga("120001")});
  EXPECT_NE(error.find(fileAt(4) + ": timestamp not increasing"), std::string::npos) << error;
}

TEST_F(NmeaTest, GarbageLineIsAnError) {
  const std::string error = errorOf({rmc("120000", "010124"), "hello", gga("120000")});
  EXPECT_NE(error.find(fileAt(2) + ": not an NMEA sentence"), std::string::npos) << error;
}

TEST_F(NmeaTest, MissingFileIsAnError) {
  try {
    readNmea(dir_ / "absent.nmea", config_);
    FAIL() << "no InputError thrown";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("file not found"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace gvio::io
