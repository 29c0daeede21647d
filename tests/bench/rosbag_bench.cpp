// Reading a camera image out of a ROS bag: one 1241x376 mono8 sensor_msgs/Image (KITTI's size),
// message read, chunk decompressed (none, lz4, bz2) and turned into the tracker's cv::Mat, in
// the order a run reads frames. Target (issue 16): <= 2 ms per image.
#include <benchmark/benchmark.h>
#include <bzlib.h>

#include <filesystem>
#include <random>
#include <vector>

#include "io/dataset.hpp"
#include "io/ros_image.hpp"
#include "io/rosbag/bag_file.hpp"
#include "support/camera_like.hpp"
#include "support/fixtures.hpp"

namespace gvio::io {
namespace {

constexpr int kImages = 40;

// kImages camera-like images on /cam0/image_raw at 10 Hz in a bag of the given compression.
void writeImageBag(const std::filesystem::path& file, bag::Compression compression) {
  std::mt19937 rng(1);
  bag::BagWriter writer(file.string(), compression);
  for (int k = 0; k < kImages; ++k) {
    bag::ImageMessage m = grayToRosImage(test::cameraLike(k, rng), false);
    const std::int64_t t_ns = 1'000'000'000 + k * 100'000'000LL;
    m.t = {t_ns, t_ns};
    writer.write("/cam0/image_raw", m);
  }
  writer.close();
}

void BM_BagImageRead(benchmark::State& state) {
  const auto compression = static_cast<bag::Compression>(state.range(0));
  test::TempDir dir("rosbag_bench");
  const auto file = dir.path() / "images.bag";
  writeImageBag(file, compression);
  Dataset ds = readDataset(file, DatasetFormat::kRosbag, ReaderConfig{});
  ds.cameras[0].fx = ds.cameras[0].fy = 700.0;  // the size check needs no more
  std::size_t frame = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(loadFrameImage(ds, frame, 0).data);
    frame = (frame + 1) % ds.frames.size();
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_BagImageRead)
    ->Arg(static_cast<int>(bag::Compression::kNone))
    ->Arg(static_cast<int>(bag::Compression::kLz4))
    ->Arg(static_cast<int>(bag::Compression::kBz2))
    ->Unit(benchmark::kMillisecond);

// Opening the bag (the record check, which decompresses every compressed chunk once to walk its
// records, then librosbag's index and the stamps of every image), per image in the bag.
void BM_BagOpen(benchmark::State& state) {
  const auto compression = static_cast<bag::Compression>(state.range(0));
  test::TempDir dir("rosbag_bench");
  const auto file = dir.path() / "images.bag";
  writeImageBag(file, compression);
  for (auto _ : state) {
    benchmark::DoNotOptimize(readDataset(file, DatasetFormat::kRosbag, ReaderConfig{}).frames);
  }
  state.SetItemsProcessed(state.iterations() * kImages);
}
BENCHMARK(BM_BagOpen)
    ->Arg(static_cast<int>(bag::Compression::kNone))
    ->Arg(static_cast<int>(bag::Compression::kLz4))
    ->Arg(static_cast<int>(bag::Compression::kBz2))
    ->Unit(benchmark::kMillisecond);

// libbz2 alone: one camera-like 1241x376 mono8 image compressed at level 9 (rosbag's bz2), then
// decompressed: the floor any bz2 bag reader has per image, whatever it does around it.
void BM_Bz2DecompressOneImage(benchmark::State& state) {
  std::mt19937 rng(1);
  const cv::Mat image = test::cameraLike(0, rng);
  std::vector<char> raw(image.datastart, image.dataend);
  std::vector<char> packed(raw.size() + raw.size() / 100 + 600);
  auto packed_size = static_cast<unsigned>(packed.size());
  if (BZ2_bzBuffToBuffCompress(packed.data(), &packed_size, raw.data(),
                               static_cast<unsigned>(raw.size()), 9, 0, 0) != BZ_OK) {
    state.SkipWithError("bz2 compression failed");
    return;
  }
  std::vector<char> out(raw.size());
  for (auto _ : state) {
    auto out_size = static_cast<unsigned>(out.size());
    BZ2_bzBuffToBuffDecompress(out.data(), &out_size, packed.data(), packed_size, 0, 0);
    benchmark::DoNotOptimize(out.data());
  }
  state.counters["raw_bytes"] = static_cast<double>(raw.size());
  state.counters["packed_bytes"] = static_cast<double>(packed_size);
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(raw.size()));
}
BENCHMARK(BM_Bz2DecompressOneImage)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace gvio::io
