#include "io/text.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "io/input_error.hpp"
#include "odometry/trajectory.hpp"
#include "support/fixtures.hpp"

namespace gvio::io {
namespace {
using testing::HasSubstr;

std::int64_t ns(std::string_view s) {
  std::int64_t t = 0;
  EXPECT_TRUE(secondsToNs(s, t)) << s;
  return t;
}

TEST(Text, SecondsToNsIsExact) {
  EXPECT_EQ(ns("1403715273.262142976"), 1403715273262142976LL);
  EXPECT_EQ(ns("0.1"), 100'000'000);
  EXPECT_EQ(ns("-1.5"), -1'500'000'000);
  EXPECT_EQ(ns("12"), 12'000'000'000);
  EXPECT_EQ(ns("1.0000000005"), 1'000'000'001);  // 10th digit rounds
  EXPECT_EQ(ns("1.037359e-01"), 103'735'900);
  EXPECT_EQ(ns("4.705816e+02"), 470'581'600'000);
  std::int64_t t = 0;
  for (const char* bad : {"", ".", "1.2.3", "abc", "nan", "1e400", "99999999999", "1,5"}) {
    EXPECT_FALSE(secondsToNs(bad, t)) << bad;
  }
}

TEST(Text, FormatSecondsRoundTrips) {
  for (const std::int64_t t :
       {0LL, 1LL, 999'999'999LL, 1403715273262142976LL, -1'500'000'000LL, -1LL}) {
    EXPECT_EQ(ns(formatSeconds(t)), t);
  }
  EXPECT_EQ(formatSeconds(-1), "-0.000000001");
}

TEST(Text, KittiTimestamps) {
  std::int64_t t = 0;
  ASSERT_TRUE(kittiTimestampToNs("2011-09-26 13:02:25.594360375", t));
  EXPECT_EQ(t, 1317042145594360375LL);  // date -u -d '2011-09-26 13:02:25' +%s = 1317042145
  ASSERT_TRUE(kittiTimestampToNs("1970-01-01 00:00:00", t));
  EXPECT_EQ(t, 0);
  for (const char* bad : {"2011-09-26", "2011-13-26 13:02:25.5", "2011-09-26T13:02:25.5",
                          "2011-09-26 13:02:25,5", "2011-09-26 25:02:25.5"}) {
    EXPECT_FALSE(kittiTimestampToNs(bad, t)) << bad;
  }
}

TEST(Text, KittiTimestampsRoundTrip) {
  for (const std::int64_t t : {0LL, 1317042145594360375LL, 951782400123456789LL /* 2000-02-29 */,
                               4102444799999999999LL /* 2099-12-31 23:59:59.999999999 */}) {
    std::int64_t back = 0;
    ASSERT_TRUE(kittiTimestampToNs(formatKittiTimestamp(t), back)) << formatKittiTimestamp(t);
    EXPECT_EQ(back, t);
  }
  EXPECT_EQ(formatKittiTimestamp(1317042145594360375LL), "2011-09-26 13:02:25.594360375");
  for (std::int64_t days = -800; days < 800000; days += 997) {
    const CivilDate d = civilFromDays(days);
    EXPECT_EQ(daysFromCivil(d.year, d.month, d.day), days);
  }
}

TEST(Text, Splitting) {
  EXPECT_EQ(splitDelimited(" a, b ,,c", ','), (std::vector<std::string_view>{"a", "b", "", "c"}));
  EXPECT_EQ(splitWhitespace("  1 \t2   3 "), (std::vector<std::string_view>{"1", "2", "3"}));
  EXPECT_TRUE(isBlankOrComment("  # note"));
  EXPECT_FALSE(isBlankOrComment(" 1 # note"));
}

TEST(Text, ColumnsByNameNameFileLineAndExpectedHeader) {
  test::TempDir dir("text");
  test::writeText(dir.path() / "f.csv", "b,a,c\n1,2,3\n");
  LineReader reader(dir.path() / "f.csv");
  std::string line;
  reader.next(line);
  const std::vector<std::string> header = {"b", "a", "c"};
  EXPECT_EQ(columnIndex(header, "a", reader), 1U);
  EXPECT_EQ(columnIndex(header, "c", reader, "a,c"), 2U);
  try {
    (void)columnIndex(header, "d", reader, "a,d");
    ADD_FAILURE() << "no column d";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("f.csv:1: header has no column 'd' (expected a,d)"));
  }
}

TEST(Text, StrictNumbersNameFileAndLine) {
  test::TempDir dir("text");
  test::writeText(dir.path() / "f.txt", "first\nsecond\n");
  LineReader reader(dir.path() / "f.txt");
  std::string line;
  reader.next(line);
  reader.next(line);
  EXPECT_DOUBLE_EQ(parseFinite("+1.5e3", reader, "x"), 1500.0);
  for (const char* bad : {"nan", "inf", "-inf", "1.5x", "", "0x10"}) {
    try {
      parseFinite(bad, reader, "speed");
      ADD_FAILURE() << bad;
    } catch (const InputError& e) {
      EXPECT_THAT(e.what(), HasSubstr("f.txt:2: "));
      EXPECT_THAT(e.what(), HasSubstr("speed"));
    }
  }
  EXPECT_THROW(parseInt64("12.5", reader, "count"), InputError);
}

TEST(Text, LineReaderErrors) {
  test::TempDir dir("text");
  EXPECT_THROW(LineReader(dir.path() / "missing.txt"), InputError);
  EXPECT_THROW(LineReader(dir.path()), InputError);
  test::writeText(dir.path() / "crlf.txt", "a\r\nb\r\n");
  LineReader reader(dir.path() / "crlf.txt");
  std::string line;
  ASSERT_TRUE(reader.next(line));
  EXPECT_EQ(line, "a");
}

TEST(Trajectory, PathLengthAndStampOrder) {
  Trajectory traj;
  for (int i = 0; i < 4; ++i) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = Eigen::Vector3d(3.0 * i, 4.0 * i, 0.0);
    traj.poses.push_back(T);
    traj.t_ns.push_back(i * 10);
  }
  EXPECT_DOUBLE_EQ(pathLengthM(traj), 15.0);
  EXPECT_EQ(firstNonIncreasingStamp(traj), -1);
  traj.t_ns[2] = traj.t_ns[1];
  EXPECT_EQ(firstNonIncreasingStamp(traj), 2);
}

}  // namespace
}  // namespace gvio::io
