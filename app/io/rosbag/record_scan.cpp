#include "io/rosbag/record_scan.hpp"

#include <cstdint>
#include <fstream>
#include <map>
#include <vector>

#include "io/rosbag/bag_file.hpp"

namespace gvio::io::bag {

namespace {

constexpr std::uint64_t kMaxChunkBytes = std::uint64_t{1} << 30;

std::uint32_t littleEndian32(const unsigned char* p) {
  return std::uint32_t{p[0]} | std::uint32_t{p[1]} << 8 | std::uint32_t{p[2]} << 16 |
         std::uint32_t{p[3]} << 24;
}

[[noreturn]] void fail(std::uint64_t offset, const std::string& what) {
  throw BagError("record at byte " + std::to_string(offset) + ": " + what);
}

// A record header: fields of <u32 length><name>=<value>, which must fill it exactly.
std::map<std::string, std::string> headerFields(const std::vector<unsigned char>& header,
                                                std::uint64_t offset) {
  std::map<std::string, std::string> fields;
  std::size_t pos = 0;
  while (pos < header.size()) {
    if (header.size() - pos < 4) fail(offset, "truncated header field");
    const std::uint32_t length = littleEndian32(&header[pos]);
    pos += 4;
    if (length > header.size() - pos) fail(offset, "header field longer than its header");
    const std::string field(header.begin() + static_cast<std::ptrdiff_t>(pos),
                            header.begin() + static_cast<std::ptrdiff_t>(pos + length));
    const std::size_t eq = field.find('=');
    if (eq == std::string::npos) fail(offset, "header field without '='");
    fields[field.substr(0, eq)] = field.substr(eq + 1);
    pos += length;
  }
  return fields;
}

}  // namespace

void checkBagRecords(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw BagError("cannot open the file");
  const auto size = static_cast<std::uint64_t>(in.tellg());
  const std::string v200 = "#ROSBAG V2.0\n";
  std::string magic(v200.size(), '\0');
  in.seekg(0);
  if (!in.read(magic.data(), static_cast<std::streamsize>(magic.size())) || magic != v200) return;
  std::uint64_t pos = v200.size();
  unsigned char len[4];
  auto readLength = [&](const char* what) {
    if (size - pos < 4 || !in.read(reinterpret_cast<char*>(len), 4)) fail(pos, what);
    pos += 4;
    return std::uint64_t{littleEndian32(len)};
  };
  while (pos < size) {
    const std::uint64_t start = pos;
    const std::uint64_t header_len = readLength("truncated (no header length)");
    if (header_len > size - pos) fail(start, "header runs past the end of the file");
    std::vector<unsigned char> header(header_len);
    in.read(reinterpret_cast<char*>(header.data()), static_cast<std::streamsize>(header_len));
    pos += header_len;
    const std::uint64_t data_len = readLength("truncated (no data length)");
    if (data_len > size - pos) fail(start, "data runs past the end of the file");
    const auto fields = headerFields(header, start);
    const auto op = fields.find("op");
    if (op != fields.end() && op->second == std::string(1, '\x05')) {  // a chunk
      const auto compression = fields.find("compression");
      const auto declared = fields.find("size");
      if (compression == fields.end() || declared == fields.end() || declared->second.size() != 4)
        fail(start, "chunk header without compression or size");
      const std::uint64_t unpacked =
          littleEndian32(reinterpret_cast<const unsigned char*>(declared->second.data()));
      if (unpacked > kMaxChunkBytes) fail(start, "chunk declares more than 1 GiB of messages");
      if (compression->second == "none" && unpacked != data_len)
        fail(start, "uncompressed chunk whose size differs from its data");
    }
    pos += data_len;
    in.seekg(static_cast<std::streamoff>(pos));
  }
}

}  // namespace gvio::io::bag
