#include "io/rosbag/record_scan.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <map>
#include <optional>
#include <vector>

#include <bzlib.h>
#include <roslz4/lz4s.h>

#include "io/rosbag/bag_file.hpp"
#include "io/rosbag/little_endian.hpp"

namespace gvio::io::bag {

namespace {

constexpr std::uint64_t kMaxChunkBytes = std::uint64_t{1} << 30;

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

// The bag read at offsets (within the file: the caller checked). A seek discards the stream's
// buffer, so it seeks only when a read does not start where the last one ended: the walk reads
// each record's lengths and header in order and skips most data.
class OffsetReader {
 public:
  explicit OffsetReader(std::ifstream& in) : in_(in) {}

  std::vector<unsigned char> readAt(std::uint64_t offset, std::uint64_t count) {
    std::vector<unsigned char> bytes(count);
    if (at_ != offset) in_.seekg(static_cast<std::streamoff>(offset));
    in_.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(count));
    if (!in_) fail(offset, "cannot be read");
    at_ = offset + count;
    return bytes;
  }

 private:
  std::ifstream& in_;
  std::optional<std::uint64_t> at_;  // where the stream stands, once known
};

// A decompressed chunk, read at offsets as the file is.
class MemoryReader {
 public:
  explicit MemoryReader(const std::vector<unsigned char>& bytes) : bytes_(bytes) {}

  std::vector<unsigned char> readAt(std::uint64_t offset, std::uint64_t count) const {
    if (offset > bytes_.size() || count > bytes_.size() - offset) fail(offset, "cannot be read");
    const auto begin = bytes_.begin() + static_cast<std::ptrdiff_t>(offset);
    return {begin, begin + static_cast<std::ptrdiff_t>(count)};
  }

 private:
  const std::vector<unsigned char>& bytes_;
};

using Fields = std::map<std::string, std::string>;
// Record ops (http://wiki.ros.org/Bags/Format/2.0).
constexpr char kOpMessageData = 0x02;
constexpr char kOpFileHeader = 0x03;
constexpr char kOpIndexData = 0x04;
constexpr char kOpChunk = 0x05;
constexpr char kOpChunkInfo = 0x06;
constexpr char kOpConnection = 0x07;

// A record's op, or '\0' when its header has none of one byte.
char opOf(const Fields& fields) {
  const auto op = fields.find("op");
  return op == fields.end() || op->second.size() != 1 ? '\0' : op->second[0];
}

// A 4-byte little-endian header field, or nullopt when absent or of another size.
std::optional<std::uint32_t> field32(const Fields& fields, const char* name) {
  const auto it = fields.find(name);
  if (it == fields.end() || it->second.size() != 4) return std::nullopt;
  return littleEndian32(reinterpret_cast<const unsigned char*>(it->second.data()));
}

// An 8-byte little-endian header field, or nullopt when absent or of another size.
std::optional<std::uint64_t> field64(const Fields& fields, const char* name) {
  const auto it = fields.find(name);
  if (it == fields.end() || it->second.size() != 8) return std::nullopt;
  const auto* p = reinterpret_cast<const unsigned char*>(it->second.data());
  return std::uint64_t{littleEndian32(p)} | std::uint64_t{littleEndian32(p + 4)} << 32;
}

// A chunk header's compression and declared (uncompressed) size.
struct ChunkHeader {
  std::string compression;
  std::uint32_t size = 0;
};

// The chunk's header. A size librosbag could not have written is refused before anything
// allocates it: more than 1 GiB, an uncompressed chunk of another size than its data, or an lz4
// chunk declaring more than LZ4 can expand to (at most 255 bytes per byte: a match's length
// grows by 255 per extension byte; https://github.com/lz4/lz4/blob/dev/doc/lz4_Block_format.md).
ChunkHeader checkChunkHeader(const Fields& fields, std::uint64_t start, std::uint64_t data_len) {
  const auto compression = fields.find("compression");
  const auto unpacked = field32(fields, "size");
  if (compression == fields.end() || !unpacked)
    fail(start, "chunk header without compression or size");
  if (*unpacked > kMaxChunkBytes) fail(start, "chunk declares more than 1 GiB of messages");
  const std::string& kind = compression->second;
  if (kind != "none" && kind != "lz4" && kind != "bz2")
    fail(start, "chunk compression is not none, lz4 or bz2");
  if (kind == "none" && *unpacked != data_len)
    fail(start, "uncompressed chunk whose size differs from its data");
  if (kind == "lz4" && *unpacked > 256 * data_len + 65536)
    fail(start, "lz4 chunk declaring more data than lz4 can expand to");
  return {kind, *unpacked};
}

// A bz2 chunk's data, decompressed in steps so that memory follows what the stream holds, not
// what the chunk header declares (up to 1 GiB: allocated first, a damaged size field would cost
// that much for a few bytes of data). As BZ2_bzBuffToBuffDecompress, which librosbag calls, it
// ends at the end of the first stream; it must produce exactly the declared size.
std::vector<unsigned char> bz2Decompressed(std::vector<unsigned char>& packed,
                                           std::uint32_t unpacked_size, std::uint64_t start) {
  bz_stream stream{};
  if (BZ2_bzDecompressInit(&stream, 0, 0) != BZ_OK) fail(start, "bz2 decompressor not started");
  stream.next_in = reinterpret_cast<char*>(packed.data());
  stream.avail_in = static_cast<unsigned int>(packed.size());
  std::vector<unsigned char> out;
  int rc = BZ_OK;
  while (rc == BZ_OK && out.size() <= unpacked_size) {
    const std::size_t have = out.size();
    const std::size_t room = std::min<std::size_t>(std::max<std::size_t>(have, 1 << 16),
                                                   std::size_t{unpacked_size} + 1 - have);
    out.resize(have + room);
    stream.next_out = reinterpret_cast<char*>(out.data() + have);
    stream.avail_out = static_cast<unsigned int>(room);
    rc = BZ2_bzDecompress(&stream);
    out.resize(have + room - stream.avail_out);
    if (rc == BZ_OK && stream.avail_out > 0) rc = BZ_UNEXPECTED_EOF;  // input ended mid-stream
  }
  BZ2_bzDecompressEnd(&stream);
  if (rc != BZ_STREAM_END && out.size() <= unpacked_size)
    fail(start, "bz2 chunk whose data does not decompress");
  return out;
}

// A compressed chunk's data decompressed as librosbag decompresses it (Bz2Stream and LZ4Stream::
// decompress: one buffer-to-buffer call into the declared size), which it must fill exactly.
// lz4 is decompressed into the declared size at once: checkChunkHeader bounded it by the data.
std::vector<unsigned char> decompressed(std::vector<unsigned char> packed, const std::string& kind,
                                        std::uint32_t unpacked_size, std::uint64_t start) {
  std::vector<unsigned char> out;
  if (kind == "bz2") {
    out = bz2Decompressed(packed, unpacked_size, start);
  } else {
    out.resize(std::max<std::uint32_t>(unpacked_size, 1));
    unsigned int out_len = unpacked_size;
    if (roslz4_buffToBuffDecompress(reinterpret_cast<char*>(packed.data()),
                                    static_cast<unsigned int>(packed.size()),
                                    reinterpret_cast<char*>(out.data()), &out_len) != ROSLZ4_OK)
      fail(start, "lz4 chunk whose data does not decompress");
    out.resize(out_len);
  }
  if (out.size() != unpacked_size)
    fail(start, kind + " chunk whose data decompresses to another size than it declares");
  return out;
}

// Records by their byte offset in the file: their ops.
using RecordOps = std::map<std::uint64_t, char>;

// The records of the last chunk: by their offset in the file from `begin` (its data) when it is
// uncompressed, in its decompressed data (`begin` 0) otherwise.
struct ChunkRecords {
  std::uint64_t begin = 0;
  RecordOps ops;
};

// An index data record (op 0x04) follows its chunk and lists (time, offset) entries of 12 bytes;
// librosbag reads a message record at each offset of the chunk's data as it stands (an offset
// into the middle of a record made it read a header past its buffer: a fuzz finding). The offsets
// are into the chunk's decompressed data for a compressed chunk.
void checkIndexData(const Fields& fields, const std::vector<unsigned char>& data,
                    std::uint64_t start, const std::optional<ChunkRecords>& chunk) {
  if (!chunk) fail(start, "index data record before any chunk");
  const auto count = field32(fields, "count");
  if (!count || data.size() != std::uint64_t{12} * *count)
    fail(start, "index data whose size is not 12 bytes per entry");
  for (std::uint64_t i = 0; i < *count; ++i) {
    const std::uint32_t offset = littleEndian32(&data[12 * i + 8]);
    const auto record = chunk->ops.find(chunk->begin + offset);
    if (record == chunk->ops.end() || record->second != kOpMessageData)
      fail(start, "index entry whose offset " + std::to_string(offset) +
                      " is not a message record of its chunk");
  }
}

// The records in [begin, end) of the file, which they must fill exactly: every header's fields
// well formed, and every connection record's data (its connection header, the same format) too.
// At the top level the records inside each chunk are walked as well (chunkRecords). librosbag
// parses all of these with ros::Header::parse, which trusts each field's length: a field longer
// than its header made it read past its buffer (a fuzz finding). `ops` gets every record walked
// at this level; `jumps` (at the top level only) the file header and chunk info records, whose
// index_pos / chunk_pos librosbag seeks to.
using Jumps = std::vector<std::pair<std::uint64_t, Fields>>;
template <typename Reader>
void walkRecords(Reader& in, std::uint64_t begin, std::uint64_t end, RecordOps& ops, Jumps* jumps);

// The records of a chunk whose data is [pos, pos + data_len) of the file, walked as librosbag will
// parse them: in the file when uncompressed, decompressed otherwise (its records go through the
// same parser, so they get the same checks).
template <typename Reader>
ChunkRecords chunkRecords(Reader& in, const Fields& fields, std::uint64_t start, std::uint64_t pos,
                          std::uint64_t data_len) {
  const ChunkHeader header = checkChunkHeader(fields, start, data_len);
  const std::string& kind = header.compression;
  ChunkRecords chunk;
  if (kind == "none") {
    chunk.begin = pos;
    walkRecords(in, pos, pos + data_len, chunk.ops, nullptr);
    return chunk;
  }
  const std::vector<unsigned char> data =
      decompressed(in.readAt(pos, data_len), kind, header.size, start);
  MemoryReader memory(data);
  try {
    walkRecords(memory, 0, data.size(), chunk.ops, nullptr);
  } catch (const BagError& e) {
    throw BagError("chunk at byte " + std::to_string(start) + ", " + kind +
                   "-decompressed: " + e.what());
  }
  return chunk;
}

template <typename Reader>
void walkRecords(Reader& in, std::uint64_t begin, std::uint64_t end, RecordOps& ops, Jumps* jumps) {
  const bool top_level = jumps != nullptr;
  std::uint64_t pos = begin;
  auto readLength = [&](const char* what) {
    if (end - pos < 4) fail(pos, what);
    const std::vector<unsigned char> bytes = in.readAt(pos, 4);
    pos += 4;
    return std::uint64_t{littleEndian32(bytes.data())};
  };
  std::optional<ChunkRecords> last_chunk;
  while (pos < end) {
    const std::uint64_t start = pos;
    const std::uint64_t header_len = readLength("truncated (no header length)");
    if (header_len > end - pos) fail(start, "header runs past the end of its container");
    const Fields fields = headerFields(in.readAt(pos, header_len), start);
    pos += header_len;
    const std::uint64_t data_len = readLength("truncated (no data length)");
    if (data_len > end - pos) fail(start, "data runs past the end of its container");
    const char op = opOf(fields);
    if (op == kOpConnection) headerFields(in.readAt(pos, data_len), start);
    if (op == kOpChunk) {
      if (!top_level) fail(start, "chunk inside a chunk");
      last_chunk = chunkRecords(in, fields, start, pos, data_len);
    }
    if (top_level && op == kOpIndexData)
      checkIndexData(fields, in.readAt(pos, data_len), start, last_chunk);
    if (top_level && (op == kOpFileHeader || op == kOpChunkInfo))
      jumps->emplace_back(start, fields);
    ops[start] = op;
    pos += data_len;
  }
}

// librosbag reads the index from the file header's index_pos and each chunk from its chunk info's
// chunk_pos: a position that is not the start of a checked record had it parse whatever bytes lie
// there (a length of 2.3 GB it then allocated; a fuzz finding). index_pos 0 is an unindexed bag,
// which librosbag reports itself.
void checkJumps(const RecordOps& top, const Jumps& jumps, std::uint64_t file_size) {
  for (const auto& [offset, fields] : jumps) {
    if (opOf(fields) == kOpFileHeader) {
      const auto index_pos = field64(fields, "index_pos");
      if (index_pos && *index_pos != 0 && *index_pos != file_size && top.count(*index_pos) == 0)
        fail(offset, "file header's index_pos " + std::to_string(*index_pos) +
                         " is not the start of a record");
    } else {
      const auto chunk_pos = field64(fields, "chunk_pos");
      const auto chunk = chunk_pos ? top.find(*chunk_pos) : top.end();
      if (chunk == top.end() || chunk->second != kOpChunk)
        fail(offset, "chunk info whose chunk_pos is not the start of a chunk");
    }
  }
}

}  // namespace

void checkBagRecords(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw BagError("cannot open the file");
  const auto size = static_cast<std::uint64_t>(in.tellg());
  // The version line as librosbag reads it, so that every file it takes for version 2.0 is
  // checked from where it reads the file header. ChunkedFile::getline reads the line with fgets
  // into 1024 bytes: the stream then stands after the newline, or after 1023 bytes without one,
  // and Bag::readFileHeaderRecord reads on from there (no seek). Bag::readVersion scans the C
  // string it got with the format below, which ends at the first NUL byte. So "#ROSBAG V2.0"
  // followed by other bytes, or by a NUL, is 2.0 to it, read from after the newline (three fuzz
  // findings: its header parser read past its buffer, then allocated 4 GB and 1.9 GB; the last
  // of these was read from where the C string ended, wrongly).
  constexpr std::uint64_t kFgetsBytes = 1023;
  std::string head(std::min(size, kFgetsBytes), '\0');
  in.seekg(0);
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  const std::size_t newline = head.find('\n');
  const std::uint64_t header_pos = newline == std::string::npos ? head.size() : newline + 1;
  const std::string line = head.substr(0, std::min<std::size_t>(header_pos, head.find('\0')));
  std::array<char, 100> type{};
  int major = -1, minor = -1;
  if (std::sscanf(line.c_str(), "#ROS%99s V%d.%d", type.data(), &major, &minor) != 3) return;
  // librosbag also reads format 1.2 (ROS 2010) with the same trust in every length (a 1.2 file
  // header asked it for 3.4 GB; a fuzz finding). Only 2.0, which rosbag has written since, is read.
  if (major != 2 || minor != 0) {
    throw BagError("ROS bag format " + std::to_string(major) + "." + std::to_string(minor) +
                   ": only format 2.0 is read");
  }
  in.clear();
  RecordOps top;
  Jumps jumps;
  OffsetReader reader(in);
  walkRecords(reader, header_pos, size, top, &jumps);
  checkJumps(top, jumps, size);
}

}  // namespace gvio::io::bag
