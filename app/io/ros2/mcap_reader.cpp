#include "io/ros2/mcap_reader.hpp"

#include <algorithm>
#include <limits>
#include <utility>

#include "io/ros2/mcap_records.hpp"
#include "io/ros2/ros2_error.hpp"

namespace gvio::io::ros2 {

namespace {

using mcap::Bytes;
using mcap::kRecordPrefix;
using mcap::withCommas;
namespace op = mcap::op;

using ChunkSpans = std::vector<std::pair<std::uint64_t, std::uint64_t>>;  // offset, length

std::string chunkWhere(const McapChunkInfo& chunk) {
  return "chunk at byte " + withCommas(chunk.record_offset);
}

Bytes decompressChunk(const McapChunkInfo& chunk, std::span<const std::uint8_t> compressed) {
  return mcap::decompress(chunk.compression, compressed, chunk.uncompressed_size,
                          chunk.uncompressed_crc, chunkWhere(chunk));
}

// At most 40 characters of a string read from the file, for a warning.
std::string quoted(const std::string& text) {
  return "'" + (text.size() > 40 ? text.substr(0, 40) + "..." : text) + "'";
}

}  // namespace

McapReader::McapReader(const std::filesystem::path& file)
    : file_(std::make_unique<mcap::FileSource>(file)) {
  const mcap::Header header = mcap::readHeader(*file_);
  profile_ = header.profile;
  library_ = header.library;
  const std::uint64_t data_start = header.end;
  const std::optional<mcap::Footer> footer = mcap::readFooter(*file_);
  // Spec "Footer": summary_start 0 means there is no summary; then only a scan finds messages.
  if (!footer || footer->summary_start == 0 || !readIndexed(*footer, data_start)) {
    scanDataSection(data_start, footer.has_value());
  }
  finish();
}

McapReader::~McapReader() = default;

// Reads the chunks the summary's ChunkIndex records point to (spec "Chunk Index"). False when
// the data section must be scanned instead: the summary has no chunk index (what it holds is
// kept), or cannot be used (what was read is forgotten).
bool McapReader::readIndexed(const mcap::Footer& footer, std::uint64_t data_start) {
  ChunkSpans spans;
  if (!readSummary(footer, data_start, spans)) return false;
  if (spans.empty()) return false;  // messages, if any, are outside chunks: only a scan finds them
  std::sort(spans.begin(), spans.end());
  spans.erase(std::unique(spans.begin(), spans.end()), spans.end());
  for (const auto& [offset, length] : spans) {
    const bool inside = offset >= data_start && offset <= footer.summary_start &&
                        length >= kRecordPrefix && length <= footer.summary_start - offset;
    const Bytes prefix = inside ? file_->read(offset, kRecordPrefix) : Bytes(kRecordPrefix);
    if (!inside || prefix[0] != op::kChunk || mcap::le64(&prefix[1]) != length - kRecordPrefix) {
      reset();
      found_.warnings.push_back("summary: the ChunkIndex for byte " + withCommas(offset) +
                                " does not point to a Chunk record of its chunk_length " +
                                withCommas(length) + "; scanned the data section instead");
      return false;
    }
    readChunk(offset, length - kRecordPrefix);
  }
  if (statistics_messages_ && *statistics_messages_ != found_.messages.size()) {
    const std::string line = "summary: Statistics message_count " +
                             withCommas(*statistics_messages_) + " but the chunk index leads to " +
                             withCommas(found_.messages.size()) +
                             " messages; scanned the data section instead";
    reset();
    found_.warnings.push_back(line);
    return false;
  }
  return true;
}

// Spec "Summary Section": Schema, Channel, ChunkIndex and Statistics records are used; the rest
// (AttachmentIndex, MetadataIndex, SummaryOffset) skipped. False, with a warning, when unusable.
bool McapReader::readSummary(const mcap::Footer& footer, std::uint64_t data_start,
                             ChunkSpans& spans) {
  if (footer.summary_start < data_start || footer.summary_start > footer.offset) {
    found_.warnings.push_back("footer: summary_start " + withCommas(footer.summary_start) +
                              " lies outside the file's records; scanned the data section instead");
    return false;
  }
  const Bytes summary = file_->read(footer.summary_start, footer.offset - footer.summary_start);
  const std::uint32_t computed = mcap::summaryCrc(summary, footer);
  if (footer.summary_crc != 0 && computed != footer.summary_crc) {
    found_.warnings.push_back("summary: CRC mismatch (stored " + mcap::hex32(footer.summary_crc) +
                              ", computed " + mcap::hex32(computed) +
                              "); scanned the data section instead");
    return false;
  }
  try {
    mcap::forEachRecord(summary, footer.summary_start, mcap::Where::kInFile,
                        [&](const mcap::Where& where, std::span<const std::uint8_t> content) {
                          readSummaryRecord(where, content, spans);
                        });
  } catch (const Ros2Error& error) {
    reset();
    spans.clear();
    statistics_messages_.reset();
    found_.warnings.push_back(std::string("summary unusable (") + error.what() +
                              "); scanned the data section instead");
    return false;
  }
  return true;
}

void McapReader::readSummaryRecord(const mcap::Where& where, std::span<const std::uint8_t> content,
                                   ChunkSpans& spans) {
  mcap::FieldReader fields(content, where);
  if (where.opcode == op::kChunkIndex) {
    fields.u64("message_start_time");
    fields.u64("message_end_time");
    const std::uint64_t offset = fields.u64("chunk_start_offset");
    spans.emplace_back(offset, fields.u64("chunk_length"));
  } else if (where.opcode == op::kStatistics) {
    statistics_messages_ = fields.u64("message_count");
  } else if (where.opcode == op::kSchema || where.opcode == op::kChannel) {
    readRecord(where.opcode, content, where, McapMessageRef::kNoChunk, 0);
  }
}

// Spec "Data Section": records from after the Header up to DataEnd, read one by one. A record
// running past the end of the file means the file was cut short: what came before is kept.
void McapReader::scanDataSection(std::uint64_t start, bool has_footer) {
  const std::uint64_t size = file_->size();
  for (std::uint64_t pos = start;;) {
    const std::uint64_t left = size - pos;
    if (left < kRecordPrefix) {
      warnCutShort(pos, left == 0 ? "the file ends there, without a DataEnd record"
                                  : "a record's opcode and length are incomplete");
      return;
    }
    const Bytes prefix = file_->read(pos, kRecordPrefix);
    const mcap::Where where{prefix[0], pos};
    const std::uint64_t length = mcap::le64(&prefix[1]);
    if (length > left - kRecordPrefix) {
      warnCutShort(pos, "the " + mcap::opName(where.opcode) + " record at byte " + withCommas(pos) +
                            " needs " + withCommas(length) +
                            " bytes after its opcode and length, " +
                            withCommas(left - kRecordPrefix) + " are there" +
                            (where.opcode == op::kChunk ? "; that chunk is dropped" : ""));
      return;
    }
    const std::uint64_t content_at = pos + kRecordPrefix;
    if (where.opcode == op::kDataEnd || where.opcode == op::kFooter) {
      // A Footer straight after the data is how files of writers without DataEnd end.
      if (!has_footer) {
        found_.warnings.push_back(
            "cut short: the file (" + withCommas(size) +
            " bytes) ends after its data section, without a valid Footer; all " +
            withCommas(found_.messages.size()) + " messages are there");
      }
      return;
    }
    if (where.opcode == op::kChunk) {
      readChunk(pos, length);
    } else if (where.opcode == op::kMessage) {
      // Only the fixed fields and the head: the data is read on demand.
      const std::uint64_t wanted = mcap::kMessageFixed + kHeadBytes;
      const Bytes head = file_->read(content_at, std::min(length, wanted));
      addMessage(head, length, where, McapMessageRef::kNoChunk, content_at);
    } else if (where.opcode == op::kSchema || where.opcode == op::kChannel) {
      readRecord(where.opcode, file_->read(content_at, length), where, McapMessageRef::kNoChunk,
                 content_at);
    } else {
      readRecord(where.opcode, {}, where, McapMessageRef::kNoChunk, content_at);  // skipped
    }
    pos = content_at + length;
  }
}

void McapReader::warnCutShort(std::uint64_t pos, const std::string& detail) {
  found_.warnings.push_back("cut short: read " + withCommas(pos) + " of " +
                            withCommas(file_->size()) + " bytes (the data section up to byte " +
                            withCommas(pos) + "), " + withCommas(found_.messages.size()) +
                            " messages; the rest is lost (" + detail + ")");
}

// Spec "Chunk": message_start_time, message_end_time, uncompressed_size, uncompressed_crc,
// compression, records (uint64 length + bytes).
void McapReader::readChunk(std::uint64_t offset, std::uint64_t length) {
  const Bytes content = file_->read(offset + kRecordPrefix, length);
  mcap::FieldReader fields(content, {op::kChunk, offset});
  McapChunkInfo chunk;
  chunk.record_offset = offset;
  fields.u64("message_start_time");
  fields.u64("message_end_time");
  chunk.uncompressed_size = fields.u64("uncompressed_size");
  chunk.uncompressed_crc = fields.u32("uncompressed_crc");
  chunk.compression = fields.string("compression");
  const std::span<const std::uint8_t> records = fields.bytes64("records");
  chunk.records_offset = offset + kRecordPrefix + (fields.position() - records.size());
  chunk.compressed_size = records.size();
  if (!mcap::isKnownCompression(chunk.compression)) {
    ++found_.skipped_chunks[chunk.compression];
    return;
  }
  Bytes data = decompressChunk(chunk, records);
  found_.chunks.push_back(std::move(chunk));
  scanChunk(found_.chunks.size() - 1, data);
  cached_chunk_ = found_.chunks.size() - 1;  // reading messages in file order starts with this one
  cached_ = std::move(data);
}

// The records inside a chunk (spec "Chunk": Schema, Channel and Message records). Their bytes
// passed the CRC check, so a record that does not fit is a defect, not damage.
void McapReader::scanChunk(std::size_t chunk, std::span<const std::uint8_t> records) {
  mcap::forEachRecord(records, 0, found_.chunks[chunk].record_offset,
                      [&](const mcap::Where& where, std::span<const std::uint8_t> content) {
                        readRecord(where.opcode, content, where, chunk,
                                   where.offset + kRecordPrefix);
                      });
}

// One Schema, Channel or Message record (content at content_offset in the file or the chunk);
// other records are skipped, those of unknown opcodes counted.
void McapReader::readRecord(std::uint8_t opcode, std::span<const std::uint8_t> content,
                            const mcap::Where& where, std::size_t chunk,
                            std::uint64_t content_offset) {
  mcap::FieldReader fields(content, where);
  if (opcode == op::kSchema) {  // spec "Schema": id, name, encoding, data (uint32 length)
    McapSchema schema;
    schema.id = fields.u16("id");
    schema.name = fields.string("name");
    schema.encoding = fields.string("encoding");
    const std::span<const std::uint8_t> data = fields.bytes32("data");
    schema.data.assign(data.begin(), data.end());
    addSchema(std::move(schema), where);
  } else if (opcode == op::kChannel) {  // spec "Channel"
    McapChannel channel;
    channel.id = fields.u16("id");
    channel.schema_id = fields.u16("schema_id");
    channel.topic = fields.string("topic");
    channel.message_encoding = fields.string("message_encoding");
    channel.metadata = fields.stringMap("metadata");
    addChannel(std::move(channel), where);
  } else if (opcode == op::kMessage) {
    addMessage(content, content.size(), where, chunk, content_offset);
  } else if (!mcap::isKnownOp(opcode)) {
    ++found_.unknown_records;
    found_.unknown_opcodes.insert(opcode);
  }
}

// Spec "Schema": ids are unique, a repeated record must be identical; id 0 is invalid and ignored.
void McapReader::addSchema(McapSchema schema, const mcap::Where& where) {
  if (schema.id == 0) return;
  const auto known = found_.schema_index.find(schema.id);
  if (known == found_.schema_index.end()) {
    found_.schema_index.emplace(schema.id, found_.schemas.size());
    found_.schemas.push_back(std::move(schema));
    return;
  }
  const McapSchema& old = found_.schemas[known->second];
  if (old.name != schema.name || old.encoding != schema.encoding || old.data != schema.data) {
    throw Ros2Error(where.describe() + ": schema " + std::to_string(schema.id) +
                    " redefined with different content");
  }
}

// Spec "Channel": ids are unique, a repeated record must be identical.
void McapReader::addChannel(McapChannel channel, const mcap::Where& where) {
  const auto known = found_.channel_index.find(channel.id);
  if (known == found_.channel_index.end()) {
    found_.channel_index.emplace(channel.id, found_.channels.size());
    found_.channels.push_back(std::move(channel));
    return;
  }
  const McapChannel& old = found_.channels[known->second];
  if (old.schema_id != channel.schema_id || old.topic != channel.topic ||
      old.message_encoding != channel.message_encoding || old.metadata != channel.metadata) {
    throw Ros2Error(where.describe() + ": channel " + std::to_string(channel.id) +
                    " redefined with different content");
  }
}

// Spec "Message": channel_id, sequence, log_time, publish_time, then the data (the rest of the
// record). `head` holds at least the fixed fields and the first kHeadBytes of data (if any).
void McapReader::addMessage(std::span<const std::uint8_t> head, std::uint64_t length,
                            const mcap::Where& where, std::size_t chunk,
                            std::uint64_t content_offset) {
  mcap::FieldReader fields(head, where);
  if (length < mcap::kMessageFixed) fields.fail("shorter than a Message's fixed fields");
  if (length - mcap::kMessageFixed > std::numeric_limits<std::uint32_t>::max()) {
    fields.fail("message data over 4 GiB");
  }
  McapMessageRef message;
  message.channel_id = fields.u16("channel_id");
  message.sequence = fields.u32("sequence");
  message.log_time_ns = fields.u64("log_time");
  message.publish_time_ns = fields.u64("publish_time");
  message.chunk = chunk;
  message.offset = content_offset + mcap::kMessageFixed;
  message.size = static_cast<std::uint32_t>(length - mcap::kMessageFixed);
  std::array<std::uint8_t, kHeadBytes> bytes{};
  const std::size_t count = std::min<std::size_t>({kHeadBytes, message.size, fields.left()});
  std::copy_n(head.begin() + mcap::kMessageFixed, count, bytes.begin());
  found_.messages.push_back(message);
  found_.heads.push_back(bytes);
}

// Forgets what an abandoned summary-driven read collected (the Statistics count stays).
void McapReader::reset() {
  found_ = Contents{};
  cached_chunk_ = McapMessageRef::kNoChunk;
  cached_.clear();
}

// The warnings gathered while reading, one line each.
void McapReader::finish() {
  for (const auto& [compression, count] : found_.skipped_chunks) {
    found_.warnings.push_back("skipped " + withCommas(count) + " chunk(s) of unknown compression " +
                              quoted(compression) + ": their messages are not read");
  }
  if (statistics_messages_ && *statistics_messages_ != found_.messages.size()) {
    found_.warnings.push_back("the Statistics record counts " + withCommas(*statistics_messages_) +
                              " messages, " + withCommas(found_.messages.size()) + " were found");
  }
  if (found_.unknown_records != 0) {
    std::string codes;
    for (const std::uint8_t code : found_.unknown_opcodes) {
      codes += (codes.empty() ? "" : ", ") + mcap::opName(code).substr(8);  // "(0x81)"
    }
    found_.warnings.push_back("skipped " + withCommas(found_.unknown_records) +
                              " record(s) of unknown opcodes " + codes);
  }
  const auto orphans =
      std::count_if(found_.messages.begin(), found_.messages.end(),
                    [&](const auto& m) { return channel(m.channel_id) == nullptr; });
  if (orphans != 0) {
    found_.warnings.push_back(std::to_string(orphans) +
                              " message(s) on channels without a Channel record");
  }
}

const McapSchema* McapReader::schema(std::uint16_t id) const {
  const auto found = found_.schema_index.find(id);
  return found == found_.schema_index.end() ? nullptr : &found_.schemas[found->second];
}

const McapChannel* McapReader::channel(std::uint16_t id) const {
  const auto found = found_.channel_index.find(id);
  return found == found_.channel_index.end() ? nullptr : &found_.channels[found->second];
}

std::vector<std::uint8_t> McapReader::loadChunk(const McapChunkInfo& chunk) const {
  const Bytes compressed = file_->read(chunk.records_offset, chunk.compressed_size);
  return decompressChunk(chunk, compressed);
}

std::vector<std::uint8_t> McapReader::read(const McapMessageRef& message) const {
  const std::lock_guard<std::mutex> lock(mutex_);
  if (message.chunk == McapMessageRef::kNoChunk) return file_->read(message.offset, message.size);
  if (message.chunk >= found_.chunks.size()) {
    throw Ros2Error("a message in chunk " + std::to_string(message.chunk) + " of " +
                    std::to_string(found_.chunks.size()));
  }
  if (cached_chunk_ != message.chunk) {
    cached_chunk_ = McapMessageRef::kNoChunk;  // stays so when loading throws
    cached_ = loadChunk(found_.chunks[message.chunk]);
    cached_chunk_ = message.chunk;
  }
  if (message.offset > cached_.size() || message.size > cached_.size() - message.offset) {
    throw Ros2Error("a message at offset " + withCommas(message.offset) + " (" +
                    withCommas(message.size) + " bytes) lies beyond the " +
                    chunkWhere(found_.chunks[message.chunk]) + " (" + withCommas(cached_.size()) +
                    " bytes)");
  }
  const auto begin = cached_.begin() + static_cast<std::ptrdiff_t>(message.offset);
  return {begin, begin + message.size};
}

const std::array<std::uint8_t, McapReader::kHeadBytes>& McapReader::head(std::size_t index) const {
  if (index >= found_.heads.size()) {
    throw Ros2Error("message " + std::to_string(index) + " of " +
                    std::to_string(found_.heads.size()));
  }
  return found_.heads[index];
}

std::uint32_t McapReader::headSize(std::size_t index) const {
  head(index);  // checks the index
  return std::min(static_cast<std::uint32_t>(kHeadBytes), found_.messages[index].size);
}

}  // namespace gvio::io::ros2
