#include "io/image_loader.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cctype>
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

// A chunk's 4-byte type as text: letters as they are (a valid type is 4 ASCII letters, PNG
// specification section 5.4), anything else as \xNN, so an error quoting it stays one line.
std::string chunkName(const unsigned char* p) {
  std::string name;
  for (int i = 0; i < 4; ++i) {
    const unsigned char c = p[i];
    name +=
        std::isalpha(c) != 0 ? std::string(1, static_cast<char>(c)) : fmt::format("\\x{:02X}", c);
  }
  return name;
}

// libpng refuses a side over its default user limit of 1,000,000 px (png_set_user_limits) or a
// zero side, printing "libpng warning/error" lines first: such an IHDR (the first chunk, PNG
// specification section 5.6) is a defect here. "" when the header is missing (left to the walk).
std::string pngSizeDefect(const std::vector<unsigned char>& bytes, std::size_t pos) {
  constexpr std::uint32_t kMaxSidePx = 1'000'000;
  if (bytes.size() - pos < 8 + 8 || chunkName(&bytes[pos + 4]) != "IHDR") return {};
  const std::uint32_t width = bigEndian32(&bytes[pos + 8]);
  const std::uint32_t height = bigEndian32(&bytes[pos + 12]);
  if (width == 0 || height == 0 || width > kMaxSidePx || height > kMaxSidePx)
    return fmt::format("PNG of {}x{} px (each side must be 1 to {})", width, height, kMaxSidePx);
  return {};
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
  if (const std::string d = pngSizeDefect(bytes, pos); !d.empty()) return d;
  while (true) {
    if (bytes.size() - pos < 12) return "truncated PNG (no IEND chunk)";
    const std::uint32_t length = bigEndian32(&bytes[pos]);
    const std::string type = chunkName(&bytes[pos + 4]);
    if (length > bytes.size() - pos - 12) return "truncated PNG (ends inside chunk " + type + ")";
    const std::uint32_t crc = bigEndian32(&bytes[pos + 8 + length]);
    // The chunk CRC covers type and data (PNG specification, section 5.3): zlib's CRC-32.
    if (::crc32(0L, &bytes[pos + 4], length + 4) != crc)
      return "PNG chunk " + type + " fails its CRC";
    if (type == "IEND") return {};
    pos += 12 + length;
  }
}

constexpr std::array<unsigned char, 3> kJpegSignature = {0xFF, 0xD8, 0xFF};

template <std::size_t N>
bool startsWith(const std::vector<unsigned char>& bytes, const std::array<unsigned char, N>& sig) {
  return bytes.size() >= N && std::equal(sig.begin(), sig.end(), bytes.begin());
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

cv::Mat decodeGrayPngOrJpeg(const std::vector<unsigned char>& bytes, std::string& defect) {
  defect.clear();
  if (startsWith(bytes, kPngSignature)) {
    defect = pngDefect(bytes);
  } else if (!startsWith(bytes, kJpegSignature)) {
    defect =
        bytes.empty() ? "empty" : "not a PNG or JPEG (its first bytes are neither's signature)";
  }
  if (!defect.empty()) return {};
  cv::Mat image;
  try {
    image = cv::imdecode(bytes, cv::IMREAD_GRAYSCALE);
  } catch (const cv::Exception& e) {
    // imdecode checks the header's size against CV_IO_MAX_IMAGE_PIXELS (2^30) and width/height
    // against 2^20 with CV_Assert outside its decoders' try (OpenCV 4.6 loadsave.cpp): a JPEG
    // declaring 60000x60000 threw (found by fuzzing ros_image in CI).
    defect = "the decoder refused it (OpenCV's check failed: " + e.err + ")";
    return {};
  }
  if (image.empty()) defect = "corrupt PNG/JPEG data";
  return image;
}

cv::Mat tryLoadGrayImage(const std::filesystem::path& file) {
  try {
    std::string defect;
    return decodeGrayPngOrJpeg(readBytes(file), defect);
  } catch (const InputError&) {
    return {};
  }
}

cv::Mat loadGrayImage(const std::filesystem::path& file, const CameraModel& camera) {
  if (!std::filesystem::is_regular_file(file)) throw InputError(file, 0, "image file not found");
  std::string defect;
  cv::Mat image = decodeGrayPngOrJpeg(readBytes(file), defect);
  if (image.empty()) throw InputError(file, 0, "unreadable image: " + defect);
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
