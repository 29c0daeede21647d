#include "io/ros2/mcap_writer.hpp"

#include <algorithm>
#include <limits>

#include "io/ros2/mcap_records.hpp"
#include "io/ros2/ros2_error.hpp"

namespace gvio::io::ros2 {

namespace {

using mcap::Bytes;
namespace op = mcap::op;

constexpr std::size_t kMaxIds = std::numeric_limits<std::uint16_t>::max();

std::string compressionName(McapCompression compression) {
  switch (compression) {
    case McapCompression::kLz4:
      return "lz4";
    case McapCompression::kZstd:
      return "zstd";
    case McapCompression::kNone:
      break;
  }
  return "";
}

// <opcode><uint64 length><content> (spec "Records").
void putRecord(Bytes& out, std::uint8_t opcode, const Bytes& content) {
  mcap::putRecordPrefix(out, opcode, content.size());
  mcap::putBytes(out, content.data(), content.size());
}

// Spec "Schema": id, name, encoding, data (uint32 length + bytes).
void putSchema(Bytes& out, const McapSchema& schema) {
  Bytes content;
  mcap::putU16(content, schema.id);
  mcap::putString(content, schema.name);
  mcap::putString(content, schema.encoding);
  mcap::putString(content, schema.data);
  putRecord(out, op::kSchema, content);
}

// Spec "Channel": id, schema_id, topic, message_encoding, metadata.
void putChannel(Bytes& out, const McapChannel& channel) {
  Bytes content;
  mcap::putU16(content, channel.id);
  mcap::putU16(content, channel.schema_id);
  mcap::putString(content, channel.topic);
  mcap::putString(content, channel.message_encoding);
  mcap::putStringMap(content, channel.metadata);
  putRecord(out, op::kChannel, content);
}

// Spec "Serialization": Map<uint16, uint64> = uint32 byte length + (uint16, uint64) entries.
void putIdMap(Bytes& out, const std::map<std::uint16_t, std::uint64_t>& map) {
  mcap::putU32(out, static_cast<std::uint32_t>(map.size() * 10));  // at most 65,536 entries
  for (const auto& [id, value] : map) {
    mcap::putU16(out, id);
    mcap::putU64(out, value);
  }
}

void checkUint32(std::uint64_t value, const char* what) {
  if (value > std::numeric_limits<std::uint32_t>::max()) {
    throw Ros2Error(std::string(what) + " of " + mcap::withCommas(value) +
                    " does not fit MCAP's uint32");
  }
}

}  // namespace

McapWriter::McapWriter(const std::filesystem::path& file, McapCompression compression,
                       std::string profile, std::size_t chunk_bytes)
    : compression_(compressionName(compression)), chunk_bytes_(chunk_bytes) {
  out_.open(file, std::ios::binary | std::ios::trunc);
  if (!out_) throw Ros2Error("cannot open for writing");
  // Spec "File Structure": <Magic><Header>; spec "Header": profile, library.
  Bytes head(mcap::kMagic.begin(), mcap::kMagic.end());
  Bytes header;
  mcap::putString(header, profile);
  mcap::putString(header, "gvio");
  putRecord(head, op::kHeader, header);
  put(head);
}

McapWriter::~McapWriter() = default;  // the stream flushes what it buffered, without throwing

void McapWriter::checkOpen() const {
  if (closed_) throw Ros2Error("the MCAP writer is closed");
}

std::uint16_t McapWriter::addSchema(const std::string& name, const std::string& encoding,
                                    const std::string& data) {
  checkOpen();
  if (schemas_.size() >= kMaxIds) throw Ros2Error("more than 65,535 schemas");
  const auto id = static_cast<std::uint16_t>(schemas_.size() + 1);
  schemas_.push_back({id, name, encoding, data});
  schema_written_.push_back(false);
  return id;
}

std::uint16_t McapWriter::addChannel(const std::string& topic, std::uint16_t schema_id,
                                     const std::string& message_encoding,
                                     const std::map<std::string, std::string>& metadata) {
  checkOpen();
  if (schema_id > schemas_.size()) {
    throw Ros2Error("channel " + topic + ": unknown schema " + std::to_string(schema_id));
  }
  if (channels_.size() >= kMaxIds) throw Ros2Error("more than 65,535 channels");
  const auto id = static_cast<std::uint16_t>(channels_.size() + 1);
  channels_.push_back({id, schema_id, topic, message_encoding, metadata});
  channel_written_.push_back(false);
  sequences_.push_back(0);
  return id;
}

// Spec "Channel"/"Schema": each must occur before the first record that refers to it. The
// channel's records (and its schema's) not written yet; markWritten records that they now are.
std::vector<std::uint8_t> McapWriter::pendingDefinitions(std::uint16_t channel_id) const {
  Bytes out;
  const McapChannel& channel = channels_[channel_id - 1u];
  if (channel_written_[channel_id - 1u]) return out;
  if (channel.schema_id != 0 && !schema_written_[channel.schema_id - 1u]) {
    putSchema(out, schemas_[channel.schema_id - 1u]);
  }
  putChannel(out, channel);
  return out;
}

void McapWriter::markWritten(std::uint16_t channel_id) {
  channel_written_[channel_id - 1u] = true;
  const std::uint16_t schema_id = channels_[channel_id - 1u].schema_id;
  if (schema_id != 0) schema_written_[schema_id - 1u] = true;
}

void McapWriter::write(std::uint16_t channel_id, std::uint64_t log_time_ns,
                       std::uint64_t publish_time_ns, const std::uint8_t* data, std::size_t size) {
  checkOpen();
  if (channel_id == 0 || channel_id > channels_.size()) {
    throw Ros2Error("a message on unknown channel " + std::to_string(channel_id));
  }
  // Chunks stay within what McapReader accepts (mcap::kMaxChunkBytes uncompressed).
  const Bytes definitions = pendingDefinitions(channel_id);
  const std::uint64_t needed =
      definitions.size() + mcap::kRecordPrefix + mcap::kMessageFixed + size;
  if (needed > mcap::kMaxChunkBytes) {
    throw Ros2Error("a message of " + mcap::withCommas(size) + " bytes does not fit a chunk");
  }
  if (chunk_.size() + needed > mcap::kMaxChunkBytes) flushChunk();
  mcap::putBytes(chunk_, definitions.data(), definitions.size());
  markWritten(channel_id);
  // Spec "Message": channel_id, sequence, log_time, publish_time, data (the rest of the record).
  const std::uint64_t offset = chunk_.size();
  mcap::putRecordPrefix(chunk_, op::kMessage, mcap::kMessageFixed + size);
  mcap::putU16(chunk_, channel_id);
  mcap::putU32(chunk_, sequences_[channel_id - 1u]++);
  mcap::putU64(chunk_, log_time_ns);
  mcap::putU64(chunk_, publish_time_ns);
  mcap::putBytes(chunk_, data, size);

  const bool first_in_chunk = chunk_entries_.empty();
  chunk_entries_[channel_id].emplace_back(log_time_ns, offset);
  chunk_start_ns_ = first_in_chunk ? log_time_ns : std::min(chunk_start_ns_, log_time_ns);
  chunk_end_ns_ = first_in_chunk ? log_time_ns : std::max(chunk_end_ns_, log_time_ns);
  start_ns_ = message_count_ == 0 ? log_time_ns : std::min(start_ns_, log_time_ns);
  end_ns_ = message_count_ == 0 ? log_time_ns : std::max(end_ns_, log_time_ns);
  ++message_count_;
  ++counts_[channel_id];
  if (chunk_.size() >= chunk_bytes_) flushChunk();
}

// Spec "Chunk": message_start_time, message_end_time, uncompressed_size, uncompressed_crc,
// compression, records (uint64 length + bytes); then its MessageIndex records.
void McapWriter::flushChunk() {
  if (chunk_.empty()) return;
  ChunkIndex index;
  index.start_ns = chunk_entries_.empty() ? 0 : chunk_start_ns_;
  index.end_ns = chunk_entries_.empty() ? 0 : chunk_end_ns_;
  index.offset = written_;
  index.uncompressed_size = chunk_.size();
  const std::uint32_t crc = mcap::crc32(chunk_.data(), chunk_.size());
  const Bytes compressed = compression_.empty() ? Bytes{} : mcap::compress(compression_, chunk_);
  const Bytes& records = compression_.empty() ? chunk_ : compressed;
  index.compressed_size = records.size();

  Bytes head;
  mcap::putRecordPrefix(head, op::kChunk,
                        8 + 8 + 8 + 4 + 4 + compression_.size() + 8 + records.size());
  mcap::putU64(head, index.start_ns);
  mcap::putU64(head, index.end_ns);
  mcap::putU64(head, index.uncompressed_size);
  mcap::putU32(head, crc);
  mcap::putString(head, compression_);
  mcap::putU64(head, records.size());
  put(head);
  put(records);  // not copied into `head`: a chunk is megabytes
  index.length = written_ - index.offset;
  writeMessageIndexes(index);
  chunk_indexes_.push_back(std::move(index));
  chunk_.clear();
  chunk_entries_.clear();
}

// Spec "Message Index": one per channel in the chunk: channel_id, then (log_time, offset of the
// Message record in the uncompressed records) entries; the ChunkIndex points to each.
void McapWriter::writeMessageIndexes(ChunkIndex& index) {
  Bytes bytes;
  for (const auto& [channel_id, entries] : chunk_entries_) {
    index.message_index_offsets[channel_id] = written_ + bytes.size();
    const std::uint64_t array_bytes = 16 * std::uint64_t{entries.size()};
    checkUint32(array_bytes, "a message index");
    mcap::putRecordPrefix(bytes, op::kMessageIndex, 2 + 4 + array_bytes);
    mcap::putU16(bytes, channel_id);
    mcap::putU32(bytes, static_cast<std::uint32_t>(array_bytes));
    for (const auto& [log_time_ns, offset] : entries) {
      mcap::putU64(bytes, log_time_ns);
      mcap::putU64(bytes, offset);
    }
  }
  put(bytes);
  index.message_index_length = bytes.size();
}

void McapWriter::close() {
  if (closed_) return;
  closed_ = true;  // a failure below is not retried: the file stays incomplete
  flushChunk();
  // Schemas and channels no message used go into the data section too, so a scan finds them.
  Bytes definitions;
  for (const McapChannel& channel : channels_) {
    const Bytes records = pendingDefinitions(channel.id);
    mcap::putBytes(definitions, records.data(), records.size());
    markWritten(channel.id);
  }
  for (std::size_t i = 0; i < schemas_.size(); ++i) {
    if (!schema_written_[i]) putSchema(definitions, schemas_[i]);
  }
  put(definitions);
  // Spec "Data End": data_section_crc, of every byte before it, the opening magic included (as the
  // reference writers compute it).
  Bytes data_end;
  mcap::putRecordPrefix(data_end, op::kDataEnd, 4);
  mcap::putU32(data_end, data_crc_);
  put(data_end);
  put(summary(written_));
  out_.flush();
  out_.close();
  if (!out_) throw Ros2Error("cannot finish writing the file");
}

// The summary section, the SummaryOffset records, the Footer and the closing magic, for a summary
// starting at file offset summary_start.
std::vector<std::uint8_t> McapWriter::summary(std::uint64_t summary_start) const {
  Bytes out;
  struct Group {
    std::uint8_t opcode;
    std::uint64_t start, length;
  };
  std::vector<Group> groups;
  // Spec "Summary Section": records grouped by opcode; spec "Summary Offset": one per group.
  const auto group = [&](std::uint8_t opcode, const auto& write_records) {
    const std::size_t begin = out.size();
    write_records();
    if (out.size() != begin) groups.push_back({opcode, summary_start + begin, out.size() - begin});
  };
  group(op::kSchema, [&] {
    for (const McapSchema& schema : schemas_) putSchema(out, schema);
  });
  group(op::kChannel, [&] {
    for (const McapChannel& channel : channels_) putChannel(out, channel);
  });
  group(op::kStatistics, [&] {  // spec "Statistics"
    checkUint32(chunk_indexes_.size(), "the chunk count");
    Bytes content;
    mcap::putU64(content, message_count_);
    mcap::putU16(content, static_cast<std::uint16_t>(schemas_.size()));
    mcap::putU32(content, static_cast<std::uint32_t>(channels_.size()));
    mcap::putU32(content, 0);  // attachment_count
    mcap::putU32(content, 0);  // metadata_count
    mcap::putU32(content, static_cast<std::uint32_t>(chunk_indexes_.size()));
    mcap::putU64(content, start_ns_);
    mcap::putU64(content, end_ns_);
    putIdMap(content, counts_);
    putRecord(out, op::kStatistics, content);
  });
  group(op::kChunkIndex, [&] {  // spec "Chunk Index"
    for (const ChunkIndex& index : chunk_indexes_) {
      Bytes content;
      mcap::putU64(content, index.start_ns);
      mcap::putU64(content, index.end_ns);
      mcap::putU64(content, index.offset);
      mcap::putU64(content, index.length);
      putIdMap(content, index.message_index_offsets);
      mcap::putU64(content, index.message_index_length);
      mcap::putString(content, compression_);
      mcap::putU64(content, index.compressed_size);
      mcap::putU64(content, index.uncompressed_size);
      putRecord(out, op::kChunkIndex, content);
    }
  });
  const std::uint64_t summary_offset_start = summary_start + out.size();
  for (const Group& g : groups) {
    mcap::putRecordPrefix(out, op::kSummaryOffset, 1 + 8 + 8);
    mcap::putU8(out, g.opcode);
    mcap::putU64(out, g.start);
    mcap::putU64(out, g.length);
  }
  // Spec "Footer": summary_start, summary_offset_start, then summary_crc over everything from the
  // summary's start up to here.
  mcap::putRecordPrefix(out, op::kFooter, mcap::kFooterContent);
  mcap::putU64(out, summary_start);
  mcap::putU64(out, summary_offset_start);
  mcap::putU32(out, mcap::crc32(out.data(), out.size()));
  mcap::putBytes(out, mcap::kMagic.data(), mcap::kMagic.size());
  return out;
}

void McapWriter::put(const std::uint8_t* data, std::size_t size) {
  out_.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  if (!out_) {
    throw Ros2Error("cannot write " + mcap::withCommas(size) + " bytes at byte " +
                    mcap::withCommas(written_));
  }
  written_ += size;
  data_crc_ = mcap::crc32(data, size, data_crc_);
}

}  // namespace gvio::io::ros2
