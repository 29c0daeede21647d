// The record check inside compressed chunks (issue 17): librosbag decompresses an lz4 or bz2
// chunk and parses its records with the same trusting parser as an uncompressed chunk's, so the
// check decompresses them and walks them the same way. The bags here are written uncompressed,
// damaged where needed, and their chunks then compressed by a small rewriter (as rosbag would
// have written them), so that the damage sits inside a valid lz4 or bz2 stream.
#include <bzlib.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <roslz4/lz4s.h>
#include <sys/resource.h>

#include <cstdint>
#include <filesystem>
#include <map>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "io/dataset.hpp"
#include "io/ros_image.hpp"
#include "io/rosbag/bag_file.hpp"
#include "support/errors.hpp"
#include "support/fixtures.hpp"

namespace gvio::io {
namespace {
namespace fs = std::filesystem;

constexpr std::int64_t kT0 = 1'600'000'000'000'000'000;
constexpr std::size_t kVersionLine = 13;  // "#ROSBAG V2.0\n"

std::uint32_t u32At(const std::string& b, std::size_t at) {
  return std::uint32_t{static_cast<unsigned char>(b[at])} |
         std::uint32_t{static_cast<unsigned char>(b[at + 1])} << 8 |
         std::uint32_t{static_cast<unsigned char>(b[at + 2])} << 16 |
         std::uint32_t{static_cast<unsigned char>(b[at + 3])} << 24;
}

std::string le(std::uint64_t v, std::size_t bytes) {
  std::string out;
  for (std::size_t i = 0; i < bytes; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
  return out;
}

// A record: its header's fields in order (name, value) and its data.
struct Record {
  std::vector<std::pair<std::string, std::string>> fields;
  std::string data;

  std::string field(const std::string& name) const {
    for (const auto& [n, v] : fields) {
      if (n == name) return v;
    }
    return {};
  }
  void set(const std::string& name, const std::string& value) {
    for (auto& [n, v] : fields) {
      if (n == name) v = value;
    }
  }
  std::string bytes() const {
    std::string header;
    for (const auto& [n, v] : fields) header += le(n.size() + 1 + v.size(), 4) + n + "=" + v;
    return le(header.size(), 4) + header + le(data.size(), 4) + data;
  }
};

std::vector<Record> parseRecords(const std::string& b, std::size_t pos) {
  std::vector<Record> records;
  while (pos < b.size()) {
    Record r;
    const std::size_t header_end = pos + 4 + u32At(b, pos);
    for (std::size_t p = pos + 4; p < header_end;) {
      const std::string f = b.substr(p + 4, u32At(b, p));
      r.fields.emplace_back(f.substr(0, f.find('=')), f.substr(f.find('=') + 1));
      p += 4 + f.size();
    }
    r.data = b.substr(header_end + 4, u32At(b, header_end));
    pos = header_end + 4 + r.data.size();
    records.push_back(std::move(r));
  }
  return records;
}

std::string compress(std::string data, const std::string& kind) {
  std::string out(data.size() * 2 + 1024, '\0');
  unsigned int out_len = static_cast<unsigned int>(out.size());
  const int rc =
      kind == "lz4"
          ? roslz4_buffToBuffCompress(data.data(), data.size(), out.data(), &out_len, 6)
          : BZ2_bzBuffToBuffCompress(out.data(), &out_len, data.data(), data.size(), 9, 0, 30);
  EXPECT_EQ(rc, 0) << kind;
  out.resize(out_len);
  return out;
}

// The bag with every uncompressed chunk compressed as `kind`, and the file header's index_pos and
// every chunk info's chunk_pos moved with the records. `edit` may change a chunk's records
// (already decompressed) or its header before it is compressed.
std::string withCompressedChunks(const std::string& bag, const std::string& kind,
                                 const std::function<void(Record&)>& edit = {}) {
  std::vector<Record> records = parseRecords(bag, kVersionLine);
  std::map<std::uint64_t, std::uint64_t> moved;  // old offset -> new offset
  std::uint64_t old_at = kVersionLine, new_at = kVersionLine;
  for (Record& r : records) {
    const std::uint64_t old_size = r.bytes().size();
    if (r.field("op") == "\x05" && r.field("compression") == "none") {
      r.data = compress(r.data, kind);
      r.set("compression", kind);
      if (edit) edit(r);
    }
    moved[old_at] = new_at;
    old_at += old_size;
    new_at += r.bytes().size();
  }
  moved[old_at] = new_at;
  auto movedPos = [&](const std::string& v) {
    std::uint64_t p = 0;
    for (std::size_t i = 0; i < 8; ++i)
      p |= std::uint64_t{static_cast<unsigned char>(v[i])} << 8 * i;
    return le(moved.at(p), 8);
  };
  std::string out = bag.substr(0, kVersionLine);
  for (Record& r : records) {
    if (r.field("op") == "\x03") r.set("index_pos", movedPos(r.field("index_pos")));
    if (r.field("op") == "\x06") r.set("chunk_pos", movedPos(r.field("chunk_pos")));
    out += r.bytes();
  }
  return out;
}

// A stereo bag of 3 frames, 30 IMU samples and a fix, uncompressed, with its Kalibr files.
std::string driveBag(const fs::path& file) {
  bag::BagWriter w(file.string(), bag::Compression::kNone);
  for (int k = 0; k < 3; ++k) {
    for (int c = 0; c < 2; ++c) {
      bag::ImageMessage m = grayToRosImage(cv::Mat(24, 32, CV_8UC1, cv::Scalar(40 * c + k)), false);
      m.t = {kT0 + k * 100'000'000LL, kT0 + k * 100'000'000LL};
      w.write(c == 0 ? "/cam0/image_raw" : "/cam1/image_raw", m);
    }
  }
  for (int i = 0; i < 30; ++i) {
    bag::ImuMessage m;
    m.t = {kT0 + i * 10'000'000LL, kT0 + i * 10'000'000LL};
    m.acc_mps2 = {0.0, 0.0, 9.81};
    w.write("/imu0", m);
  }
  w.close();
  return test::readText(file);
}

std::string readError(const fs::path& file) {
  return test::inputError([&] { (void)readDataset(file, std::nullopt, {}); });
}

TEST(RosbagChunks, RewrittenCompressedBagsReadAsTheOriginal) {
  test::TempDir dir("rosbag_chunks");
  const fs::path plain = dir.path() / "plain.bag";
  const std::string bytes = driveBag(plain);
  const Dataset original = readDataset(plain, std::nullopt, {});
  for (const std::string kind : {"lz4", "bz2"}) {
    const fs::path file = dir.path() / (kind + ".bag");
    test::writeText(file, withCompressedChunks(bytes, kind));
    const Dataset ds = readDataset(file, std::nullopt, {});
    EXPECT_EQ(ds.frames.size(), original.frames.size()) << kind;
    EXPECT_EQ(ds.imu.size(), original.imu.size()) << kind;
  }
}

// A connection header (the data of the connection record inside the chunk) whose first field
// states more bytes than the header holds: librosbag's ros::Header::parse reads past its buffer.
TEST(RosbagChunks, DamagedRecordsInsideCompressedChunksAreRefusedNamingTheChunk) {
  test::TempDir dir("rosbag_chunks");
  const fs::path plain = dir.path() / "plain.bag";
  std::string bytes = driveBag(plain);
  const std::size_t topic = bytes.find("topic=/cam0/image_raw");
  ASSERT_NE(topic, std::string::npos);
  bytes.replace(topic - 4, 4, le(0x7fff, 4));  // the chunk's first connection record comes first
  test::writeText(plain, bytes);
  EXPECT_TRUE(test::names(readError(plain), plain, 0, "header field longer than its header"));
  for (const std::string kind : {"lz4", "bz2"}) {
    const fs::path file = dir.path() / (kind + ".bag");
    test::writeText(file, withCompressedChunks(bytes, kind));
    const std::string error = readError(file);
    EXPECT_TRUE(test::names(error, file, 0, kind + "-decompressed: record at byte")) << error;
    EXPECT_THAT(error, testing::HasSubstr("header field longer than its header"));
  }
}

TEST(RosbagChunks, CompressedChunksOfAnotherSizeThanDeclaredAreRefused) {
  test::TempDir dir("rosbag_chunks");
  const std::string bytes = driveBag(dir.path() / "plain.bag");
  for (const std::string kind : {"lz4", "bz2"}) {
    const fs::path shorter = dir.path() / (kind + "_size.bag");
    test::writeText(shorter, withCompressedChunks(bytes, kind, [](Record& chunk) {
                      chunk.set("size", le(u32At(chunk.field("size"), 0) + 1, 4));
                    }));
    EXPECT_TRUE(test::names(readError(shorter), shorter, 0,
                            "decompresses to another size than it declares"));
    const fs::path garbage = dir.path() / (kind + "_garbage.bag");
    test::writeText(garbage, withCompressedChunks(bytes, kind, [](Record& chunk) {
                      chunk.data[chunk.data.size() / 2] ^= 0x5a;
                    }));
    EXPECT_TRUE(test::names(readError(garbage), garbage, 0, "does not decompress"));
  }
  // A bz2 chunk declaring 512 MiB around 9 KiB of data: refused after decompressing what the
  // stream holds, without allocating the declared size (this process stays far below it).
  const fs::path declared = dir.path() / "bz2_declared.bag";
  test::writeText(declared, withCompressedChunks(bytes, "bz2", [](Record& chunk) {
                    chunk.set("size", le(std::uint64_t{1} << 29, 4));
                  }));
  EXPECT_TRUE(test::names(readError(declared), declared, 0,
                          "decompresses to another size than it declares"));
  rusage usage{};
  ASSERT_EQ(getrusage(RUSAGE_SELF, &usage), 0);
  EXPECT_LT(usage.ru_maxrss, 400 * 1024) << "peak RSS in KiB";
  // More than lz4 can expand to: refused before anything allocates the declared size.
  const fs::path huge = dir.path() / "lz4_huge.bag";
  test::writeText(huge, withCompressedChunks(bytes, "lz4", [](Record& chunk) {
                    chunk.set("size", le(std::uint64_t{1} << 29, 4));
                  }));
  EXPECT_TRUE(test::names(readError(huge), huge, 0, "more data than lz4 can expand to"));
}

}  // namespace
}  // namespace gvio::io
