#pragma once
// Reads an MCAP file (https://mcap.dev/spec), the storage of ROS 2 bags since Iron: its schemas,
// channels and an index of every message; message data is read on demand, one chunk decompressed
// at a time. Defects throw Ros2Error (without the file name: callers add it); damage a reader can
// live with (a file cut short, an unknown compression, ...) becomes a warning instead.
#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <vector>

namespace gvio::io::ros2 {

namespace mcap {
class FileSource;
struct Footer;
struct Where;
}  // namespace mcap

struct McapSchema {
  std::uint16_t id = 0;
  std::string name, encoding;
  std::string data;
};

struct McapChannel {
  std::uint16_t id = 0;
  std::uint16_t schema_id = 0;  // 0: no schema
  std::string topic, message_encoding;
  std::map<std::string, std::string> metadata;
};

// Where one message's bytes are: inside chunk `chunk` (index into the reader's chunk list) at
// `offset` in the chunk's uncompressed records, or, for chunk == kNoChunk, at `offset` in the file.
struct McapMessageRef {
  static constexpr std::size_t kNoChunk = static_cast<std::size_t>(-1);
  std::uint16_t channel_id = 0;
  std::uint32_t sequence = 0;
  std::uint64_t log_time_ns = 0, publish_time_ns = 0;
  std::size_t chunk = kNoChunk;
  std::uint64_t offset = 0;
  std::uint32_t size = 0;  // the message data's bytes
};

// A Chunk record whose messages were read (chunks skipped for an unknown compression are not).
struct McapChunkInfo {
  std::uint64_t record_offset = 0;   // the Chunk record (its opcode) in the file
  std::uint64_t records_offset = 0;  // its compressed records field in the file
  std::uint64_t compressed_size = 0, uncompressed_size = 0;
  std::uint32_t uncompressed_crc = 0;  // 0: not stored
  std::string compression;             // "", "lz4" or "zstd"
};

class McapReader {
 public:
  static constexpr std::size_t kHeadBytes = 16;

  // Reads the file's index: through the summary's chunk index when the file has a valid footer
  // and summary, else by scanning the data section. Throws Ros2Error (also when the file cannot be
  // opened).
  explicit McapReader(const std::filesystem::path& file);
  ~McapReader();
  McapReader(const McapReader&) = delete;
  McapReader& operator=(const McapReader&) = delete;

  const std::string& profile() const { return profile_; }  // the Header's profile, e.g. "ros2"
  const std::string& library() const { return library_; }  // the Header's writing library
  const std::vector<McapSchema>& schemas() const { return found_.schemas; }
  const std::vector<McapChannel>& channels() const { return found_.channels; }
  const McapSchema* schema(std::uint16_t id) const;    // nullptr when unknown
  const McapChannel* channel(std::uint16_t id) const;  // nullptr when unknown
  const std::vector<McapChunkInfo>& chunks() const { return found_.chunks; }
  const std::vector<McapMessageRef>& messages() const { return found_.messages; }  // in file order

  // The message's data bytes. Thread-safe (a mutex; the last decompressed chunk is cached, so
  // reading messages in file order decompresses each chunk once). Throws Ros2Error.
  std::vector<std::uint8_t> read(const McapMessageRef& message) const;

  // The first headSize(i) <= 16 data bytes of messages()[i] (fewer when the message is shorter),
  // kept while indexing so that ROS header stamps are read without decompressing chunks again.
  // Throws Ros2Error for an index out of range.
  const std::array<std::uint8_t, kHeadBytes>& head(std::size_t message_index) const;
  std::uint32_t headSize(std::size_t message_index) const;

  // Damage read past, one line each: a file cut short, a Statistics message_count that differs
  // from the messages found, records with unknown opcodes, a chunk of unknown compression, ...
  const std::vector<std::string>& warnings() const { return found_.warnings; }

 private:
  bool readIndexed(const mcap::Footer& footer, std::uint64_t data_start);
  bool readSummary(const mcap::Footer& footer, std::uint64_t data_start,
                   std::vector<std::pair<std::uint64_t, std::uint64_t>>& chunk_spans);
  void readSummaryRecord(const mcap::Where& where, std::span<const std::uint8_t> content,
                         std::vector<std::pair<std::uint64_t, std::uint64_t>>& chunk_spans);
  void scanDataSection(std::uint64_t start, bool has_footer);
  void warnCutShort(std::uint64_t pos, const std::string& detail);
  void readChunk(std::uint64_t offset, std::uint64_t length);
  void scanChunk(std::size_t chunk, std::span<const std::uint8_t> records);
  void readRecord(std::uint8_t opcode, std::span<const std::uint8_t> content,
                  const mcap::Where& where, std::size_t chunk, std::uint64_t content_offset);
  void addSchema(McapSchema schema, const mcap::Where& where);
  void addChannel(McapChannel channel, const mcap::Where& where);
  void addMessage(std::span<const std::uint8_t> head, std::uint64_t length,
                  const mcap::Where& where, std::size_t chunk, std::uint64_t content_offset);
  void reset();
  void finish();
  std::vector<std::uint8_t> loadChunk(const McapChunkInfo& chunk) const;

  std::unique_ptr<mcap::FileSource> file_;
  std::string profile_, library_;
  std::optional<std::uint64_t> statistics_messages_;  // the summary's Statistics message_count
  // What was found; forgotten when a summary-driven read is abandoned for a scan.
  struct Contents {
    std::vector<McapSchema> schemas;
    std::vector<McapChannel> channels;
    std::map<std::uint16_t, std::size_t> schema_index, channel_index;  // id -> index
    std::vector<McapChunkInfo> chunks;
    std::vector<McapMessageRef> messages;
    std::vector<std::array<std::uint8_t, kHeadBytes>> heads;
    std::set<std::uint8_t> unknown_opcodes;
    std::uint64_t unknown_records = 0;
    std::map<std::string, std::uint64_t> skipped_chunks;  // by their unknown compression
    std::vector<std::string> warnings;
  } found_;

  mutable std::mutex mutex_;  // guards file_ and the cache below after construction
  mutable std::size_t cached_chunk_ = McapMessageRef::kNoChunk;
  mutable std::vector<std::uint8_t> cached_;
};

}  // namespace gvio::io::ros2
