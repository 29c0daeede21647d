#pragma once
// Writes an MCAP file (https://mcap.dev/spec) the way the reference writers lay one out for a
// ROS 2 bag: Header; chunks (each followed by its MessageIndex records) holding the Schema and
// Channel records before the first message that uses them; DataEnd; a summary (Schema, Channel,
// Statistics, ChunkIndex records), SummaryOffset records, the Footer and the closing magic.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "io/ros2/mcap_reader.hpp"

namespace gvio::io::ros2 {

enum class McapCompression { kNone, kLz4, kZstd };

class McapWriter {
 public:
  // Writes to `file` directly (the caller renames it into place). chunk_bytes: a chunk is closed
  // when its uncompressed records reach this size. Throws Ros2Error.
  McapWriter(const std::filesystem::path& file, McapCompression compression,
             std::string profile = "ros2", std::size_t chunk_bytes = 4u << 20);
  // Does not throw. An unclosed file is left incomplete: the chunks written so far are readable
  // (McapReader reports the file as cut short), the open chunk is lost.
  ~McapWriter();
  McapWriter(const McapWriter&) = delete;
  McapWriter& operator=(const McapWriter&) = delete;

  // Ids from 1 (spec "Schema": 0 is invalid).
  std::uint16_t addSchema(const std::string& name, const std::string& encoding,
                          const std::string& data);
  // Ids from 1. schema_id 0: no schema; else one addSchema returned.
  std::uint16_t addChannel(const std::string& topic, std::uint16_t schema_id,
                           const std::string& message_encoding,
                           const std::map<std::string, std::string>& metadata = {});
  // Sequence numbers count each channel's messages from 0. Throws Ros2Error for an unknown
  // channel, data of about 1 GiB or more (a chunk's limit), after close() or when the file cannot
  // be written.
  void write(std::uint16_t channel_id, std::uint64_t log_time_ns, std::uint64_t publish_time_ns,
             const std::uint8_t* data, std::size_t size);
  // Flushes the last chunk; writes DataEnd, the summary, SummaryOffset records, the Footer (with
  // summary_crc) and the closing magic. Throws Ros2Error; a second call does nothing.
  void close();

 private:
  // Spec "Chunk Index" fields of a chunk written.
  struct ChunkIndex {
    std::uint64_t start_ns = 0, end_ns = 0;
    std::uint64_t offset = 0, length = 0;
    std::map<std::uint16_t, std::uint64_t> message_index_offsets;
    std::uint64_t message_index_length = 0;
    std::uint64_t compressed_size = 0, uncompressed_size = 0;
  };

  void checkOpen() const;
  std::vector<std::uint8_t> pendingDefinitions(std::uint16_t channel_id) const;
  void markWritten(std::uint16_t channel_id);
  void flushChunk();
  void writeMessageIndexes(ChunkIndex& index);
  std::vector<std::uint8_t> summary(std::uint64_t summary_start) const;
  void put(const std::uint8_t* data, std::size_t size);
  void put(const std::vector<std::uint8_t>& bytes) { put(bytes.data(), bytes.size()); }

  std::ofstream out_;
  std::uint64_t written_ = 0;   // bytes written to the file: the next record's offset
  std::uint32_t data_crc_ = 0;  // CRC-32 of those bytes (for DataEnd)
  std::string compression_;     // spec "Chunk" compression: "", "lz4" or "zstd"
  std::size_t chunk_bytes_;
  bool closed_ = false;

  std::vector<McapSchema> schemas_;    // id = index + 1
  std::vector<McapChannel> channels_;  // id = index + 1
  std::vector<bool> schema_written_, channel_written_;
  std::vector<std::uint32_t> sequences_;           // per channel: the next sequence number
  std::map<std::uint16_t, std::uint64_t> counts_;  // messages per channel (those with any)

  // The open chunk: its uncompressed records, message times and index entries per channel
  // (spec "Message Index": log_time and the record's offset in the uncompressed records).
  std::vector<std::uint8_t> chunk_;
  std::uint64_t chunk_start_ns_ = 0, chunk_end_ns_ = 0;
  std::map<std::uint16_t, std::vector<std::pair<std::uint64_t, std::uint64_t>>> chunk_entries_;

  std::vector<ChunkIndex> chunk_indexes_;
  std::uint64_t message_count_ = 0, start_ns_ = 0, end_ns_ = 0;
};

}  // namespace gvio::io::ros2
