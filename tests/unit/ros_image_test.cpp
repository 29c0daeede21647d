// sensor_msgs/Image and CompressedImage payloads to 8-bit grey (issue 16): every accepted
// encoding, padded rows, 16-bit in either byte order, PNG and JPEG, and the refusals.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "io/ros_image.hpp"
#include "odometry/error.hpp"

namespace gvio::io {
namespace {
using testing::HasSubstr;

cv::Mat gradient() {
  cv::Mat g(6, 10, CV_8UC1);
  for (int r = 0; r < g.rows; ++r) {
    for (int c = 0; c < g.cols; ++c)
      g.at<std::uint8_t>(r, c) = static_cast<std::uint8_t>(20 * r + 7 * c);
  }
  return g;
}

bag::ImageMessage raw(const cv::Mat& m, const std::string& encoding, int pad_bytes = 0) {
  bag::ImageMessage out;
  out.encoding = encoding;
  out.width = static_cast<std::uint32_t>(m.cols);
  out.height = static_cast<std::uint32_t>(m.rows);
  const std::size_t row = m.cols * m.elemSize();
  out.step = static_cast<std::uint32_t>(row + static_cast<std::size_t>(pad_bytes));
  out.data.assign(out.step * out.height, 0xAB);  // padding bytes must be ignored
  for (int r = 0; r < m.rows; ++r) std::memcpy(&out.data[r * out.step], m.ptr(r), row);
  return out;
}

constexpr std::array<std::uint8_t, 2> kSof0 = {0xFF, 0xC0};  // baseline JPEG frame header

std::string error(const bag::ImageMessage& m) {
  try {
    (void)rosImageToGray(m);
  } catch (const InvalidInput& e) {
    return e.what();
  }
  return "no error";
}

TEST(RosImage, Mono8WithPaddedRowsAndItsAlias) {
  const cv::Mat g = gradient();
  EXPECT_EQ(cv::norm(rosImageToGray(raw(g, "mono8", 6)), g, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(rosImageToGray(raw(g, "8UC1")), g, cv::NORM_INF), 0.0);
  const bag::ImageMessage round_trip = grayToRosImage(g, false);
  EXPECT_EQ(cv::norm(rosImageToGray(round_trip), g, cv::NORM_INF), 0.0);
}

TEST(RosImage, ColourToGreyWithOpenCvWeights) {
  cv::Mat bgr(6, 10, CV_8UC3, cv::Scalar(200, 100, 50));  // B, G, R
  cv::Mat expected;
  cv::cvtColor(bgr, expected, cv::COLOR_BGR2GRAY);
  EXPECT_EQ(cv::norm(rosImageToGray(raw(bgr, "bgr8")), expected, cv::NORM_INF), 0.0);
  cv::Mat rgb;
  cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  EXPECT_EQ(cv::norm(rosImageToGray(raw(rgb, "rgb8")), expected, cv::NORM_INF), 0.0);
  cv::Mat rgba;
  cv::cvtColor(bgr, rgba, cv::COLOR_BGR2RGBA);
  EXPECT_EQ(cv::norm(rosImageToGray(raw(rgba, "rgba8")), expected, cv::NORM_INF), 0.0);
  // Not the same as reading the channels in the wrong order.
  cv::Mat swapped;
  cv::cvtColor(bgr, swapped, cv::COLOR_RGB2GRAY);
  EXPECT_GT(cv::norm(swapped, expected, cv::NORM_INF), 10.0);
}

TEST(RosImage, Mono16InEitherByteOrderScaledBy256) {
  cv::Mat wide(2, 3, CV_16UC1);
  for (int i = 0; i < 6; ++i)
    wide.at<std::uint16_t>(i / 3, i % 3) = static_cast<std::uint16_t>(i * 10000 + 300);
  bag::ImageMessage little = raw(wide, "mono16");
  const cv::Mat a = rosImageToGray(little);
  ASSERT_EQ(a.type(), CV_8UC1);
  for (int i = 0; i < 6; ++i) {
    EXPECT_EQ(a.at<std::uint8_t>(i / 3, i % 3), cvRound((i * 10000 + 300) / 256.0)) << i;
  }
  bag::ImageMessage big = little;
  big.big_endian = true;
  for (std::size_t i = 0; i + 1 < big.data.size(); i += 2) std::swap(big.data[i], big.data[i + 1]);
  EXPECT_EQ(cv::norm(rosImageToGray(big), a, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(rosImageToGray(raw(wide, "16UC1")), a, cv::NORM_INF), 0.0);
}

TEST(RosImage, CompressedPngAndJpeg) {
  const cv::Mat g = gradient();
  const bag::ImageMessage png = grayToRosImage(g, true);
  EXPECT_TRUE(png.compressed);
  EXPECT_EQ(cv::norm(rosImageToGray(png), g, cv::NORM_INF), 0.0);
  bag::ImageMessage jpeg;
  jpeg.compressed = true;
  jpeg.format = "bgr8; jpeg compressed bgr8";
  cv::Mat bgr;
  cv::cvtColor(g, bgr, cv::COLOR_GRAY2BGR);
  cv::imencode(".jpg", bgr, jpeg.data, {cv::IMWRITE_JPEG_QUALITY, 100});
  EXPECT_LE(cv::norm(rosImageToGray(jpeg), g, cv::NORM_INF), 3.0);
}

TEST(RosImage, RefusalsSayWhatIsWrong) {
  const cv::Mat g = gradient();
  EXPECT_THAT(error(raw(g, "yuv422")),
              HasSubstr("image encoding 'yuv422' is not supported (mono8, 8UC1"));
  bag::ImageMessage short_data = raw(g, "mono8");
  short_data.data.resize(short_data.data.size() - 1);
  EXPECT_THAT(error(short_data), HasSubstr("does not fit its 59 bytes"));
  bag::ImageMessage narrow_step = raw(g, "mono8");
  narrow_step.step = 5;
  EXPECT_THAT(error(narrow_step), HasSubstr("with step 5"));
  bag::ImageMessage depth = grayToRosImage(g, true);
  depth.format = "16UC1; compressedDepth png";
  EXPECT_THAT(error(depth),
              HasSubstr("compressed image format '16UC1; compressedDepth png' is not"));
  bag::ImageMessage garbage = grayToRosImage(g, true);
  garbage.data.assign(40, 7);
  EXPECT_THAT(error(garbage), HasSubstr("cannot be decoded: not a PNG or JPEG"));
  // Other formats never reach OpenCV, whose DICOM decoder (GDCM) aborted on this fuzzed message.
  bag::ImageMessage dicom = grayToRosImage(g, true);
  dicom.data.assign(128, 0);
  const std::string tag = "DICM";
  std::copy(tag.begin(), tag.end(), dicom.data.begin() + 128 - 4);
  dicom.data.insert(dicom.data.end(), {'P', '1', '6', 'U', 'C', '1', 0, 0xC8, 0xDC});
  EXPECT_THAT(error(dicom), HasSubstr("not a PNG or JPEG"));
  bag::ImageMessage bmp = grayToRosImage(g, true);
  cv::imencode(".bmp", g, bmp.data);  // BMP decodes in OpenCV, but is no ROS compressed format
  EXPECT_THAT(error(bmp), HasSubstr("not a PNG or JPEG"));
  bag::ImageMessage odd_step = raw(g, "mono8");
  odd_step.encoding = "mono16";
  odd_step.width = 2;
  odd_step.height = 4;
  odd_step.step = 11;
  EXPECT_THAT(error(odd_step),
              HasSubstr("mono16 image with step 11: not a multiple of its 2-byte"));
  bag::ImageMessage empty = raw(g, "mono8");
  empty.width = 0;
  EXPECT_THAT(error(empty), HasSubstr("image of 0x6 pixels"));
}

// A header may declare any size: OpenCV asserts (throws) on more than 2^30 pixels and libpng
// prints lines of its own over 10^6 px a side. Both are refused as one-line defects.
TEST(RosImage, OversizedHeadersAreRefusedNotThrown) {
  const cv::Mat g = gradient();
  bag::ImageMessage jpeg;
  jpeg.compressed = true;
  jpeg.format = "mono8; jpeg compressed mono8";
  cv::imencode(".jpg", g, jpeg.data);
  const auto sof = std::search(jpeg.data.begin(), jpeg.data.end(), kSof0.begin(), kSof0.end());
  ASSERT_NE(sof, jpeg.data.end());
  const std::array<std::uint8_t, 4> huge = {0xEA, 0x60, 0xEA, 0x60};  // 60000 x 60000
  std::copy(huge.begin(), huge.end(), sof + 5);                       // after length, precision
  EXPECT_THAT(error(jpeg), HasSubstr("cannot be decoded: the decoder refused it ("));
  bag::ImageMessage png = grayToRosImage(g, true);
  const std::array<std::uint8_t, 4> wide = {0x00, 0x1E, 0x84, 0x80};  // 2,000,000
  std::copy(wide.begin(), wide.end(), png.data.begin() + 16);         // IHDR width
  EXPECT_THAT(error(png), HasSubstr("PNG of 2000000x6 px (each side must be 1 to 1000000)"));
}

// A colour filter array of one colour (R 200, G 100, B 50), demosaiced to grey: OpenCV's weights
// where the pattern is read right (a pattern read as another one swaps red and blue: 96 not 124).
TEST(RosImage, BayerPatternsDemosaicToGrey) {
  const double expected = 0.299 * 200 + 0.587 * 100 + 0.114 * 50;
  const std::pair<const char*, std::array<int, 4>> kPatterns[] = {
      {"bayer_rggb", {200, 100, 100, 50}},  // the 2x2 cell: top left, top right, bottom left, ...
      {"bayer_bggr", {50, 100, 100, 200}},
      {"bayer_gbrg", {100, 50, 200, 100}},
      {"bayer_grbg", {100, 200, 50, 100}}};
  for (const auto& [name, cell] : kPatterns) {
    cv::Mat mosaic(8, 12, CV_8UC1);
    cv::Mat wide(8, 12, CV_16UC1);
    for (int r = 0; r < mosaic.rows; ++r) {
      for (int c = 0; c < mosaic.cols; ++c) {
        const int v = cell[static_cast<std::size_t>(2 * (r % 2) + c % 2)];
        mosaic.at<std::uint8_t>(r, c) = static_cast<std::uint8_t>(v);
        wide.at<std::uint16_t>(r, c) = static_cast<std::uint16_t>(v * 256);
      }
    }
    for (const auto& [image, bits] : {std::pair{mosaic, "8"}, std::pair{wide, "16"}}) {
      const cv::Mat gray = rosImageToGray(raw(image, std::string(name) + bits));
      ASSERT_EQ(gray.size(), mosaic.size());
      // Interior pixels (the demosaic's border is an extrapolation).
      EXPECT_NEAR(gray.at<std::uint8_t>(4, 6), expected, 1.5) << name << bits;
      EXPECT_NEAR(gray.at<std::uint8_t>(3, 5), expected, 1.5) << name << bits;
    }
  }
  bag::ImageMessage tiny = raw(cv::Mat(1, 4, CV_8UC1, cv::Scalar(9)), "bayer_rggb8");
  EXPECT_THAT(error(tiny), HasSubstr("bayer_rggb8 image of 4x1 pixels"));
}

}  // namespace
}  // namespace gvio::io
