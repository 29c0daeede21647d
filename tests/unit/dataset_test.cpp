// Dataset front door: format detection and names, the time-ordered measurement stream, and the
// "holds nothing" check of readDataset.
#include "io/dataset.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <limits>
#include <set>
#include <string>
#include <variant>

#include "io/input_error.hpp"
#include "io/measurement_stream.hpp"
#include "io/nmea.hpp"
#include "odometry/error.hpp"
#include "support/errors.hpp"
#include "support/fixtures.hpp"

namespace gvio::io {
namespace {

namespace fs = std::filesystem;
using test::inputError;
using test::names;
using ::testing::HasSubstr;
using ::testing::StartsWith;

class DatasetTest : public ::testing::Test {
 protected:
  [[nodiscard]] fs::path kitti(const test::KittiFixture& spec = {}) const {
    return test::writeKittiFixture(tmp_.path(), spec);
  }
  test::TempDir tmp_{"dataset"};
};

TEST_F(DatasetTest, DetectsKittiRawDrive) {
  EXPECT_EQ(detectFormat(kitti()), DatasetFormat::kKittiRaw);
}

TEST_F(DatasetTest, DetectsEurocFolderAndMav0Itself) {
  const fs::path root = tmp_.path() / "V1_01";
  test::writeText(root / "mav0" / "imu0" / "data.csv", "#timestamp\n");
  EXPECT_EQ(detectFormat(root), DatasetFormat::kEuroc);
  EXPECT_EQ(detectFormat(root / "mav0"), DatasetFormat::kEuroc);
}

TEST_F(DatasetTest, DetectsNmeaFile) {
  const fs::path log = tmp_.path() / "drive.nmea";
  test::writeText(
      log, withNmeaChecksum("GPRMC,130200.00,A,4900.6600,N,00824.0000,E,0,0,260911,,,A") + "\r\n");
  EXPECT_EQ(detectFormat(log), DatasetFormat::kNmea);

  const fs::path text = tmp_.path() / "notes.txt";
  test::writeText(text, "just some notes\n");
  EXPECT_THAT(inputError([&] { detectFormat(text); }), StartsWith(text.string() + ": "));
}

TEST_F(DatasetTest, EmptyFolderIsNotADataset) {
  const fs::path empty = tmp_.path() / "empty";
  fs::create_directories(empty);
  const std::string message = inputError([&] { detectFormat(empty); });
  EXPECT_THAT(message, StartsWith(empty.string() + ": "));
  EXPECT_THAT(message, HasSubstr("unrecognised dataset layout"));
}

TEST_F(DatasetTest, MissingPath) {
  const fs::path missing = tmp_.path() / "nowhere";
  EXPECT_EQ(inputError([&] { detectFormat(missing); }), missing.string() + ": dataset not found");
  EXPECT_THAT(inputError([&] { readDataset(missing, std::nullopt, ReaderConfig{}); }),
              StartsWith(missing.string() + ": "));
}

TEST(DatasetFormatName, ParsesKnownNamesAndRejectsOthers) {
  EXPECT_EQ(parseDatasetFormat("auto"), std::nullopt);
  EXPECT_EQ(parseDatasetFormat("kitti-raw"), DatasetFormat::kKittiRaw);
  EXPECT_EQ(parseDatasetFormat("euroc"), DatasetFormat::kEuroc);
  EXPECT_EQ(parseDatasetFormat("nmea"), DatasetFormat::kNmea);
  for (const auto format : {DatasetFormat::kKittiRaw, DatasetFormat::kEuroc, DatasetFormat::kNmea})
    EXPECT_EQ(parseDatasetFormat(toString(format)), format);
  EXPECT_THROW(parseDatasetFormat("kitti"), gvio::InvalidInput);
  EXPECT_THROW(parseDatasetFormat(""), gvio::InvalidInput);
  std::string message;
  try {
    parseDatasetFormat("EuRoC");  // names are case-sensitive
  } catch (const gvio::InvalidInput& e) {
    message = e.what();
  }
  EXPECT_THAT(message, HasSubstr("unknown dataset format 'EuRoC'"));
}

TEST_F(DatasetTest, EmptyEurocHoldsNothing) {
  const fs::path mav0 = tmp_.path() / "empty_euroc" / "mav0";
  test::writeText(mav0 / "imu0" / "data.csv", "#timestamp [ns],w_x,w_y,w_z,a_x,a_y,a_z\n");
  const std::string message = inputError([&] { readDataset(mav0, std::nullopt, ReaderConfig{}); });
  EXPECT_THAT(message, StartsWith(mav0.string() + ": "));
  EXPECT_THAT(message, HasSubstr("holds no"));
}

// ---- MeasurementStream ----

// Kind of a measurement: 0 IMU, 1 frame, 2 GNSS.
std::size_t kindOf(const Measurement& m) {
  return m.index();
}

// Drains the stream, checking it yields every record exactly once in non-decreasing time order
// and that every frame has all IMU samples up to its stamp before it.
void checkStream(const Dataset& ds) {
  MeasurementStream stream(ds);
  std::set<const void*> seen;
  std::size_t count = 0, imu_seen = 0;
  std::int64_t last = std::numeric_limits<std::int64_t>::min();
  while (const auto m = stream.next()) {
    ++count;
    const std::int64_t t = stampOf(*m);
    ASSERT_GE(t, last) << "record " << count;
    last = t;
    std::visit([&](const auto* record) { EXPECT_TRUE(seen.insert(record).second); }, *m);
    if (kindOf(*m) == 0) ++imu_seen;
    if (kindOf(*m) == 1) {
      std::size_t imu_upto = 0;
      for (const auto& s : ds.imu) imu_upto += s.t_ns <= t ? 1 : 0;
      EXPECT_EQ(imu_seen, imu_upto) << "frame at " << t;
    }
  }
  EXPECT_EQ(count, stream.total());
  EXPECT_EQ(seen.size(), ds.imu.size() + ds.frames.size() + ds.gnss.size());
  EXPECT_FALSE(stream.next().has_value());  // stays at the end
}

TEST_F(DatasetTest, StreamMergesKittiDriveInTimeOrder) {
  test::KittiFixture spec;
  spec.frames = 20;
  spec.write_nmea = true;
  spec.nmea_rate_hz = 5;
  const Dataset ds = readDataset(kitti(spec), std::nullopt, ReaderConfig{});
  ASSERT_EQ(ds.imu.size(), 200U);
  ASSERT_EQ(ds.frames.size(), 20U);
  ASSERT_FALSE(ds.gnss.empty());
  // The fixture stamps frames exactly on oxts samples: ties between IMU and frames are exercised.
  ASSERT_EQ(ds.frames[3].t_ns, ds.imu[30].t_ns);
  checkStream(ds);
}

TEST(StreamOrder, ImuComesFirstAtEqualStamps) {
  Dataset ds;
  for (const std::int64_t t : {0, 10, 20, 25, 30}) ds.imu.emplace_back().t_ns = t;
  ds.frames = {FrameRecord{10, {}}, FrameRecord{20, {}}, FrameRecord{40, {}}};
  ds.gnss.resize(2);
  ds.gnss[0].t_ns = 5;
  ds.gnss[1].t_ns = 20;
  MeasurementStream stream(ds);
  EXPECT_EQ(stream.total(), 10U);
  std::string order;
  while (const auto m = stream.next()) order += "IFG"[kindOf(*m)];
  EXPECT_EQ(order, "IGIFIFGIIF");
  checkStream(ds);
}

TEST(StreamOrder, EmptyDatasetYieldsNothing) {
  const Dataset ds;
  MeasurementStream stream(ds);
  EXPECT_EQ(stream.total(), 0U);
  EXPECT_FALSE(stream.next().has_value());
}

}  // namespace
}  // namespace gvio::io
