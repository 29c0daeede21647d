// CDR reading and writing (io/ros2/cdr.hpp) and the ROS 2 messages on top of it
// (io/ros2/ros2_messages.hpp): hand-written golden bytes, round trips of every type, and damaged
// or foreign messages, each of which must end in a Ros2Error.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "io/ros2/cdr.hpp"
#include "io/ros2/ros2_error.hpp"
#include "io/ros2/ros2_messages.hpp"

namespace gvio::io::ros2 {
namespace {

using Bytes = std::vector<std::uint8_t>;
using Decoder = void (*)(std::span<const std::uint8_t>);

// The what() of the Ros2Error `fn` throws, or "" (with a test failure) when it throws none.
template <typename Fn>
std::string ros2Error(Fn&& fn) {
  try {
    fn();
  } catch (const Ros2Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected a Ros2Error";
  return {};
}

::testing::AssertionResult mentions(const std::string& message, const std::string& phrase) {
  if (message.find(phrase) != std::string::npos) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "'" << message << "' lacks '" << phrase << "'";
}

std::uint64_t bits(double value) {
  return std::bit_cast<std::uint64_t>(value);
}

// A double's IEEE 754 bit pattern, appended little-endian (the golden messages' float64 fields).
void appendLe(Bytes& out, std::uint64_t pattern) {
  for (int i = 0; i < 8; ++i) out.push_back(static_cast<std::uint8_t>(pattern >> (8 * i)));
}

constexpr std::uint64_t kOne = 0x3FF0000000000000;         // 1.0
constexpr std::uint64_t kTwo = 0x4000000000000000;         // 2.0
constexpr std::uint64_t kMinusHalf = 0xBFE0000000000000;   // -0.5
constexpr std::uint64_t kMinusOne = 0xBFF0000000000000;    // -1.0
constexpr std::uint64_t kQuarter = 0x3FD0000000000000;     // 0.25
constexpr std::uint64_t kNanPayload = 0x7FF8000000C0FFEE;  // a quiet NaN with a payload

const Decoder kDecoders[] = {
    [](std::span<const std::uint8_t> m) { (void)decodeImu(m); },
    [](std::span<const std::uint8_t> m) { (void)decodeNavSatFix(m); },
    [](std::span<const std::uint8_t> m) { (void)decodeImage(m); },
    [](std::span<const std::uint8_t> m) { (void)decodeCompressedImage(m); },
    [](std::span<const std::uint8_t> m) { (void)decodeCameraInfo(m); },
    [](std::span<const std::uint8_t> m) { (void)decodeTfMessage(m); },
};
constexpr const char* kTypes[] = {kRos2ImuType,        kRos2NavSatFixType,
                                  kRos2ImageType,      kRos2CompressedImageType,
                                  kRos2CameraInfoType, kRos2TfType};

// ---- sample messages, one of each type, in kTypes' order ----

Ros2Imu sampleImu(const std::string& frame) {
  Ros2Imu m;
  m.imu.t.header_ns = -1'700'000'000;  // {sec: -2, nanosec: 3e8}
  m.imu.acc_mps2 = {0.1, -9.81, std::numeric_limits<double>::infinity()};
  m.imu.gyr_radps = {std::bit_cast<double>(kNanPayload), -0.0, 1e-300};
  m.imu.orientation_xyzw = {0.5, -0.5, 0.5, -0.5};
  m.imu.orientation_covariance[0] = -1.0;
  m.angular_velocity_covariance[4] = 1e-6;
  m.linear_acceleration_covariance[8] = std::numeric_limits<double>::denorm_min();
  m.frame_id = frame;
  return m;
}

Ros2NavSatFix sampleFix(const std::string& frame) {
  Ros2NavSatFix m;
  m.fix.t.header_ns = 1'700'000'000'123'456'789;
  m.fix.status = -2;
  m.service = 0xFFFF;
  m.fix.lat_deg = 48.1;
  m.fix.lon_deg = -11.5;
  m.fix.alt_m = std::numeric_limits<double>::quiet_NaN();
  m.fix.covariance_enu_m2 = {1, 2, 3, 4, 5, 6, 7, 8, 9};
  m.fix.covariance_type = 255;
  m.frame_id = frame;
  return m;
}

Ros2Image sampleImage(const std::string& frame, std::size_t pixels) {
  Ros2Image m;
  m.image.t.header_ns = 5;
  m.image.height = 1;
  m.image.width = static_cast<std::uint32_t>(pixels);
  m.image.step = static_cast<std::uint32_t>(pixels);
  m.image.encoding = frame.empty() ? "" : "mono8";
  m.image.big_endian = true;
  for (std::size_t i = 0; i < pixels; ++i) m.image.data.push_back(static_cast<std::uint8_t>(i));
  m.frame_id = frame;
  return m;
}

Ros2Image sampleCompressed(const std::string& frame) {
  Ros2Image m;
  m.image.t.header_ns = std::int64_t{std::numeric_limits<std::int32_t>::max()} * 1'000'000'000 +
                        999'999'999;  // the last stamp Time holds
  m.image.compressed = true;
  m.image.format = frame + "jpeg";
  m.image.data = Bytes(frame.size(), 0xFF);
  m.frame_id = frame;
  return m;
}

CameraInfoMessage sampleCameraInfo(const std::string& frame) {
  CameraInfoMessage m;
  m.t.header_ns = std::int64_t{std::numeric_limits<std::int32_t>::min()} * 1'000'000'000;
  m.frame_id = frame;
  m.height = 480;
  m.width = 752;
  m.distortion_model = frame.empty() ? "" : "plumb_bob";
  m.d.assign(frame.size(), -0.25);  // 0 to 9 coefficients
  m.k = {458.654, 0, 367.215, 0, 457.296, 248.375, 0, 0, 1};
  m.r = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  m.p = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12};
  m.binning_x = 2;
  m.binning_y = 3;
  m.roi = {1, 2, 3, 4, true};
  return m;
}

std::vector<TransformMessage> sampleTf(const std::string& frame) {
  std::vector<TransformMessage> transforms;
  for (std::size_t i = 0; i < frame.size() % 3; ++i) {  // 0, 1 or 2 transforms
    TransformMessage t;
    t.t.header_ns = static_cast<std::int64_t>(i) * 1'000'000'001;
    t.frame_id = frame;
    t.child_frame_id = frame.substr(i);
    t.translation = {1.0, -2.0, std::bit_cast<double>(kNanPayload)};
    t.rotation_xyzw = {0.0, 0.0, std::sqrt(0.5), std::sqrt(0.5)};
    transforms.push_back(t);
  }
  return transforms;
}

std::vector<Bytes> samples(const std::string& frame) {
  return {encodeImu(sampleImu(frame)),
          encodeNavSatFix(sampleFix(frame)),
          encodeImage(sampleImage(frame, 7)),
          encodeCompressedImage(sampleCompressed(frame)),
          encodeCameraInfo(sampleCameraInfo(frame)),
          encodeTfMessage(sampleTf(frame))};
}

// ---- golden bytes ----

// clang-format off
// sensor_msgs/NavSatFix, frame_id "ab": after the 3-byte string (offset 15, counted from the end
// of the encapsulation header) status lands at 15, service pads to 16, latitude pads to 24.
const Bytes kNavSatFixLe = {
    0x00, 0x01, 0x00, 0x00,                          // CDR_LE
    0x01, 0x00, 0x00, 0x00, 0x02, 0x00, 0x00, 0x00,  // stamp: sec 1, nanosec 2
    0x03, 0x00, 0x00, 0x00, 'a', 'b', 0x00,          // frame_id "ab" (the length counts the NUL)
    0xFF,                                            // status.status -1 (at offset 15)
    0x01, 0x00,                                      // status.service 1 (at 16)
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00,              // padding to 24
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xF0, 0x3F,  // latitude 1.0
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x40,  // longitude 2.0
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xE0, 0xBF,  // altitude -0.5
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xD0, 0x3F,  // position_covariance[0] 0.25
    0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0,  // [1..3] 0
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xD0, 0x3F,  // [4] 0.25
    0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0,  // [5..7] 0
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xF0, 0x3F,  // [8] 1.0
    0x02,                                            // position_covariance_type 2
};

// The same message big-endian (CDR_BE): the same layout, every number's bytes reversed.
const Bytes kNavSatFixBe = {
    0x00, 0x00, 0x00, 0x00,                          // CDR_BE
    0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x02,  // stamp
    0x00, 0x00, 0x00, 0x03, 'a', 'b', 0x00,          // frame_id
    0xFF, 0x00, 0x01,                                // status, service
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00,              // padding to 24
    0x3F, 0xF0, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,  // latitude
    0x40, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,  // longitude
    0xBF, 0xE0, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,  // altitude
    0x3F, 0xD0, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,  // [0]
    0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0,  // [1..3]
    0x3F, 0xD0, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,  // [4]
    0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0,  // [5..7]
    0x3F, 0xF0, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,  // [8]
    0x02,
};

// sensor_msgs/Imu, frame_id "imu0" (5 bytes, ends at offset 17): orientation pads to 24; then
// 37 float64, given as their bit patterns.
const Bytes kImuHead = {
    0x00, 0x01, 0x00, 0x00,                          // CDR_LE
    0x0A, 0x00, 0x00, 0x00, 0x00, 0x65, 0xCD, 0x1D,  // sec 10, nanosec 5e8 (0x1DCD6500)
    0x05, 0x00, 0x00, 0x00, 'i', 'm', 'u', '0', 0x00,  // frame_id "imu0"
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,        // padding to 24
};
const std::uint64_t kImuFields[37] = {
    0, 0, 0, kOne,                                    // orientation x y z w
    kMinusOne, 0, 0, 0, 0, 0, 0, 0, 0,                // orientation_covariance
    kQuarter, 0, kMinusHalf,                          // angular_velocity
    0, 0, 0, 0, 0, 0, 0, 0, 0,                        // angular_velocity_covariance
    0, kTwo, kNanPayload,                             // linear_acceleration
    kQuarter, 0, 0, 0, kQuarter, 0, 0, 0, kQuarter,   // linear_acceleration_covariance
};
// clang-format on

void expectGoldenFix(const Ros2NavSatFix& m) {
  EXPECT_EQ(m.fix.t.header_ns, 1'000'000'002);
  EXPECT_EQ(m.fix.t.receive_ns, 0);
  EXPECT_EQ(m.frame_id, "ab");
  EXPECT_EQ(m.fix.status, -1);
  EXPECT_EQ(m.service, 1);
  EXPECT_EQ(bits(m.fix.lat_deg), kOne);
  EXPECT_EQ(bits(m.fix.lon_deg), kTwo);
  EXPECT_EQ(bits(m.fix.alt_m), kMinusHalf);
  EXPECT_EQ(m.fix.covariance_enu_m2, (std::array<double, 9>{0.25, 0, 0, 0, 0.25, 0, 0, 0, 1}));
  EXPECT_EQ(m.fix.covariance_type, 2);
}

TEST(CdrGolden, NavSatFixLittleEndian) {
  expectGoldenFix(decodeNavSatFix(kNavSatFixLe));
  Ros2NavSatFix m;
  m.fix.t.header_ns = 1'000'000'002;
  m.frame_id = "ab";
  m.fix.status = -1;
  m.service = 1;
  m.fix.lat_deg = 1.0;
  m.fix.lon_deg = 2.0;
  m.fix.alt_m = -0.5;
  m.fix.covariance_enu_m2 = {0.25, 0, 0, 0, 0.25, 0, 0, 0, 1};
  m.fix.covariance_type = 2;
  EXPECT_EQ(encodeNavSatFix(m), kNavSatFixLe);
}

TEST(CdrGolden, NavSatFixBigEndian) {
  expectGoldenFix(decodeNavSatFix(kNavSatFixBe));
}

TEST(CdrGolden, ImuLittleEndian) {
  Bytes expected = kImuHead;
  for (const std::uint64_t pattern : kImuFields) appendLe(expected, pattern);
  ASSERT_EQ(expected.size(), 4u + 24u + 37u * 8u);

  Ros2Imu m;
  m.imu.t.header_ns = 10'500'000'000;
  m.frame_id = "imu0";
  m.imu.orientation_covariance[0] = -1.0;
  m.imu.gyr_radps = {0.25, 0.0, -0.5};
  m.imu.acc_mps2 = {0.0, 2.0, std::bit_cast<double>(kNanPayload)};
  m.linear_acceleration_covariance = {0.25, 0, 0, 0, 0.25, 0, 0, 0, 0.25};
  EXPECT_EQ(encodeImu(m), expected);

  const Ros2Imu back = decodeImu(expected);
  EXPECT_EQ(back.imu.t.header_ns, 10'500'000'000);
  EXPECT_EQ(back.frame_id, "imu0");
  EXPECT_EQ(back.imu.orientation_xyzw, (std::array<double, 4>{0, 0, 0, 1}));
  EXPECT_EQ(back.imu.orientation_covariance[0], -1.0);
  EXPECT_EQ(back.imu.gyr_radps, m.imu.gyr_radps);
  EXPECT_EQ(bits(back.imu.acc_mps2[2]), kNanPayload);
  EXPECT_EQ(back.linear_acceleration_covariance, m.linear_acceleration_covariance);
}

// ---- the reader and writer themselves ----

TEST(CdrReader, AlignsRelativeToTheEndOfTheEncapsulationHeader) {
  CdrWriter w;
  w.u8(7);
  w.u32(0x01020304);  // pads 3 bytes: at offset 4, buffer byte 8
  w.u8(8);
  w.f64(1.0);  // pads 7 bytes: at offset 16, buffer byte 20
  w.u16(0xBEEF);
  const Bytes b = w.take();
  ASSERT_EQ(b.size(), 4u + 26u);
  EXPECT_EQ(b[8], 0x04);
  EXPECT_EQ(b[27], 0x3F);
  CdrReader r(b);
  EXPECT_FALSE(r.bigEndian());
  EXPECT_EQ(r.u8("a"), 7);
  EXPECT_EQ(r.u32("b"), 0x01020304u);
  EXPECT_EQ(r.u8("c"), 8);
  EXPECT_EQ(r.f64("d"), 1.0);
  EXPECT_EQ(r.u16("e"), 0xBEEF);
  EXPECT_EQ(r.remaining(), 0u);
  EXPECT_EQ(w.take(), (Bytes{0x00, 0x01, 0x00, 0x00}));  // take() starts a new message
}

TEST(CdrReader, RefusesOtherEncapsulations) {
  const Bytes pl_cdr = {0x00, 0x03, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00};
  const std::string e = ros2Error([&] { CdrReader r(pl_cdr, "sensor_msgs/msg/Imu"); });
  EXPECT_TRUE(mentions(e, "sensor_msgs/msg/Imu"));
  EXPECT_TRUE(mentions(e, "0x0003 (PL_CDR_LE"));
  EXPECT_TRUE(mentions(ros2Error([] {
                         (void)decodeImu(Bytes{0x00, 0x02, 0x00, 0x00});
                       }),
                       "PL_CDR_BE"));
  EXPECT_TRUE(mentions(ros2Error([] {
                         (void)decodeImu(Bytes{0x00, 0x07, 0x00, 0x00});
                       }),
                       "CDR2_LE"));
  EXPECT_TRUE(mentions(ros2Error([] {
                         (void)decodeImu(Bytes{0x00, 0x01, 0x00});
                       }),
                       "shorter than the 4-byte CDR encapsulation header"));
}

TEST(CdrReader, ChecksStringsBoolsAndLengths) {
  const Bytes unterminated = {0x00, 0x01, 0x00, 0x00, 0x03, 0x00, 0x00, 0x00, 'a', 'b', 'c'};
  EXPECT_TRUE(mentions(ros2Error([&] { CdrReader(unterminated).string("name"); }),
                       "its name (3 bytes) does not end in a NUL"));
  const Bytes empty = {0x00, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00};  // length 0: Fast CDR's ""
  EXPECT_EQ(CdrReader(empty).string("name"), "");
  const Bytes two = {0x00, 0x01, 0x00, 0x00, 0x02};
  EXPECT_TRUE(mentions(ros2Error([&] { CdrReader(two).boolean("flag"); }), "not a bool"));
  // A count times the least element size must fit in what follows; the division cannot overflow.
  const Bytes three = {0x00, 0x01, 0x00, 0x00, 0x03, 0x00, 0x00, 0x00, 1, 2, 3, 4, 5, 6};
  EXPECT_EQ(CdrReader(three).sequenceLength("s", 2), 3u);
  EXPECT_THROW(CdrReader(three).sequenceLength("s", 3), Ros2Error);
  EXPECT_THROW(CdrReader(three).sequenceLength("s", std::numeric_limits<std::size_t>::max()),
               Ros2Error);
}

// ---- round trips: every type, frame ids of 0..9 characters (every padding after them) ----

TEST(Ros2MessageRoundTrip, EveryTypeGivesBackItsValues) {
  for (std::size_t n = 0; n <= 9; ++n) {
    SCOPED_TRACE(n);
    const std::string frame(n, static_cast<char>('a' + n));
    const std::vector<Bytes> encoded = samples(frame);

    const Ros2Imu imu = decodeImu(encoded[0]);
    EXPECT_EQ(imu.frame_id, frame);
    EXPECT_EQ(imu.imu.t.header_ns, -1'700'000'000);
    EXPECT_EQ(bits(imu.imu.gyr_radps[0]), kNanPayload);
    EXPECT_EQ(bits(imu.imu.gyr_radps[1]), bits(-0.0));
    EXPECT_EQ(encodeImu(imu), encoded[0]);

    const Ros2NavSatFix fix = decodeNavSatFix(encoded[1]);
    EXPECT_EQ(fix.frame_id, frame);
    EXPECT_EQ(fix.fix.t.header_ns, 1'700'000'000'123'456'789);
    EXPECT_EQ(fix.fix.status, -2);
    EXPECT_EQ(fix.service, 0xFFFF);
    EXPECT_EQ(fix.fix.covariance_type, 255);
    EXPECT_TRUE(std::isnan(fix.fix.alt_m));
    EXPECT_EQ(encodeNavSatFix(fix), encoded[1]);

    const Ros2Image image = decodeImage(encoded[2]);
    EXPECT_EQ(image.frame_id, frame);
    EXPECT_FALSE(image.image.compressed);
    EXPECT_EQ(image.image.data, sampleImage(frame, 7).image.data);
    EXPECT_TRUE(image.image.big_endian);
    EXPECT_EQ(encodeImage(image), encoded[2]);

    const Ros2Image compressed = decodeCompressedImage(encoded[3]);
    EXPECT_EQ(compressed.frame_id, frame);
    EXPECT_TRUE(compressed.image.compressed);
    EXPECT_EQ(compressed.image.format, frame + "jpeg");
    EXPECT_EQ(compressed.image.data.size(), n);
    EXPECT_EQ(compressed.image.t.header_ns, sampleCompressed(frame).image.t.header_ns);
    EXPECT_EQ(encodeCompressedImage(compressed), encoded[3]);

    const CameraInfoMessage info = decodeCameraInfo(encoded[4]);
    const CameraInfoMessage want = sampleCameraInfo(frame);
    EXPECT_EQ(info.frame_id, frame);
    EXPECT_EQ(info.t.header_ns, want.t.header_ns);
    EXPECT_EQ(info.distortion_model, want.distortion_model);
    EXPECT_EQ(info.d, want.d);
    EXPECT_EQ(info.k, want.k);
    EXPECT_EQ(info.p, want.p);
    EXPECT_TRUE(info.roi.do_rectify);
    EXPECT_EQ(info.roi.width, 4u);
    EXPECT_EQ(encodeCameraInfo(info), encoded[4]);

    const std::vector<TransformMessage> tf = decodeTfMessage(encoded[5]);
    ASSERT_EQ(tf.size(), n % 3);
    for (std::size_t i = 0; i < tf.size(); ++i) {
      EXPECT_EQ(tf[i].frame_id, frame);
      EXPECT_EQ(tf[i].child_frame_id, frame.substr(i));
      EXPECT_EQ(bits(tf[i].translation[2]), kNanPayload);
      EXPECT_EQ(tf[i].rotation_xyzw[3], std::sqrt(0.5));
      EXPECT_EQ(tf[i].t.header_ns, static_cast<std::int64_t>(i) * 1'000'000'001);
    }
    EXPECT_EQ(encodeTfMessage(tf), encoded[5]);
  }
}

TEST(Ros2MessageRoundTrip, EmptyStringsAndSequences) {
  const Ros2Image image = decodeImage(encodeImage(sampleImage("", 0)));
  EXPECT_TRUE(image.image.encoding.empty());
  EXPECT_TRUE(image.image.data.empty());
  const CameraInfoMessage info = decodeCameraInfo(encodeCameraInfo(CameraInfoMessage{}));
  EXPECT_TRUE(info.d.empty());
  EXPECT_TRUE(info.frame_id.empty());
  EXPECT_TRUE(decodeTfMessage(encodeTfMessage({})).empty());
}

TEST(Ros2MessageStamp, HeaderStampNsReadsTheFirst12Bytes) {
  const Bytes imu = encodeImu(sampleImu("x"));
  EXPECT_EQ(headerStampNs(imu.data(), 12), -1'700'000'000);
  EXPECT_EQ(headerStampNs(kNavSatFixBe.data(), kNavSatFixBe.size()), 1'000'000'002);
  EXPECT_THROW((void)headerStampNs(imu.data(), 11), Ros2Error);
  EXPECT_THROW((void)headerStampNs(nullptr, 0), Ros2Error);
  Bytes late = imu;
  late[8] = 0x00, late[9] = 0xCA, late[10] = 0x9A, late[11] = 0x3B;  // nanosec 1e9
  EXPECT_TRUE(mentions(ros2Error([&] { (void)headerStampNs(late.data(), late.size()); }),
                       "nanosec 1000000000 is not below 1e9"));
  EXPECT_THROW((void)decodeImu(late), Ros2Error);
}

// ---- defects ----

TEST(Ros2MessageDefects, EveryTruncationThrows) {
  for (std::size_t n = 0; n <= 9; ++n) {
    const std::vector<Bytes> encoded = samples(std::string(n, 'f'));
    for (std::size_t type = 0; type < encoded.size(); ++type) {
      for (std::size_t size = 0; size < encoded[type].size(); ++size) {
        EXPECT_THROW(kDecoders[type]({encoded[type].data(), size}), Ros2Error)
            << kTypes[type] << " cut to " << size << " of " << encoded[type].size() << " bytes";
      }
    }
  }
}

TEST(Ros2MessageDefects, TrailingBytesBeyondPaddingThrow) {
  Bytes imu = encodeImu(sampleImu("imu"));
  for (int i = 0; i < 3; ++i) imu.push_back(0);
  EXPECT_NO_THROW((void)decodeImu(imu));  // padding to a multiple of 4 is tolerated
  imu.push_back(0);
  EXPECT_TRUE(mentions(ros2Error([&] { (void)decodeImu(imu); }),
                       "4 bytes left after the last field: not a sensor_msgs/msg/Imu"));
}

TEST(Ros2MessageDefects, AMessageOfAnotherTypeThrows) {
  const std::vector<Bytes> encoded = samples("camera");
  EXPECT_TRUE(mentions(ros2Error([&] { (void)decodeNavSatFix(encoded[0]); }),
                       "not a sensor_msgs/msg/NavSatFix"));
  EXPECT_THROW((void)decodeImu(encoded[2]), Ros2Error);
  EXPECT_THROW((void)decodeImage(encoded[4]), Ros2Error);
  for (std::size_t as = 0; as < encoded.size(); ++as) {
    for (std::size_t type = 0; type < encoded.size(); ++type) {
      if (as == type) continue;
      EXPECT_THROW(kDecoders[as](encoded[type]), Ros2Error)
          << kTypes[type] << " decoded as " << kTypes[as];
    }
  }
}

TEST(Ros2MessageDefects, HostileLengthsThrowBeforeAllocating) {
  // Each states 0xFFFFFFFF elements (or string bytes) with a few bytes after it; the count is
  // checked against the bytes left before anything is sized by it.
  const auto hostile = [](auto fields) {
    CdrWriter w;
    w.i32(1);
    w.u32(2);
    fields(w);
    w.u32(0xFFFFFFFF);
    w.bytes(Bytes(16, 0xAB));
    return w.take();
  };
  const Bytes frame_id = hostile([](CdrWriter&) {});
  const Bytes data = hostile([](CdrWriter& w) {
    w.string("cam");
    w.string("png");
  });
  const Bytes d = hostile([](CdrWriter& w) {
    w.string("cam");
    w.u32(480);
    w.u32(640);
    w.string("plumb_bob");
  });
  CdrWriter tf;
  tf.u32(0xFFFFFFFF);
  tf.bytes(Bytes(100, 0));
  const Bytes transforms = tf.take();
  for (const std::string& e : {ros2Error([&] { (void)decodeImu(frame_id); }),
                               ros2Error([&] { (void)decodeCompressedImage(data); }),
                               ros2Error([&] { (void)decodeCameraInfo(d); }),
                               ros2Error([&] { (void)decodeTfMessage(transforms); })}) {
    EXPECT_TRUE(mentions(e, "4294967295")) << e;
  }
}

TEST(Ros2MessageDefects, ValuesTheTypeForbidsThrow) {
  Bytes image = encodeImage(sampleImage("cam", 2));
  // Encapsulation, stamp, frame_id "cam" (4 + 4), height and width, encoding "mono8" (4 + 6).
  const std::size_t is_bigendian = 4 + 8 + 8 + 8 + 10;
  ASSERT_EQ(image[is_bigendian], 1);
  image[is_bigendian] = 2;
  EXPECT_TRUE(mentions(ros2Error([&] { (void)decodeImage(image); }), "is_bigendian is 2"));
  Bytes info = encodeCameraInfo(sampleCameraInfo("cam"));
  info.back() = 7;  // roi.do_rectify
  EXPECT_TRUE(mentions(ros2Error([&] { (void)decodeCameraInfo(info); }), "not a bool"));
}

TEST(Ros2MessageDefects, EncodersRefuseValuesTheMessageCannotHold) {
  Ros2NavSatFix fix = sampleFix("gps");
  fix.fix.status = 128;
  EXPECT_THROW((void)encodeNavSatFix(fix), Ros2Error);
  fix = sampleFix("gps");
  fix.fix.covariance_type = -1;
  EXPECT_THROW((void)encodeNavSatFix(fix), Ros2Error);
  Ros2Imu imu = sampleImu("imu");
  imu.imu.t.header_ns =
      (std::int64_t{std::numeric_limits<std::int32_t>::max()} + 1) * 1'000'000'000;
  EXPECT_TRUE(mentions(ros2Error([&] { (void)encodeImu(imu); }), "int32 seconds"));
  EXPECT_THROW((void)encodeImage(sampleCompressed("cam")), Ros2Error);
  EXPECT_THROW((void)encodeCompressedImage(sampleImage("cam", 1)), Ros2Error);
}

// ---- type names and definitions ----

TEST(Ros2MessageDefinition, ComposesDependenciesAsRosbag2McapDoes) {
  const std::string bar(80, '=');
  EXPECT_EQ(ros2MessageDefinition(kRos2CompressedImageType),
            "std_msgs/Header header\nstring format\nuint8[] data\n"
            "\n" +
                bar +
                "\nMSG: std_msgs/Header\n"
                "builtin_interfaces/Time stamp\nstring frame_id\n"
                "\n" +
                bar +
                "\nMSG: builtin_interfaces/Time\n"
                "int32 sec\nuint32 nanosec\n");
  // Depth first, in name order, each dependency once (Header only under TransformStamped).
  const std::string tf = ros2MessageDefinition(kRos2TfType);
  std::size_t at = 0;
  for (const char* dependency :
       {"geometry_msgs/TransformStamped", "geometry_msgs/Transform", "geometry_msgs/Quaternion",
        "geometry_msgs/Vector3", "std_msgs/Header", "builtin_interfaces/Time"}) {
    const std::size_t next = tf.find(bar + "\nMSG: " + dependency + "\n", at);
    ASSERT_NE(next, std::string::npos) << dependency << " in order in\n" << tf;
    at = next + 1;
  }
  EXPECT_EQ(tf.find("MSG: std_msgs/Header", tf.find("MSG: std_msgs/Header") + 1),
            std::string::npos);
}

TEST(Ros2MessageDefinition, HoldsEveryFieldAndConstant) {
  const std::string fix = ros2MessageDefinition(kRos2NavSatFixType);
  for (const char* line :
       {"\nNavSatStatus status\n", "\nfloat64[9] position_covariance\n",
        "\nuint8 COVARIANCE_TYPE_KNOWN = 3\n", "\nMSG: sensor_msgs/NavSatStatus\n",
        "\nint8 STATUS_FIX =      0\n", "\nuint16 SERVICE_GALILEO = 8\n", "\nuint16 service\n"}) {
    EXPECT_TRUE(mentions(fix, line));
  }
  const std::string info = ros2MessageDefinition(kRos2CameraInfoType);
  for (const char* line : {"\nfloat64[] d\n", "\nfloat64[12] p\n", "\nRegionOfInterest roi\n",
                           "\nMSG: sensor_msgs/RegionOfInterest\n", "\nbool do_rectify\n"}) {
    EXPECT_TRUE(mentions(info, line));
  }
  EXPECT_TRUE(mentions(ros2MessageDefinition(kRos2ImuType), "\nMSG: geometry_msgs/Vector3\n"));
  EXPECT_TRUE(mentions(ros2MessageDefinition(kRos2ImageType), "\nuint8 is_bigendian\n"));
  EXPECT_TRUE(mentions(ros2Error([] { (void)ros2MessageDefinition("sensor_msgs/msg/Joy"); }),
                       "sensor_msgs/msg/Joy"));
}

TEST(Ros2MessageTypeName, DropsTheMsgPart) {
  EXPECT_EQ(ros1TypeName(kRos2ImageType), "sensor_msgs/Image");
  EXPECT_EQ(ros1TypeName(kRos2TfType), "tf2_msgs/TFMessage");
  EXPECT_EQ(ros1TypeName("sensor_msgs/Image"), "sensor_msgs/Image");
  EXPECT_EQ(ros1TypeName("example/srv/Call"), "example/srv/Call");
  EXPECT_EQ(ros1TypeName("a/msg/b/c"), "a/msg/b/c");
  EXPECT_EQ(ros1TypeName(""), "");
}

}  // namespace
}  // namespace gvio::io::ros2
