#pragma once
// What the MCAP reader and writer share (https://mcap.dev/spec): the magic, record opcodes,
// little-endian serialisation, bounds-checked field parsing, CRC-32, chunk (de)compression and a
// file read at offsets. Internal to io/ros2 (namespace mcap); callers use McapReader/McapWriter.
#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace gvio::io::ros2::mcap {

using Bytes = std::vector<std::uint8_t>;

// Spec "Magic": 0x89 "MCAP", the major version '0', "\r\n"; a file starts and ends with it.
inline constexpr std::array<std::uint8_t, 8> kMagic{0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};

// Spec "Records": opcodes 0x01-0x7F are the format's, 0x80-0xFF application extensions.
namespace op {
inline constexpr std::uint8_t kHeader = 0x01;
inline constexpr std::uint8_t kFooter = 0x02;
inline constexpr std::uint8_t kSchema = 0x03;
inline constexpr std::uint8_t kChannel = 0x04;
inline constexpr std::uint8_t kMessage = 0x05;
inline constexpr std::uint8_t kChunk = 0x06;
inline constexpr std::uint8_t kMessageIndex = 0x07;
inline constexpr std::uint8_t kChunkIndex = 0x08;
inline constexpr std::uint8_t kAttachment = 0x09;
inline constexpr std::uint8_t kAttachmentIndex = 0x0A;
inline constexpr std::uint8_t kStatistics = 0x0B;
inline constexpr std::uint8_t kMetadata = 0x0C;
inline constexpr std::uint8_t kMetadataIndex = 0x0D;
inline constexpr std::uint8_t kSummaryOffset = 0x0E;
inline constexpr std::uint8_t kDataEnd = 0x0F;
}  // namespace op

inline bool isKnownOp(std::uint8_t opcode) {
  return opcode >= op::kHeader && opcode <= op::kDataEnd;
}

// Every record: <opcode: uint8><content length: uint64><content>.
inline constexpr std::uint64_t kRecordPrefix = 9;
// Footer content: summary_start, summary_offset_start (uint64), summary_crc (uint32).
inline constexpr std::uint64_t kFooterContent = 20;
// Message content before its data: channel_id (2), sequence (4), log_time (8), publish_time (8).
inline constexpr std::uint64_t kMessageFixed = 22;
// The largest chunk (uncompressed) either side handles: bounds what a damaged size can allocate.
inline constexpr std::uint64_t kMaxChunkBytes = std::uint64_t{1} << 30;

std::string opName(std::uint8_t opcode);      // e.g. "Chunk (0x06)"
std::string withCommas(std::uint64_t value);  // 1234567 -> "1,234,567"
std::string hex32(std::uint32_t value);       // "0x0000abcd"

// Spec "CRC32": the standard (zlib) CRC-32, continued from `crc` (0 to start).
std::uint32_t crc32(const std::uint8_t* data, std::size_t size, std::uint32_t crc = 0);

// Spec "Serialization": little-endian integers, String = uint32 length + UTF-8 bytes,
// Map = uint32 byte length + entries.
inline std::uint16_t le16(const std::uint8_t* p) {
  return static_cast<std::uint16_t>(p[0] | p[1] << 8);
}
inline std::uint32_t le32(const std::uint8_t* p) {
  return std::uint32_t{p[0]} | std::uint32_t{p[1]} << 8 | std::uint32_t{p[2]} << 16 |
         std::uint32_t{p[3]} << 24;
}
inline std::uint64_t le64(const std::uint8_t* p) {
  return std::uint64_t{le32(p)} | std::uint64_t{le32(p + 4)} << 32;
}
void putU8(Bytes& out, std::uint8_t value);
void putU16(Bytes& out, std::uint16_t value);
void putU32(Bytes& out, std::uint32_t value);
void putU64(Bytes& out, std::uint64_t value);
void putBytes(Bytes& out, const std::uint8_t* data, std::size_t size);
void putString(Bytes& out, std::string_view text);  // throws Ros2Error past 4 GiB
void putStringMap(Bytes& out, const std::map<std::string, std::string>& map);
void putRecordPrefix(Bytes& out, std::uint8_t opcode, std::uint64_t content_length);

// Where a record is, for error messages (formatted only when one is thrown): a record in the file
// at byte `offset`, or, when chunk_offset is set, at `offset` in the uncompressed records of the
// chunk at byte chunk_offset.
struct Where {
  static constexpr std::uint64_t kInFile = ~std::uint64_t{0};
  std::uint8_t opcode = 0;
  std::uint64_t offset = 0;
  std::uint64_t chunk_offset = kInFile;
  std::string describe() const;
};

// One record's content, read field by field; every field is checked against the bytes left and a
// field that runs past them throws Ros2Error naming the record and the field. Trailing bytes are
// left alone: spec "Records" lets later versions append fields that readers ignore.
class FieldReader {
 public:
  FieldReader(std::span<const std::uint8_t> content, Where where) : data_(content), where_(where) {}

  std::uint16_t u16(const char* field) { return le16(take(2, field)); }
  std::uint32_t u32(const char* field) { return le32(take(4, field)); }
  std::uint64_t u64(const char* field) { return le64(take(8, field)); }
  std::string string(const char* field);
  std::span<const std::uint8_t> bytes32(const char* field);  // uint32 length + bytes
  std::span<const std::uint8_t> bytes64(const char* field);  // uint64 length + bytes
  std::map<std::string, std::string> stringMap(const char* field);
  std::size_t position() const { return pos_; }
  std::size_t left() const { return data_.size() - pos_; }
  [[noreturn]] void fail(const std::string& what) const;

 private:
  const std::uint8_t* take(std::uint64_t count, const char* field);

  std::span<const std::uint8_t> data_;
  Where where_;
  std::size_t pos_ = 0;
};

// Spec "Chunk" compression: "" (none), "lz4" (LZ4 frame format) or "zstd".
bool isKnownCompression(std::string_view compression);
Bytes compress(std::string_view compression, std::span<const std::uint8_t> records);
// The records a chunk's compressed bytes hold: exactly uncompressed_size bytes, of CRC
// uncompressed_crc unless that is 0 (spec "Chunk"). Throws Ros2Error ("<where>: ...") for corrupt
// data, a size or CRC mismatch or an impossible size; never allocates much more than the data
// really decompresses to.
Bytes decompress(std::string_view compression, std::span<const std::uint8_t> compressed,
                 std::uint64_t uncompressed_size, std::uint32_t uncompressed_crc,
                 const std::string& where);

// Calls visit(where, content) for each record of a chunk's records or of the summary section, in
// memory. Record i is at `base` + its position (chunk_offset: as in Where). A record that does not
// fit throws Ros2Error.
using RecordVisitor = std::function<void(const Where&, std::span<const std::uint8_t>)>;
void forEachRecord(std::span<const std::uint8_t> records, std::uint64_t base,
                   std::uint64_t chunk_offset, const RecordVisitor& visit);

// A file read at offsets, checked against its size. Seeks only when a read does not start where
// the last one ended (a seek discards the stream's buffer). Throws Ros2Error.
class FileSource {
 public:
  explicit FileSource(const std::filesystem::path& file);
  std::uint64_t size() const { return size_; }
  Bytes read(std::uint64_t offset, std::uint64_t count);

 private:
  std::ifstream in_;
  std::uint64_t size_ = 0;
  std::uint64_t at_ = ~std::uint64_t{0};  // where the stream stands; unknown at first
};

// Spec "Header": the first record, after the opening magic. Throws Ros2Error for a file that does
// not start with the magic ("not an MCAP file") or whose Header cannot be read.
struct Header {
  std::string profile, library;
  std::uint64_t end = 0;  // where the data section starts
};
Header readHeader(FileSource& file);

// Spec "Footer": the last record, right before the closing magic.
struct Footer {
  std::uint64_t offset = 0;  // of the Footer record
  std::uint64_t summary_start = 0, summary_offset_start = 0;
  std::uint32_t summary_crc = 0;  // 0: not stored
};
std::optional<Footer> readFooter(FileSource& file);  // nullopt when the file ends otherwise
// The CRC summary_crc should hold: of the summary (and summary offset) section and the Footer
// up to its summary_offset_start.
std::uint32_t summaryCrc(std::span<const std::uint8_t> summary, const Footer& footer);

}  // namespace gvio::io::ros2::mcap
