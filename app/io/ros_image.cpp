#include "io/ros_image.hpp"

#include <fmt/format.h>

#include <bit>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "io/image_loader.hpp"
#include "odometry/error.hpp"

namespace gvio::io {
namespace {

struct Layout {
  int type;  // OpenCV type of one pixel row element
  int bytes_per_pixel;
  int to_gray;  // cv::cvtColor code, -1 for none
};

Layout layoutOf(const std::string& encoding) {
  if (encoding == "mono8" || encoding == "8UC1") return {CV_8UC1, 1, -1};
  if (encoding == "mono16" || encoding == "16UC1") return {CV_16UC1, 2, -1};
  if (encoding == "bgr8") return {CV_8UC3, 3, cv::COLOR_BGR2GRAY};
  if (encoding == "rgb8") return {CV_8UC3, 3, cv::COLOR_RGB2GRAY};
  if (encoding == "bgra8") return {CV_8UC4, 4, cv::COLOR_BGRA2GRAY};
  if (encoding == "rgba8") return {CV_8UC4, 4, cv::COLOR_RGBA2GRAY};
  // Colour filter arrays, named by their first row (ROS) where OpenCV names the second row's
  // pattern: bayer_rggb8 is OpenCV's BayerBG (as cv_bridge maps them).
  if (encoding == "bayer_rggb8") return {CV_8UC1, 1, cv::COLOR_BayerBG2GRAY};
  if (encoding == "bayer_bggr8") return {CV_8UC1, 1, cv::COLOR_BayerRG2GRAY};
  if (encoding == "bayer_gbrg8") return {CV_8UC1, 1, cv::COLOR_BayerGR2GRAY};
  if (encoding == "bayer_grbg8") return {CV_8UC1, 1, cv::COLOR_BayerGB2GRAY};
  if (encoding == "bayer_rggb16") return {CV_16UC1, 2, cv::COLOR_BayerBG2GRAY};
  if (encoding == "bayer_bggr16") return {CV_16UC1, 2, cv::COLOR_BayerRG2GRAY};
  if (encoding == "bayer_gbrg16") return {CV_16UC1, 2, cv::COLOR_BayerGR2GRAY};
  if (encoding == "bayer_grbg16") return {CV_16UC1, 2, cv::COLOR_BayerGB2GRAY};
  throw InvalidInput(
      fmt::format("image encoding '{}' is not supported ({})", encoding, kRosImageEncodings));
}

cv::Mat rawToGray(const bag::ImageMessage& m) {
  const Layout layout = layoutOf(m.encoding);
  const std::uint64_t row_bytes =
      std::uint64_t{m.width} * static_cast<unsigned>(layout.bytes_per_pixel);
  if (m.width == 0 || m.height == 0 || m.width > 65535 || m.height > 65535) {
    throw InvalidInput(fmt::format("image of {}x{} pixels", m.width, m.height));
  }
  const bool bayer = m.encoding.rfind("bayer_", 0) == 0;
  if (bayer && (m.width < 2 || m.height < 2)) {  // a colour filter's 2x2 cell must fit
    throw InvalidInput(fmt::format("{} image of {}x{} pixels", m.encoding, m.width, m.height));
  }
  if (m.step < row_bytes || std::uint64_t{m.step} * m.height > m.data.size()) {
    throw InvalidInput(fmt::format("{}x{} {} image with step {} does not fit its {} bytes of data",
                                   m.width, m.height, m.encoding, m.step, m.data.size()));
  }
  // OpenCV (and so cv_bridge) needs a row step that is a whole number of channel values: an odd
  // step of a 16-bit image threw from cv::Mat (found by fuzzing ros_image).
  if (m.step % CV_ELEM_SIZE1(layout.type) != 0) {
    throw InvalidInput(fmt::format("{} image with step {}: not a multiple of its {}-byte values",
                                   m.encoding, m.step, CV_ELEM_SIZE1(layout.type)));
  }
  // A view of the message's rows (step may pad them); converted copies below own their pixels.
  const cv::Mat view(static_cast<int>(m.height), static_cast<int>(m.width), layout.type,
                     const_cast<std::uint8_t*>(m.data.data()), m.step);
  if (layout.type == CV_16UC1) {
    cv::Mat wide = view.clone();
    const bool host_big = std::endian::native == std::endian::big;
    if (m.big_endian != host_big) {
      for (int r = 0; r < wide.rows; ++r) {
        auto* row = wide.ptr<std::uint16_t>(r);
        for (int c = 0; c < wide.cols; ++c)
          row[c] = static_cast<std::uint16_t>((row[c] >> 8) | (row[c] << 8));
      }
    }
    cv::Mat scaled;
    wide.convertTo(scaled, CV_8U, 1.0 / 256.0);
    if (layout.to_gray < 0) return scaled;
    // 16-bit Bayer demosaiced after the scaling: OpenCV's 16-bit Bayer-to-grey leaves a 2-pixel
    // pattern of up to 8 % on a uniform colour where its 8-bit one is exact.
    cv::Mat gray;
    cv::cvtColor(scaled, gray, layout.to_gray);
    return gray;
  }
  if (layout.to_gray < 0) return view.clone();
  cv::Mat gray;
  cv::cvtColor(view, gray, layout.to_gray);
  return gray;
}

cv::Mat compressedToGray(const bag::ImageMessage& m) {
  const std::string& f = m.format;
  if (f.find("compressedDepth") != std::string::npos ||
      (f.find("png") == std::string::npos && f.find("jpeg") == std::string::npos &&
       f.find("jpg") == std::string::npos)) {
    throw InvalidInput(fmt::format("compressed image format '{}' is not supported (png, jpeg)", f));
  }
  if (m.data.empty()) throw InvalidInput("compressed image without data");
  std::string defect;
  cv::Mat gray = decodeGrayPngOrJpeg(m.data, defect);
  if (gray.empty()) {
    throw InvalidInput(fmt::format("compressed image ({}) cannot be decoded: {}", f, defect));
  }
  return gray;
}

}  // namespace

cv::Mat rosImageToGray(const bag::ImageMessage& message) {
  return message.compressed ? compressedToGray(message) : rawToGray(message);
}

bag::ImageMessage grayToRosImage(const cv::Mat& gray, bool png) {
  if (gray.type() != CV_8UC1) throw InvalidInput("grayToRosImage: expected an 8-bit grey image");
  bag::ImageMessage m;
  if (png) {
    m.compressed = true;
    m.format = "mono8; png compressed ";
    // Fastest zlib level: bags from the simulator are written for tests, not for archiving.
    cv::imencode(".png", gray, m.data, {cv::IMWRITE_PNG_COMPRESSION, 1});
    return m;
  }
  m.encoding = "mono8";
  m.width = static_cast<std::uint32_t>(gray.cols);
  m.height = static_cast<std::uint32_t>(gray.rows);
  m.step = m.width;
  const cv::Mat packed = gray.isContinuous() ? gray : gray.clone();
  m.data.assign(packed.data, packed.data + packed.total());
  return m;
}

}  // namespace gvio::io
