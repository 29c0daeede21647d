#include "io/image_loader.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include <zlib.h>

#include "io/atomic_write.hpp"
#include "io/input_error.hpp"

namespace gvio::io {
namespace {

constexpr std::array<unsigned char, 8> kPngSignature = {0x89, 'P',  'N',  'G',
                                                        '\r', '\n', 0x1A, '\n'};

std::uint32_t bigEndian32(const unsigned char* p) {
  return (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) |
         std::uint32_t{p[3]};
}

// libpng prints "libpng error: ..." on stderr before OpenCV reports a failed decode, so a damaged
// PNG would add a stray line to the CLI's one-line error. Walks the chunk structure first
// (lengths, CRCs, IEND) and returns what is wrong, or "" for a sound file or a non-PNG.
std::string pngDefect(const std::vector<unsigned char>& bytes) {
  if (bytes.size() < kPngSignature.size() ||
      !std::equal(kPngSignature.begin(), kPngSignature.end(), bytes.begin())) {
    return {};  // not a PNG: left to the other decoders
  }
  std::size_t pos = kPngSignature.size();
  while (true) {
    if (bytes.size() - pos < 12) return "truncated PNG (no IEND chunk)";
    const std::uint32_t length = bigEndian32(&bytes[pos]);
    const std::string type(reinterpret_cast<const char*>(&bytes[pos + 4]), 4);
    if (length > bytes.size() - pos - 12) return "truncated PNG (ends inside chunk " + type + ")";
    const std::uint32_t crc = bigEndian32(&bytes[pos + 8 + length]);
    // The chunk CRC covers type and data (PNG specification, section 5.3): zlib's CRC-32.
    if (::crc32(0L, &bytes[pos + 4], length + 4) != crc)
      return "PNG chunk " + type + " fails its CRC";
    if (type == "IEND") return {};
    pos += 12 + length;
  }
}

std::vector<unsigned char> readBytes(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary | std::ios::ate);
  if (!in) throw InputError(file, 0, "cannot open image file");
  const std::streamsize size = in.tellg();
  std::vector<unsigned char> bytes(static_cast<std::size_t>(std::max<std::streamsize>(size, 0)));
  in.seekg(0);
  if (!in.read(reinterpret_cast<char*>(bytes.data()), size)) {
    throw InputError(file, 0, "cannot read image file");
  }
  return bytes;
}

}  // namespace

cv::Mat loadGrayImage(const std::filesystem::path& file, const CameraModel& camera) {
  if (!std::filesystem::is_regular_file(file)) throw InputError(file, 0, "image file not found");
  const std::vector<unsigned char> bytes = readBytes(file);
  if (const std::string defect = pngDefect(bytes); !defect.empty()) {
    throw InputError(file, 0, "unreadable image: " + defect);
  }
  cv::Mat image = bytes.empty() ? cv::Mat() : cv::imdecode(bytes, cv::IMREAD_GRAYSCALE);
  if (image.empty()) throw InputError(file, 0, "unreadable image (corrupt or not a PNG/JPEG)");
  if (image.cols != camera.width_px || image.rows != camera.height_px) {
    throw InputError(file, 0,
                     fmt::format("image is {}x{} but the calibration of {} says {}x{}", image.cols,
                                 image.rows, camera.name, camera.width_px, camera.height_px));
  }
  return image;
}

void writePng(const std::filesystem::path& file, const cv::Mat& image) {
  std::vector<std::uint8_t> png;
  if (!cv::imencode(".png", image, png, {cv::IMWRITE_PNG_COMPRESSION, 1})) {
    throw InputError(file, 0, "PNG encoding failed");
  }
  writeFileAtomic(file, [&](std::ostream& out) {
    out.write(reinterpret_cast<const char*>(png.data()), static_cast<std::streamsize>(png.size()));
  });
}

}  // namespace gvio::io
