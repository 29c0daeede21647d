#include "io/ros2/mcap_records.hpp"

#include <lz4frame.h>
#include <zlib.h>
#include <zstd.h>

#include <algorithm>
#include <cstdio>
#include <limits>
#include <memory>
#include <system_error>

#include "io/ros2/ros2_error.hpp"

namespace gvio::io::ros2::mcap {

namespace {

constexpr std::array<const char*, 16> kOpNames{
    "invalid",  "Header",        "Footer",        "Schema",     "Channel",         "Message",
    "Chunk",    "MessageIndex",  "ChunkIndex",    "Attachment", "AttachmentIndex", "Statistics",
    "Metadata", "MetadataIndex", "SummaryOffset", "DataEnd"};

// zstd level 1: the reference writers' default level (mcap's CompressionLevel::Default), fast
// enough to record sensor streams live and within a few percent of level 3's ratio on them.
constexpr int kZstdLevel = 1;

// The most an algorithm can expand its input, so a larger uncompressed_size is damage, refused
// before anything is allocated: an LZ4 sequence adds at most 255 bytes of match per input byte; a
// zstd RLE block stores up to 128 KiB in 4 bytes. The margin covers frame headers.
constexpr std::uint64_t kLz4MaxRatio = 256;
constexpr std::uint64_t kZstdMaxRatio = 32768;
constexpr std::uint64_t kRatioMargin = 4096;
// The output buffer starts at this many times the input (most chunks fit) and doubles as needed,
// so what is allocated follows what the data really decompresses to, not what its size claims.
constexpr std::uint64_t kInitialRatio = 64;

[[noreturn]] void fail(const std::string& where, const std::string& what) {
  throw Ros2Error(where + ": " + what);
}

// Grows `out` (by doubling) up to limit bytes; false when it is already that large.
bool grow(Bytes& out, std::uint64_t limit) {
  if (out.size() >= limit) return false;
  out.resize(static_cast<std::size_t>(std::min<std::uint64_t>(limit, 2 * out.size() + 4096)));
  return true;
}

// Decompresses zstd frames (any number, as the format allows) into out, at most limit bytes;
// returns the bytes produced (limit when there would be more).
std::size_t unzstd(std::span<const std::uint8_t> in, Bytes& out, std::uint64_t limit,
                   const std::string& where) {
  const std::unique_ptr<ZSTD_DCtx, decltype(&ZSTD_freeDCtx)> ctx(ZSTD_createDCtx(), ZSTD_freeDCtx);
  if (!ctx) fail(where, "cannot allocate a zstd decoder");
  ZSTD_inBuffer input{in.data(), in.size(), 0};
  std::size_t produced = 0;
  for (;;) {
    if (produced == out.size() && !grow(out, limit)) return produced;
    ZSTD_outBuffer output{out.data(), out.size(), produced};
    const std::size_t before = input.pos;
    const std::size_t result = ZSTD_decompressStream(ctx.get(), &output, &input);
    if (ZSTD_isError(result)) fail(where, std::string("zstd: ") + ZSTD_getErrorName(result));
    const bool progressed = output.pos != produced || input.pos != before;
    produced = output.pos;
    if (result == 0 && input.pos == input.size) return produced;  // the last frame is complete
    // With room left in the output, the decoder has flushed all it could: it needs more input.
    if (produced < out.size() && (input.pos == input.size || !progressed)) {
      fail(where, "zstd data ends inside a frame");
    }
  }
}

// The same for LZ4 frames.
std::size_t unlz4(std::span<const std::uint8_t> in, Bytes& out, std::uint64_t limit,
                  const std::string& where) {
  LZ4F_dctx* raw = nullptr;
  if (LZ4F_isError(LZ4F_createDecompressionContext(&raw, LZ4F_VERSION))) {
    fail(where, "cannot allocate an lz4 decoder");
  }
  const std::unique_ptr<LZ4F_dctx, decltype(&LZ4F_freeDecompressionContext)> ctx(
      raw, LZ4F_freeDecompressionContext);
  std::size_t consumed = 0, produced = 0;
  for (;;) {
    if (produced == out.size() && !grow(out, limit)) return produced;
    std::size_t dst_size = out.size() - produced;
    std::size_t src_size = in.size() - consumed;
    const std::size_t result = LZ4F_decompress(ctx.get(), out.data() + produced, &dst_size,
                                               in.data() + consumed, &src_size, nullptr);
    if (LZ4F_isError(result)) fail(where, std::string("lz4: ") + LZ4F_getErrorName(result));
    produced += dst_size;
    consumed += src_size;
    if (result == 0 && consumed == in.size()) return produced;  // the last frame is complete
    if (produced < out.size() && (consumed == in.size() || (dst_size == 0 && src_size == 0))) {
      fail(where, "lz4 data ends inside a frame");
    }
  }
}

// Refuses sizes no valid chunk can have (spec "Chunk": uncompressed_size of the records field).
void checkClaim(std::string_view compression, std::uint64_t compressed, std::uint64_t claim,
                const std::string& where) {
  if (claim > kMaxChunkBytes) {
    fail(where, "uncompressed_size " + withCommas(claim) + " exceeds the " +
                    withCommas(kMaxChunkBytes) + " bytes a chunk may have here");
  }
  const std::uint64_t ratio = compression == "lz4" ? kLz4MaxRatio : kZstdMaxRatio;
  if (compression.empty() ? claim != compressed : claim > compressed * ratio + kRatioMargin) {
    fail(where, "uncompressed_size " + withCommas(claim) + " is impossible for " +
                    withCommas(compressed) + " bytes of " +
                    (compression.empty() ? std::string("uncompressed") : std::string(compression)) +
                    " data");
  }
}

// Spec "Chunk": uncompressed_crc 0 means no CRC was stored.
void checkCrc(const Bytes& records, std::uint32_t stored, const std::string& where) {
  if (stored == 0) return;
  const std::uint32_t computed = crc32(records.data(), records.size());
  if (computed != stored) {
    fail(where, "CRC mismatch (stored " + hex32(stored) + ", computed " + hex32(computed) + ")");
  }
}

Bytes decompressRaw(std::string_view compression, std::span<const std::uint8_t> compressed,
                    std::uint64_t uncompressed_size, const std::string& where) {
  if (!isKnownCompression(compression)) {
    fail(where, "unknown compression '" + std::string(compression) + "'");
  }
  checkClaim(compression, compressed.size(), uncompressed_size, where);
  if (compression.empty()) return {compressed.begin(), compressed.end()};
  if (uncompressed_size == 0 && compressed.empty()) return {};
  // One byte beyond the claim tells "exactly as claimed" from "more than claimed".
  const std::uint64_t limit = uncompressed_size + 1;
  Bytes out(static_cast<std::size_t>(
      std::min<std::uint64_t>(limit, compressed.size() * kInitialRatio + 4096)));
  const std::size_t produced = compression == "zstd" ? unzstd(compressed, out, limit, where)
                                                     : unlz4(compressed, out, limit, where);
  if (produced != uncompressed_size) {
    fail(where, (produced > uncompressed_size
                     ? "decompresses to more than "
                     : "decompresses to " + withCommas(produced) + " bytes, not ") +
                    withCommas(uncompressed_size) + " bytes (its uncompressed_size)");
  }
  out.resize(produced);
  return out;
}

template <typename T>
void putLittleEndian(Bytes& out, T value) {
  for (std::size_t byte = 0; byte < sizeof(T); ++byte) {
    out.push_back(static_cast<std::uint8_t>(value >> (8 * byte)));
  }
}

}  // namespace

std::string opName(std::uint8_t opcode) {
  char code[8];
  std::snprintf(code, sizeof code, "0x%02X", static_cast<unsigned>(opcode));
  return std::string(isKnownOp(opcode) ? kOpNames[opcode] : "unknown") + " (" + code + ")";
}

std::string withCommas(std::uint64_t value) {
  std::string digits = std::to_string(value);
  for (std::size_t at = digits.size(); at > 3; at -= 3) digits.insert(at - 3, 1, ',');
  return digits;
}

std::string hex32(std::uint32_t value) {
  char text[16];
  std::snprintf(text, sizeof text, "0x%08x", static_cast<unsigned>(value));
  return text;
}

std::uint32_t crc32(const std::uint8_t* data, std::size_t size, std::uint32_t crc) {
  return static_cast<std::uint32_t>(::crc32_z(crc, data, size));
}

void putU8(Bytes& out, std::uint8_t value) {
  out.push_back(value);
}
void putU16(Bytes& out, std::uint16_t value) {
  putLittleEndian(out, value);
}
void putU32(Bytes& out, std::uint32_t value) {
  putLittleEndian(out, value);
}
void putU64(Bytes& out, std::uint64_t value) {
  putLittleEndian(out, value);
}
void putBytes(Bytes& out, const std::uint8_t* data, std::size_t size) {
  if (size != 0) out.insert(out.end(), data, data + size);
}

void putString(Bytes& out, std::string_view text) {
  if (text.size() > std::numeric_limits<std::uint32_t>::max()) {
    throw Ros2Error("a string of " + withCommas(text.size()) +
                    " bytes does not fit MCAP's uint32 length");
  }
  putU32(out, static_cast<std::uint32_t>(text.size()));
  putBytes(out, reinterpret_cast<const std::uint8_t*>(text.data()), text.size());
}

void putStringMap(Bytes& out, const std::map<std::string, std::string>& map) {
  Bytes entries;
  for (const auto& [key, value] : map) {
    putString(entries, key);
    putString(entries, value);
  }
  if (entries.size() > std::numeric_limits<std::uint32_t>::max()) {
    throw Ros2Error("a map of " + withCommas(entries.size()) +
                    " bytes does not fit MCAP's uint32 length");
  }
  putU32(out, static_cast<std::uint32_t>(entries.size()));
  putBytes(out, entries.data(), entries.size());
}

void putRecordPrefix(Bytes& out, std::uint8_t opcode, std::uint64_t content_length) {
  putU8(out, opcode);
  putU64(out, content_length);
}

std::string Where::describe() const {
  std::string text = opName(opcode) + " record at ";
  if (chunk_offset == kInFile) return text + "byte " + withCommas(offset);
  return text + "offset " + withCommas(offset) + " in the chunk at byte " +
         withCommas(chunk_offset);
}

void FieldReader::fail(const std::string& what) const {
  throw Ros2Error(where_.describe() + ": " + what);
}

const std::uint8_t* FieldReader::take(std::uint64_t count, const char* field) {
  if (count > left()) {
    fail(std::string(field) + " needs " + withCommas(count) + " bytes, " + withCommas(left()) +
         " are left in the record");
  }
  const std::uint8_t* at = data_.data() + pos_;
  pos_ += static_cast<std::size_t>(count);
  return at;
}

std::string FieldReader::string(const char* field) {
  const std::span<const std::uint8_t> bytes = bytes32(field);
  return {reinterpret_cast<const char*>(bytes.data()), bytes.size()};
}

std::span<const std::uint8_t> FieldReader::bytes32(const char* field) {
  const std::uint32_t length = u32(field);
  return {take(length, field), length};
}

std::span<const std::uint8_t> FieldReader::bytes64(const char* field) {
  const std::uint64_t length = u64(field);
  return {take(length, field), static_cast<std::size_t>(length)};
}

std::map<std::string, std::string> FieldReader::stringMap(const char* field) {
  // The entries fill the map's byte length exactly; each is checked within it.
  FieldReader entries(bytes32(field), where_);
  std::map<std::string, std::string> map;
  while (entries.left() != 0) {
    std::string key = entries.string(field);
    map.emplace(std::move(key), entries.string(field));
  }
  return map;
}

bool isKnownCompression(std::string_view compression) {
  return compression.empty() || compression == "lz4" || compression == "zstd";
}

Bytes compress(std::string_view compression, std::span<const std::uint8_t> records) {
  Bytes out;
  if (compression == "zstd") {
    out.resize(ZSTD_compressBound(records.size()));
    const std::size_t size =
        ZSTD_compress(out.data(), out.size(), records.data(), records.size(), kZstdLevel);
    if (ZSTD_isError(size)) throw Ros2Error(std::string("zstd: ") + ZSTD_getErrorName(size));
    out.resize(size);
  } else if (compression == "lz4") {
    LZ4F_preferences_t preferences{};
    preferences.frameInfo.contentSize = records.size();  // lets readers size their buffer
    out.resize(LZ4F_compressFrameBound(records.size(), &preferences));
    const std::size_t size =
        LZ4F_compressFrame(out.data(), out.size(), records.data(), records.size(), &preferences);
    if (LZ4F_isError(size)) throw Ros2Error(std::string("lz4: ") + LZ4F_getErrorName(size));
    out.resize(size);
  } else if (compression.empty()) {
    out.assign(records.begin(), records.end());
  } else {
    throw Ros2Error("unknown compression '" + std::string(compression) + "'");
  }
  return out;
}

Bytes decompress(std::string_view compression, std::span<const std::uint8_t> compressed,
                 std::uint64_t uncompressed_size, std::uint32_t uncompressed_crc,
                 const std::string& where) {
  Bytes records = decompressRaw(compression, compressed, uncompressed_size, where);
  checkCrc(records, uncompressed_crc, where);
  return records;
}

void forEachRecord(std::span<const std::uint8_t> records, std::uint64_t base,
                   std::uint64_t chunk_offset, const RecordVisitor& visit) {
  for (std::size_t pos = 0; pos < records.size();) {
    const Where where{records[pos], base + pos, chunk_offset};
    const std::size_t left = records.size() - pos;
    const std::uint64_t length = left < kRecordPrefix ? left : le64(&records[pos + 1]);
    if (left < kRecordPrefix || length > left - kRecordPrefix) {
      throw Ros2Error(where.describe() + ": runs past the end of " +
                      (chunk_offset == Where::kInFile ? "the summary" : "the chunk's records") +
                      " (" + withCommas(left) + " bytes left)");
    }
    visit(where, records.subspan(pos + kRecordPrefix, static_cast<std::size_t>(length)));
    pos += kRecordPrefix + static_cast<std::size_t>(length);
  }
}

FileSource::FileSource(const std::filesystem::path& file) {
  std::error_code error;
  const std::uintmax_t size = std::filesystem::file_size(file, error);
  if (error) throw Ros2Error("cannot open: " + error.message());
  size_ = size;
  in_.open(file, std::ios::binary);
  if (!in_) throw Ros2Error("cannot open for reading");
}

Bytes FileSource::read(std::uint64_t offset, std::uint64_t count) {
  if (offset > size_ || count > size_ - offset) {
    throw Ros2Error(withCommas(count) + " bytes at byte " + withCommas(offset) +
                    " lie beyond the end of the file (" + withCommas(size_) + " bytes)");
  }
  Bytes bytes(static_cast<std::size_t>(count));
  if (count == 0) return bytes;
  if (at_ != offset) {
    in_.clear();
    in_.seekg(static_cast<std::streamoff>(offset));
  }
  in_.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(count));
  if (!in_) {
    at_ = ~std::uint64_t{0};
    in_.clear();
    throw Ros2Error("cannot read " + withCommas(count) + " bytes at byte " + withCommas(offset));
  }
  at_ = offset + count;
  return bytes;
}

Header readHeader(FileSource& file) {
  const std::uint64_t size = file.size();
  const std::uint64_t magic = kMagic.size();
  if (size < magic || file.read(0, magic) != Bytes(kMagic.begin(), kMagic.end())) {
    throw Ros2Error("not an MCAP file (it does not start with the MCAP magic)");
  }
  const auto cut = [&] {
    return Ros2Error("cut short inside the Header record at byte 8 (the file has " +
                     withCommas(size) + " bytes)");
  };
  if (size - magic < kRecordPrefix) throw cut();
  const Bytes prefix = file.read(magic, kRecordPrefix);
  if (prefix[0] != op::kHeader) {
    throw Ros2Error("the record at byte 8 is " + opName(prefix[0]) + ", not the Header");
  }
  const std::uint64_t length = le64(prefix.data() + 1);
  if (length > size - magic - kRecordPrefix) throw cut();
  const Bytes content = file.read(magic + kRecordPrefix, length);
  FieldReader fields(content, {op::kHeader, magic});
  Header header;
  header.profile = fields.string("profile");
  header.library = fields.string("library");
  header.end = magic + kRecordPrefix + length;
  return header;
}

std::optional<Footer> readFooter(FileSource& file) {
  constexpr std::uint64_t kTail = kRecordPrefix + kFooterContent + kMagic.size();
  const std::uint64_t size = file.size();
  if (size < kMagic.size() + kTail) return std::nullopt;
  const Bytes tail = file.read(size - kTail, kTail);
  if (!std::equal(kMagic.begin(), kMagic.end(), tail.end() - 8) || tail[0] != op::kFooter ||
      le64(&tail[1]) != kFooterContent) {
    return std::nullopt;
  }
  return Footer{size - kTail, le64(&tail[9]), le64(&tail[17]), le32(&tail[25])};
}

std::uint32_t summaryCrc(std::span<const std::uint8_t> summary, const Footer& footer) {
  Bytes fields;
  putRecordPrefix(fields, op::kFooter, kFooterContent);
  putU64(fields, footer.summary_start);
  putU64(fields, footer.summary_offset_start);
  return crc32(fields.data(), fields.size(), crc32(summary.data(), summary.size()));
}

}  // namespace gvio::io::ros2::mcap
