// The MCAP reader and writer (io/ros2/mcap_reader.hpp, mcap_writer.hpp): round trips for each
// compression, the layout the writer gives the index records (checked here byte by byte, against
// https://mcap.dev/spec, not through the reader), files cut short or damaged, hand-built files
// with unchunked messages and hostile lengths.
#include <gtest/gtest.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "io/ros2/mcap_reader.hpp"
#include "io/ros2/mcap_writer.hpp"
#include "io/ros2/ros2_error.hpp"

namespace gvio::io::ros2 {
namespace {
namespace fs = std::filesystem;
using Bytes = std::vector<std::uint8_t>;

class TempDir {
 public:
  TempDir() {
    static std::atomic<int> counter{0};
    path_ = fs::temp_directory_path() /
            ("gvio_mcap_test_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

Bytes readBytes(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void writeBytes(const fs::path& file, const Bytes& bytes) {
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
}

// Serialisation written here from the spec, independent of the library's helpers.
std::uint64_t le(const Bytes& b, std::size_t at, int bytes) {
  std::uint64_t value = 0;
  for (int i = bytes - 1; i >= 0; --i) value = value << 8 | b.at(at + static_cast<std::size_t>(i));
  return value;
}
void put(Bytes& out, std::uint64_t value, int bytes) {
  for (int i = 0; i < bytes; ++i) out.push_back(static_cast<std::uint8_t>(value >> (8 * i)));
}
void putStr(Bytes& out, const std::string& text) {
  put(out, text.size(), 4);
  out.insert(out.end(), text.begin(), text.end());
}
Bytes record(std::uint8_t opcode, const Bytes& content) {
  Bytes out{opcode};
  put(out, content.size(), 8);
  out.insert(out.end(), content.begin(), content.end());
  return out;
}
void append(Bytes& out, const Bytes& more) {
  out.insert(out.end(), more.begin(), more.end());
}
std::uint32_t crc(const Bytes& b, std::size_t begin, std::size_t end) {
  return static_cast<std::uint32_t>(::crc32(0, b.data() + begin, static_cast<uInt>(end - begin)));
}

const Bytes kMagic{0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};

Bytes magicAndHeader() {
  Bytes out = kMagic;
  Bytes header;
  putStr(header, "ros2");
  putStr(header, "test");
  append(out, record(0x01, header));
  return out;
}
Bytes schemaRecord(std::uint16_t id, const std::string& name, const std::string& data) {
  Bytes content;
  put(content, id, 2);
  putStr(content, name);
  putStr(content, "ros2msg");
  putStr(content, data);
  return record(0x03, content);
}
Bytes channelRecord(std::uint16_t id, std::uint16_t schema_id, const std::string& topic) {
  Bytes content;
  put(content, id, 2);
  put(content, schema_id, 2);
  putStr(content, topic);
  putStr(content, "cdr");
  Bytes map;
  putStr(map, "offered_qos_profiles");
  putStr(map, "- history: 3");
  put(content, map.size(), 4);
  append(content, map);
  return record(0x04, content);
}
Bytes messageRecord(std::uint16_t channel, std::uint32_t sequence, std::uint64_t t,
                    const Bytes& data) {
  Bytes content;
  put(content, channel, 2);
  put(content, sequence, 4);
  put(content, t, 8);
  put(content, t + 1, 8);
  append(content, data);
  return record(0x05, content);
}
Bytes chunkRecord(const std::string& compression, const Bytes& records, std::uint64_t size,
                  std::uint32_t records_crc) {
  Bytes content;
  put(content, 0, 8);
  put(content, 0, 8);
  put(content, size, 8);
  put(content, records_crc, 4);
  putStr(content, compression);
  put(content, records.size(), 8);
  append(content, records);
  return record(0x06, content);
}
// DataEnd, a Footer without a summary, the closing magic.
Bytes closing() {
  Bytes out = record(0x0F, Bytes(4, 0));
  Bytes footer(20, 0);
  append(out, record(0x02, footer));
  append(out, kMagic);
  return out;
}

std::string commas(std::uint64_t value) {
  std::string digits = std::to_string(value);
  for (std::size_t at = digits.size(); at > 3; at -= 3) digits.insert(at - 3, 1, ',');
  return digits;
}

bool hasWarning(const McapReader& reader, const std::string& part) {
  return std::any_of(reader.warnings().begin(), reader.warnings().end(),
                     [&](const std::string& w) { return w.find(part) != std::string::npos; });
}

// Runs fn, which must throw Ros2Error; returns its message.
std::string errorOf(const std::function<void()>& fn) {
  try {
    fn();
  } catch (const Ros2Error& error) {
    return error.what();
  }
  ADD_FAILURE() << "no Ros2Error";
  return {};
}

struct Written {
  std::uint16_t channel;
  std::uint64_t log_ns, publish_ns;
  Bytes data;
};

// A bag of 3 schemas and 4 channels (one without a schema), messages of 0 to 10,000 bytes (some
// larger than a chunk) in chunks of 4 KiB.
std::vector<Written> writeBag(const fs::path& file, McapCompression compression) {
  McapWriter writer(file, compression, "ros2", 4096);
  const std::uint16_t imu = writer.addSchema("sensor_msgs/msg/Imu", "ros2msg", "# imu");
  const std::uint16_t image = writer.addSchema("sensor_msgs/msg/Image", "ros2msg", "# image");
  writer.addSchema("unused/msg/Never", "ros2msg", "");
  const std::uint16_t channels[] = {
      writer.addChannel("/imu", imu, "cdr", {{"offered_qos_profiles", "- depth: 10"}}),
      writer.addChannel("/camera", image, "cdr"), writer.addChannel("/raw", 0, "x-raw"),
      writer.addChannel("/unused", image, "cdr")};
  const std::size_t sizes[] = {0, 1, 15, 16, 17, 100, 700, 5000, 10000};
  std::mt19937 random(7);
  std::vector<Written> written;
  for (std::size_t i = 0; i < 120; ++i) {
    Written m{channels[i % 3], 1'000'000'000 + i * 1000, 999'000'000 + i * 1000,
              Bytes(sizes[(i * 5) % 9])};
    for (auto& byte : m.data) byte = static_cast<std::uint8_t>(random());
    writer.write(m.channel, m.log_ns, m.publish_ns, m.data.data(), m.data.size());
    written.push_back(std::move(m));
  }
  writer.close();
  return written;
}

void expectMessages(const McapReader& reader, const std::vector<Written>& written) {
  ASSERT_EQ(reader.messages().size(), written.size());
  std::map<std::uint16_t, std::uint32_t> sequences;
  for (std::size_t i = 0; i < written.size(); ++i) {
    const McapMessageRef& m = reader.messages()[i];
    EXPECT_EQ(m.channel_id, written[i].channel) << i;
    EXPECT_EQ(m.log_time_ns, written[i].log_ns) << i;
    EXPECT_EQ(m.publish_time_ns, written[i].publish_ns) << i;
    EXPECT_EQ(m.sequence, sequences[m.channel_id]++) << i;
    EXPECT_EQ(reader.read(m), written[i].data) << i;
    const std::uint32_t head = reader.headSize(i);
    ASSERT_EQ(head, std::min<std::size_t>(16, written[i].data.size()));
    EXPECT_TRUE(std::equal(written[i].data.begin(), written[i].data.begin() + head,
                           reader.head(i).begin()));
  }
}

class McapRoundTrip : public testing::TestWithParam<McapCompression> {};

TEST_P(McapRoundTrip, ReadsBackEveryMessageInOrder) {
  const TempDir dir;
  const fs::path file = dir.path() / "bag.mcap";
  const std::vector<Written> written = writeBag(file, GetParam());
  const McapReader reader(file);
  EXPECT_TRUE(reader.warnings().empty()) << reader.warnings().front();
  EXPECT_EQ(reader.profile(), "ros2");
  EXPECT_EQ(reader.library(), "gvio");
  ASSERT_EQ(reader.schemas().size(), 3u);
  ASSERT_EQ(reader.channels().size(), 4u);
  ASSERT_NE(reader.schema(2), nullptr);
  EXPECT_EQ(reader.schema(2)->name, "sensor_msgs/msg/Image");
  EXPECT_EQ(reader.schema(2)->data, "# image");
  EXPECT_EQ(reader.schema(9), nullptr);
  ASSERT_NE(reader.channel(1), nullptr);
  EXPECT_EQ(reader.channel(1)->topic, "/imu");
  EXPECT_EQ(reader.channel(1)->metadata.at("offered_qos_profiles"), "- depth: 10");
  EXPECT_EQ(reader.channel(3)->schema_id, 0);
  EXPECT_EQ(reader.channel(3)->message_encoding, "x-raw");
  EXPECT_GT(reader.chunks().size(), 10u);
  const std::string names[] = {"", "lz4", "zstd"};
  EXPECT_EQ(reader.chunks().front().compression, names[static_cast<int>(GetParam())]);
  expectMessages(reader, written);
  // Out of order too (each read may load another chunk).
  for (std::size_t i = written.size(); i-- > 0;) {
    ASSERT_EQ(reader.read(reader.messages()[i]), written[i].data) << i;
  }
}

TEST_P(McapRoundTrip, ReadsFromSeveralThreads) {
  const TempDir dir;
  const fs::path file = dir.path() / "bag.mcap";
  const std::vector<Written> written = writeBag(file, GetParam());
  const McapReader reader(file);
  std::atomic<int> wrong{0};
  std::vector<std::thread> threads;
  for (std::size_t t = 0; t < 4; ++t) {
    threads.emplace_back([&, t] {
      for (std::size_t i = t; i < written.size(); i += 3) {
        if (reader.read(reader.messages()[i]) != written[i].data) ++wrong;
      }
    });
  }
  for (auto& thread : threads) thread.join();
  EXPECT_EQ(wrong, 0);
}

INSTANTIATE_TEST_SUITE_P(Mcap, McapRoundTrip,
                         testing::Values(McapCompression::kNone, McapCompression::kLz4,
                                         McapCompression::kZstd));

// The index records, read here by hand (spec "Chunk Index", "Message Index", "Statistics",
// "Summary Offset", "Footer"), not through McapReader.
TEST(McapWriterLayout, IndexRecordsPointWhereTheSpecSays) {
  const TempDir dir;
  const fs::path file = dir.path() / "bag.mcap";
  const std::vector<Written> written = writeBag(file, McapCompression::kNone);
  const Bytes b = readBytes(file);
  ASSERT_TRUE(std::equal(kMagic.begin(), kMagic.end(), b.end() - 8));
  const std::size_t footer = b.size() - 8 - 29;
  ASSERT_EQ(b[footer], 0x02);
  const std::size_t summary_start = le(b, footer + 9, 8), offsets_start = le(b, footer + 17, 8);
  EXPECT_EQ(le(b, footer + 25, 4), crc(b, summary_start, footer + 25));
  ASSERT_EQ(b[summary_start - 13], 0x0F);  // DataEnd right before the summary

  // Summary Offset records: one per group, each group one opcode, filling the summary exactly.
  std::map<std::uint8_t, std::vector<std::size_t>> groups;  // opcode -> record offsets
  std::size_t covered = summary_start;
  for (std::size_t at = offsets_start; at < footer; at += 9 + 17) {
    ASSERT_EQ(b[at], 0x0E);
    const auto opcode = static_cast<std::uint8_t>(b[at + 9]);
    const std::size_t start = le(b, at + 10, 8), length = le(b, at + 18, 8);
    EXPECT_EQ(start, covered);
    for (std::size_t r = start; r < start + length; r += 9 + le(b, r + 1, 8)) {
      EXPECT_EQ(b[r], opcode);
      groups[opcode].push_back(r);
    }
    covered = start + length;
  }
  EXPECT_EQ(covered, offsets_start);
  EXPECT_EQ(groups[0x03].size(), 3u);
  EXPECT_EQ(groups[0x04].size(), 4u);
  ASSERT_EQ(groups[0x0B].size(), 1u);
  const std::size_t stats = groups[0x0B][0] + 9;
  EXPECT_EQ(le(b, stats, 8), written.size());
  EXPECT_EQ(le(b, stats + 8, 2), 3u);
  EXPECT_EQ(le(b, stats + 10, 4), 4u);
  EXPECT_EQ(le(b, stats + 22, 4), groups[0x08].size());
  EXPECT_EQ(le(b, stats + 26, 8), written.front().log_ns);
  EXPECT_EQ(le(b, stats + 34, 8), written.back().log_ns);
  EXPECT_EQ(le(b, stats + 42, 4), 3u * 10);  // channels 1-3 have messages

  std::size_t messages = 0;
  for (const std::size_t index : groups[0x08]) {
    const std::size_t c = index + 9;
    const std::size_t chunk = le(b, c + 16, 8), chunk_length = le(b, c + 24, 8);
    ASSERT_EQ(b[chunk], 0x06);
    EXPECT_EQ(9 + le(b, chunk + 1, 8), chunk_length);
    const std::size_t records = chunk + 9 + 8 + 8 + 8 + 4 + 4 + 8;  // compression ""
    const std::size_t map_bytes = le(b, c + 32, 4);
    EXPECT_EQ(le(b, records - 8, 8), le(b, c + 48 + map_bytes, 8));  // compressed_size
    EXPECT_EQ(le(b, chunk + 25, 8), le(b, c + 56 + map_bytes, 8));   // uncompressed_size
    EXPECT_EQ(le(b, chunk + 33, 4), crc(b, records, chunk + chunk_length));
    std::size_t index_bytes = 0;
    for (std::size_t e = c + 36; e < c + 36 + map_bytes; e += 10) {
      const std::size_t mi = le(b, e + 2, 8);
      ASSERT_EQ(b[mi], 0x07);
      EXPECT_EQ(le(b, mi + 9, 2), le(b, e, 2));
      index_bytes += 9 + le(b, mi + 1, 8);
      for (std::size_t t = mi + 15; t < mi + 15 + le(b, mi + 11, 4); t += 16, ++messages) {
        const std::size_t message = records + le(b, t + 8, 8);
        ASSERT_EQ(b[message], 0x05);
        EXPECT_EQ(le(b, message + 9, 2), le(b, e, 2));   // its channel
        EXPECT_EQ(le(b, message + 15, 8), le(b, t, 8));  // its log_time
        EXPECT_GE(le(b, message + 15, 8), le(b, c, 8));
        EXPECT_LE(le(b, message + 15, 8), le(b, c + 8, 8));
      }
    }
    EXPECT_EQ(le(b, c + 36 + map_bytes, 8), index_bytes);
    EXPECT_EQ(b[chunk + chunk_length], 0x07);  // the indexes follow their chunk
  }
  EXPECT_EQ(messages, written.size());
}

TEST(McapWriter, RefusesUnknownIdsAndWritesAfterClose) {
  const TempDir dir;
  McapWriter writer(dir.path() / "w.mcap", McapCompression::kZstd);
  EXPECT_THROW(writer.addChannel("/a", 1, "cdr"), Ros2Error);
  const std::uint16_t channel = writer.addChannel("/a", 0, "cdr");
  const std::uint8_t byte = 1;
  EXPECT_THROW(writer.write(static_cast<std::uint16_t>(channel + 1), 0, 0, &byte, 1), Ros2Error);
  writer.write(channel, 5, 5, &byte, 1);
  writer.close();
  EXPECT_THROW(writer.write(channel, 6, 6, &byte, 1), Ros2Error);
  const McapReader reader(dir.path() / "w.mcap");
  EXPECT_EQ(reader.messages().size(), 1u);
  EXPECT_THROW(McapWriter(dir.path() / "missing" / "w.mcap", McapCompression::kNone), Ros2Error);
}

TEST(McapWriter, AnUnclosedFileKeepsItsCompleteChunks) {
  const TempDir dir;
  const fs::path file = dir.path() / "open.mcap";
  {
    McapWriter writer(file, McapCompression::kLz4, "ros2", 100);
    const std::uint16_t channel = writer.addChannel("/a", 0, "cdr");
    const Bytes data(150, 3);
    for (std::uint64_t t = 0; t < 5; ++t) writer.write(channel, t, t, data.data(), data.size());
  }
  const McapReader reader(file);
  EXPECT_EQ(reader.messages().size(), 5u);
  EXPECT_TRUE(hasWarning(reader, "cut short")) << reader.warnings().at(0);
}

// Truncations at `cut` keep the messages of the chunks complete before it.
TEST(McapCutShort, KeepsTheCompleteChunksBeforeTheCut) {
  for (const McapCompression compression : {McapCompression::kNone, McapCompression::kZstd}) {
    const TempDir dir;
    const fs::path file = dir.path() / "bag.mcap";
    const std::vector<Written> written = writeBag(file, compression);
    const Bytes full = readBytes(file);
    const McapReader whole(file);
    const std::vector<McapChunkInfo> chunks = whole.chunks();
    const auto count = [&](std::size_t chunk) {  // messages in chunks before `chunk`
      return static_cast<std::size_t>(
          std::count_if(whole.messages().begin(), whole.messages().end(),
                        [&](const McapMessageRef& m) { return m.chunk < chunk; }));
    };
    const std::size_t summary_start = le(full, full.size() - 8 - 20, 8);
    const std::pair<std::size_t, std::size_t> cuts[] = {
        {chunks[2].record_offset + 30, count(2)},  // mid-chunk
        {chunks[2].record_offset, count(2)},       // after a chunk's message indexes
        {chunks[0].records_offset + chunks[0].compressed_size + 5, count(1)},  // in an index
        {summary_start - 5, written.size()},                                   // in DataEnd
        {summary_start + 40, written.size()},                                  // in the summary
        {full.size() - 3, written.size()}};  // in the closing magic
    for (const auto& [cut, kept] : cuts) {
      writeBytes(file, Bytes(full.begin(), full.begin() + static_cast<std::ptrdiff_t>(cut)));
      const McapReader reader(file);
      ASSERT_TRUE(hasWarning(reader, "cut short")) << cut;
      EXPECT_EQ(reader.warnings().size(), 1u) << reader.warnings().back();
      ASSERT_EQ(reader.messages().size(), kept) << cut;
      for (std::size_t i = 0; i < kept; ++i)
        EXPECT_EQ(reader.read(reader.messages()[i]), written[i].data);
    }
    EXPECT_TRUE(hasWarning(McapReader(file), "all 120 messages are there"));
    writeBytes(file, Bytes(full.begin(), full.begin() + static_cast<std::ptrdiff_t>(
                                                            chunks[2].record_offset + 30)));
    EXPECT_TRUE(hasWarning(McapReader(file), "that chunk is dropped"));
    for (const std::size_t cut :
         std::vector<std::size_t>{0, 5, 8, 12, 20}) {  // in the magic or the Header
      writeBytes(file, Bytes(full.begin(), full.begin() + static_cast<std::ptrdiff_t>(cut)));
      EXPECT_THROW(McapReader{file}, Ros2Error) << cut;
    }
  }
}

TEST(McapSummary, ScanningTheDataSectionFindsTheSameMessages) {
  const TempDir dir;
  const fs::path file = dir.path() / "bag.mcap";
  writeBag(file, McapCompression::kLz4);
  const Bytes full = readBytes(file);
  const McapReader indexed(file);
  const std::size_t summary_start = le(full, full.size() - 8 - 20, 8);
  writeBytes(file,
             Bytes(full.begin(), full.begin() + static_cast<std::ptrdiff_t>(summary_start - 13)));
  const McapReader scanned(file);
  EXPECT_TRUE(hasWarning(scanned, "cut short"));
  ASSERT_EQ(scanned.messages().size(), indexed.messages().size());
  for (std::size_t i = 0; i < indexed.messages().size(); ++i) {
    const McapMessageRef &a = indexed.messages()[i], &b = scanned.messages()[i];
    EXPECT_EQ(a.channel_id, b.channel_id);
    EXPECT_EQ(a.sequence, b.sequence);
    EXPECT_EQ(a.log_time_ns, b.log_time_ns);
    EXPECT_EQ(a.chunk, b.chunk);
    EXPECT_EQ(a.offset, b.offset);
    EXPECT_EQ(a.size, b.size);
    EXPECT_EQ(indexed.read(a), scanned.read(b));
  }
  // Schemas and channels from the chunks (and the unused ones written before DataEnd).
  EXPECT_EQ(scanned.schemas().size(), 3u);
  EXPECT_EQ(scanned.channels().size(), 4u);
}

// A Statistics count that the chunk index does not match, or a summary failing its CRC, makes the
// reader scan the data section instead.
TEST(McapSummary, FallsBackToAScanWhenTheSummaryDisagrees) {
  const TempDir dir;
  const fs::path file = dir.path() / "bag.mcap";
  writeBag(file, McapCompression::kZstd);
  Bytes b = readBytes(file);
  const std::size_t footer = b.size() - 8 - 29, summary_start = le(b, footer + 9, 8);
  std::size_t stats = summary_start;
  while (b[stats] != 0x0B) stats += 9 + le(b, stats + 1, 8);
  b[stats + 9] ^= 1;  // message_count 121
  writeBytes(file, b);
  const McapReader bad_crc(file);
  EXPECT_TRUE(hasWarning(bad_crc, "summary: CRC mismatch"));
  EXPECT_EQ(bad_crc.messages().size(), 120u);
  std::fill_n(b.begin() + static_cast<std::ptrdiff_t>(footer + 25), 4, 0);  // no summary CRC
  writeBytes(file, b);
  const McapReader miscounted(file);
  EXPECT_TRUE(hasWarning(miscounted, "Statistics message_count 121"));
  EXPECT_TRUE(hasWarning(miscounted, "the Statistics record counts 121 messages, 120 were found"));
  EXPECT_EQ(miscounted.messages().size(), 120u);
}

TEST(McapCrc, ADamagedChunkIsReported) {
  for (const McapCompression compression :
       {McapCompression::kNone, McapCompression::kLz4, McapCompression::kZstd}) {
    const TempDir dir;
    const fs::path file = dir.path() / "bag.mcap";
    writeBag(file, compression);
    Bytes b = readBytes(file);
    const McapReader reader(file);
    const McapChunkInfo& chunk = reader.chunks()[3];
    std::size_t at = chunk.records_offset + chunk.compressed_size / 2;
    if (compression == McapCompression::kNone) {  // inside a message's data
      const auto m =
          std::find_if(reader.messages().begin(), reader.messages().end(),
                       [](const McapMessageRef& r) { return r.chunk == 3 && r.size > 4; });
      at = chunk.records_offset + m->offset + 2;
    }
    b[at] ^= 0x40;
    writeBytes(file, b);
    const std::string error = errorOf([&] { McapReader{file}; });
    EXPECT_NE(error.find("chunk at byte " + commas(chunk.record_offset)), std::string::npos)
        << error;
    if (compression == McapCompression::kNone) {
      EXPECT_NE(error.find("CRC mismatch (stored 0x"), std::string::npos) << error;
    }
  }
}

TEST(McapNotMcap, ATextFileIsRefused) {
  const TempDir dir;
  const fs::path file = dir.path() / "notes.txt";
  std::ofstream(file) << "these are not the bytes you are looking for\n";
  EXPECT_NE(errorOf([&] { McapReader{file}; }).find("not an MCAP file"), std::string::npos);
  std::ofstream(file, std::ios::trunc).flush();
  EXPECT_NE(errorOf([&] { McapReader{file}; }).find("not an MCAP file"), std::string::npos);
  EXPECT_THROW(McapReader{dir.path() / "missing.mcap"}, Ros2Error);
  EXPECT_THROW(McapReader{dir.path()}, Ros2Error);
}

TEST(McapUnchunked, ReadsMessagesInTheDataSection) {
  const TempDir dir;
  const fs::path file = dir.path() / "plain.mcap";
  Bytes b = magicAndHeader();
  append(b, schemaRecord(1, "std_msgs/msg/String", "string data"));
  append(b, channelRecord(1, 1, "/chatter"));
  const Bytes hello{'h', 'e', 'l', 'l', 'o', ',', ' ', 'u', 'n',
                    'c', 'h', 'u', 'n', 'k', 'e', 'd', '!'};
  const std::size_t first = b.size() + 9 + 22;
  append(b, messageRecord(1, 7, 100, hello));
  append(b, record(0x80, {1, 2, 3}));  // an application's record: skipped
  append(b, messageRecord(1, 8, 200, {}));
  append(b, channelRecord(1, 1, "/chatter"));  // repeated identically: fine
  append(b, closing());
  writeBytes(file, b);
  const McapReader reader(file);
  EXPECT_EQ(reader.profile(), "ros2");
  ASSERT_EQ(reader.messages().size(), 2u);
  const McapMessageRef& m = reader.messages()[0];
  EXPECT_EQ(m.chunk, McapMessageRef::kNoChunk);
  EXPECT_EQ(m.offset, first);
  EXPECT_EQ(m.sequence, 7u);
  EXPECT_EQ(m.log_time_ns, 100u);
  EXPECT_EQ(m.publish_time_ns, 101u);
  EXPECT_EQ(reader.read(m), hello);
  EXPECT_EQ(reader.headSize(0), 16u);
  EXPECT_TRUE(std::equal(hello.begin(), hello.begin() + 16, reader.head(0).begin()));
  EXPECT_EQ(reader.headSize(1), 0u);
  EXPECT_TRUE(reader.read(reader.messages()[1]).empty());
  EXPECT_EQ(reader.channel(1)->metadata.at("offered_qos_profiles"), "- history: 3");
  EXPECT_EQ(reader.schema(1)->data, "string data");
  ASSERT_EQ(reader.warnings().size(), 1u);
  EXPECT_EQ(reader.warnings()[0], "skipped 1 record(s) of unknown opcodes (0x80)");
  EXPECT_THROW(reader.head(2), Ros2Error);
}

TEST(McapDefects, ConflictingDefinitionsAndUnknownCompression) {
  const TempDir dir;
  const fs::path file = dir.path() / "d.mcap";
  Bytes b = magicAndHeader();
  append(b, channelRecord(1, 0, "/a"));
  append(b, channelRecord(1, 0, "/b"));
  append(b, closing());
  writeBytes(file, b);
  EXPECT_NE(errorOf([&] { McapReader{file}; }).find("channel 1 redefined"), std::string::npos);

  b = magicAndHeader();
  const Bytes records = messageRecord(1, 0, 5, {1, 2, 3});
  append(b, chunkRecord("brotli", records, records.size(), 0));
  append(b, chunkRecord("", records, records.size(), 0));
  append(b, closing());
  writeBytes(file, b);
  const McapReader reader(file);
  EXPECT_EQ(reader.messages().size(), 1u);
  EXPECT_TRUE(hasWarning(reader, "skipped 1 chunk(s) of unknown compression 'brotli'"));
  EXPECT_TRUE(hasWarning(reader, "1 message(s) on channels without a Channel record"));
}

TEST(McapHostile, HugeLengthsAreRefusedWithoutHugeAllocations) {
  const TempDir dir;
  const fs::path file = dir.path() / "h.mcap";
  const auto readWith = [&](const Bytes& records) {
    Bytes b = magicAndHeader();
    append(b, records);
    append(b, closing());
    writeBytes(file, b);
    return McapReader(file);
  };
  // A record length of 2^63: the file is cut short there.
  Bytes huge{0x05};
  put(huge, std::uint64_t{1} << 63, 8);
  EXPECT_TRUE(hasWarning(readWith(huge), "cut short"));
  // A string length of 0xFFFFFFFF, in a Channel and in the Header.
  Bytes channel;
  put(channel, 1, 2);
  put(channel, 0, 2);
  put(channel, 0xFFFFFFFF, 4);
  channel.resize(40, 'x');
  EXPECT_NE(errorOf([&] { readWith(record(0x04, channel)); }).find("topic needs 4,294,967,295"),
            std::string::npos);
  Bytes header = kMagic;
  Bytes profile;
  put(profile, 0xFFFFFFFF, 4);
  append(header, record(0x01, profile));
  writeBytes(file, header);
  EXPECT_THROW(McapReader{file}, Ros2Error);
  // A chunk claiming 2^40 bytes, one claiming more than its compression allows, one whose records
  // length exceeds the record.
  const Bytes junk(64, 0x11);
  EXPECT_NE(errorOf([&] {
              readWith(chunkRecord("zstd", junk, std::uint64_t{1} << 40, 0));
            }).find("uncompressed_size 1,099,511,627,776 exceeds"),
            std::string::npos);
  EXPECT_NE(errorOf([&] { readWith(chunkRecord("lz4", junk, 1 << 20, 0)); }).find("impossible"),
            std::string::npos);
  EXPECT_THROW(readWith(chunkRecord("", junk, 65, 0)), Ros2Error);
  EXPECT_THROW(readWith(chunkRecord("zstd", junk, 64, 0)), Ros2Error);  // not zstd data
  Bytes chunk = chunkRecord("", junk, 64, 0);
  std::fill_n(chunk.end() - 64 - 8, 8, 0xFF);  // records length 2^64-1
  EXPECT_THROW(readWith(chunk), Ros2Error);
  // Inside a chunk: a record running past the records, a Message shorter than its fixed fields.
  Bytes inner{0x05};
  put(inner, std::uint64_t{1} << 63, 8);
  EXPECT_THROW(readWith(chunkRecord("", inner, inner.size(), 0)), Ros2Error);
  const Bytes short_message = record(0x05, Bytes(21, 0));
  EXPECT_THROW(readWith(chunkRecord("", short_message, short_message.size(), 0)), Ros2Error);
  // A Footer whose summary_start points past the file: the data section is scanned.
  Bytes b = magicAndHeader();
  append(b, record(0x0F, Bytes(4, 0)));
  Bytes footer;
  put(footer, std::uint64_t{1} << 62, 8);
  put(footer, 0, 8);
  put(footer, 0, 4);
  append(b, record(0x02, footer));
  append(b, kMagic);
  writeBytes(file, b);
  EXPECT_TRUE(hasWarning(McapReader(file), "summary_start"));
}

// Every truncation and many single-byte changes of a small file: a Ros2Error or a reader whose
// messages can all be read (or throw Ros2Error) - never another exception or a crash (the
// sanitizer builds run this too).
TEST(McapHostile, EveryTruncationAndByteFlipIsHandled) {
  const TempDir dir;
  const fs::path file = dir.path() / "bag.mcap";
  for (const McapCompression compression : {McapCompression::kNone, McapCompression::kLz4}) {
    {
      McapWriter writer(file, compression, "ros2", 200);
      const std::uint16_t schema = writer.addSchema("s", "ros2msg", "def");
      const std::uint16_t channel = writer.addChannel("/t", schema, "cdr", {{"k", "v"}});
      const Bytes data(70, 9);
      for (std::uint64_t t = 0; t < 8; ++t) writer.write(channel, t, t, data.data(), data.size());
      writer.close();
    }
    const Bytes full = readBytes(file);
    // Each variant in a new file: rewriting one in place makes ext4 flush it (auto_da_alloc).
    std::size_t variant = 0;
    const auto tryRead = [&](const Bytes& bytes) {
      const fs::path damaged = dir.path() / ("variant" + std::to_string(variant++) + ".mcap");
      writeBytes(damaged, bytes);
      try {
        const McapReader reader(damaged);
        for (const McapMessageRef& m : reader.messages()) {
          try {
            reader.read(m);
          } catch (const Ros2Error&) {
          }
        }
      } catch (const Ros2Error&) {
      }
      fs::remove(damaged);
    };
    for (std::size_t cut = 0; cut <= full.size(); ++cut) {
      tryRead(Bytes(full.begin(), full.begin() + static_cast<std::ptrdiff_t>(cut)));
    }
    for (std::size_t at = 0; at < full.size(); ++at) {
      for (const std::uint8_t flip : std::vector<std::uint8_t>{0x01, 0x80, 0xFF}) {
        Bytes damaged = full;
        damaged[at] ^= flip;
        tryRead(damaged);
      }
    }
  }
}

}  // namespace
}  // namespace gvio::io::ros2
