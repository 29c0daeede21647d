#include "support/las_reader.hpp"

#include <cstring>
#include <fstream>
#include <iterator>
#include <stdexcept>

namespace gvio::test {
namespace {

class Cursor {
 public:
  explicit Cursor(const std::string& bytes) : bytes_(bytes) {}

  // Little-endian values, assembled byte by byte (no assumption about the host's order).
  template <typename T>
  T at(std::size_t offset) const {
    if (offset + sizeof(T) > bytes_.size()) throw std::runtime_error("LAS: read past the end");
    std::uint64_t bits = 0;
    for (std::size_t i = 0; i < sizeof(T); ++i) {
      bits |= static_cast<std::uint64_t>(static_cast<unsigned char>(bytes_[offset + i])) << (8 * i);
    }
    T value;
    if constexpr (sizeof(T) == 8) {
      std::memcpy(&value, &bits, 8);
    } else {
      using U = std::conditional_t<sizeof(T) == 4, std::uint32_t,
                                   std::conditional_t<sizeof(T) == 2, std::uint16_t, std::uint8_t>>;
      const auto narrow = static_cast<U>(bits);
      std::memcpy(&value, &narrow, sizeof(T));
    }
    return value;
  }
  // A fixed-width, null-padded character field.
  std::string text(std::size_t offset, std::size_t width) const {
    if (offset + width > bytes_.size()) throw std::runtime_error("LAS: read past the end");
    const std::string raw = bytes_.substr(offset, width);
    return raw.substr(0, raw.find('\0'));
  }
  std::string raw(std::size_t offset, std::size_t n) const {
    if (offset + n > bytes_.size()) throw std::runtime_error("LAS: read past the end");
    return bytes_.substr(offset, n);
  }
  [[nodiscard]] std::size_t size() const { return bytes_.size(); }

 private:
  const std::string& bytes_;
};

void readHeader(const Cursor& c, LasFile& las) {
  las.signature = c.raw(0, 4);
  if (las.signature != "LASF") throw std::runtime_error("LAS: no LASF signature");
  las.global_encoding = c.at<std::uint16_t>(6);
  las.version_major = c.at<std::uint8_t>(24);
  las.version_minor = c.at<std::uint8_t>(25);
  las.system_identifier = c.text(26, 32);
  las.generating_software = c.text(58, 32);
  las.header_size = c.at<std::uint16_t>(94);
  las.offset_to_points = c.at<std::uint32_t>(96);
  las.vlr_count = c.at<std::uint32_t>(100);
  las.point_format = c.at<std::uint8_t>(104);
  las.point_length = c.at<std::uint16_t>(105);
  las.legacy_point_count = c.at<std::uint32_t>(107);
  for (std::size_t i = 0; i < 5; ++i) las.legacy_by_return[i] = c.at<std::uint32_t>(111 + 4 * i);
  for (int i = 0; i < 3; ++i) {
    las.scale[i] = c.at<double>(131 + 8 * static_cast<std::size_t>(i));
    las.offset[i] = c.at<double>(155 + 8 * static_cast<std::size_t>(i));
    las.max[i] = c.at<double>(179 + 16 * static_cast<std::size_t>(i));
    las.min[i] = c.at<double>(187 + 16 * static_cast<std::size_t>(i));
  }
  las.evlr_start = c.at<std::uint64_t>(235);
  las.evlr_count = c.at<std::uint32_t>(243);
  las.point_count = c.at<std::uint64_t>(247);
  for (std::size_t i = 0; i < 15; ++i) las.by_return[i] = c.at<std::uint64_t>(255 + 8 * i);
}

void readVlrs(const Cursor& c, LasFile& las) {
  std::size_t pos = las.header_size;
  for (std::uint32_t i = 0; i < las.vlr_count; ++i) {
    LasVlr v;
    v.user_id = c.text(pos + 2, 16);
    v.record_id = c.at<std::uint16_t>(pos + 18);
    const auto length = c.at<std::uint16_t>(pos + 20);
    v.description = c.text(pos + 22, 32);
    v.data = c.raw(pos + 54, length);
    las.vlrs.push_back(v);
    pos += 54 + length;
  }
  if (pos != las.offset_to_points) throw std::runtime_error("LAS: VLRs do not end at point data");
}

void readPoints(const Cursor& c, LasFile& las) {
  if (las.point_format != 6 && las.point_format != 7) {
    throw std::runtime_error("LAS: point format " + std::to_string(las.point_format) +
                             " not supported by the test reader");
  }
  const std::size_t needed = las.point_format == 6 ? 30 : 36;
  if (las.point_length < needed) throw std::runtime_error("LAS: point records too short");
  if (las.offset_to_points + las.point_count * las.point_length > c.size()) {
    throw std::runtime_error("LAS: file shorter than its point count says");
  }
  for (std::uint64_t k = 0; k < las.point_count; ++k) {
    const std::size_t p = las.offset_to_points + k * las.point_length;
    LasRecord r;
    r.raw = {c.at<std::int32_t>(p), c.at<std::int32_t>(p + 4), c.at<std::int32_t>(p + 8)};
    r.xyz = r.raw.cast<double>().cwiseProduct(las.scale) + las.offset;
    r.intensity = c.at<std::uint16_t>(p + 12);
    const auto returns = c.at<std::uint8_t>(p + 14);
    r.return_number = returns & 0x0F;
    r.number_of_returns = returns >> 4;
    r.classification = c.at<std::uint8_t>(p + 16);
    r.point_source_id = c.at<std::uint16_t>(p + 20);  // after user data (17) and scan angle (18)
    r.gps_time = c.at<double>(p + 22);
    if (las.point_format == 7) {
      r.rgb = std::array<std::uint16_t, 3>{c.at<std::uint16_t>(p + 30), c.at<std::uint16_t>(p + 32),
                                           c.at<std::uint16_t>(p + 34)};
    }
    las.points.push_back(r);
  }
}

}  // namespace

std::string LasFile::wkt() const {
  for (const auto& v : vlrs) {
    if (v.user_id == "LASF_Projection" && v.record_id == 2112) {
      return v.data.substr(0, v.data.find('\0'));
    }
  }
  return {};
}

LasFile readLas(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::runtime_error("LAS: cannot open " + file.string());
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const Cursor c(bytes);
  LasFile las;
  readHeader(c, las);
  readVlrs(c, las);
  readPoints(c, las);
  return las;
}

}  // namespace gvio::test
