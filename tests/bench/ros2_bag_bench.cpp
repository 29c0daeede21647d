// Reading a stereo frame out of a ROS 2 bag (issue 60): two 1241x376 mono8 sensor_msgs/Image
// (KITTI's size) with their CameraInfo, and a 100 Hz IMU, as `gvio simulate --format ros2bag`
// writes them; per stereo frame, the images read, decompressed (MCAP none, lz4, zstd; sqlite3),
// CDR-decoded and turned into the tracker's cv::Mat in the order a run reads them, and the bag's
// opening (index, stamps, calibration) divided over its frames. Target: <= 2 ms per stereo frame
// from an uncompressed or lz4 MCAP.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <random>

#include "io/dataset.hpp"
#include "io/ros2/ros2_bag_writer.hpp"
#include "io/ros2/ros2_messages.hpp"
#include "io/ros_image.hpp"
#include "support/camera_like.hpp"
#include "support/fixtures.hpp"

namespace gvio::io {
namespace {
namespace fs = std::filesystem;

constexpr int kFrames = 30;

// The benchmark's bag kinds: MCAP chunk compressions, then sqlite3.
const char* const kKinds[] = {"none", "lz4", "zstd", "sqlite3"};

void writeStereoBag(const fs::path& folder, int kind) {
  const bool sqlite = kind == 3;
  ros2::Ros2BagWriter w(folder, "drive",
                        sqlite ? ros2::Ros2Storage::kSqlite3 : ros2::Ros2Storage::kMcap,
                        sqlite ? "none" : kKinds[kind]);
  std::size_t images[2], infos[2];
  for (int c = 0; c < 2; ++c) {
    images[c] = w.addTopic("/cam" + std::to_string(c) + "/image_raw", ros2::kRos2ImageType);
    infos[c] = w.addTopic("/cam" + std::to_string(c) + "/camera_info", ros2::kRos2CameraInfoType);
  }
  const std::size_t imu = w.addTopic("/imu0", ros2::kRos2ImuType);
  std::mt19937 rng(1);
  for (int k = 0; k < kFrames; ++k) {
    const std::int64_t t = 1'000'000'000 + k * 100'000'000LL;
    for (int i = 0; i < 10; ++i) {
      ros2::Ros2Imu m;
      m.imu.t.header_ns = t + i * 10'000'000LL;
      m.imu.acc_mps2 = {0.0, 0.0, 9.81};
      w.write(imu, m.imu.t.header_ns, ros2::encodeImu(m));
    }
    for (int c = 0; c < 2; ++c) {
      ros2::Ros2Image image;
      image.image = grayToRosImage(test::cameraLike(2 * k + c, rng), false);
      image.image.t.header_ns = t;
      w.write(images[c], t, ros2::encodeImage(image));
      ros2::CameraInfoMessage info;
      info.t.header_ns = t;
      info.width = 1241;
      info.height = 376;
      info.k = {718.856, 0, 607.19, 0, 718.856, 185.2, 0, 0, 1};
      w.write(infos[c], t, ros2::encodeCameraInfo(info));
    }
  }
  w.close();
}

void BM_Ros2StereoFrameRead(benchmark::State& state) {
  test::TempDir dir("ros2_bag_bench");
  writeStereoBag(dir.path(), static_cast<int>(state.range(0)));
  Dataset ds = readDataset(dir.path(), DatasetFormat::kRos2Bag, ReaderConfig{});
  for (CameraModel& cam : ds.cameras) cam.fx = cam.fy = 700.0;  // the size check needs no more
  std::size_t frame = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(loadFrameImage(ds, frame, 0).data);
    benchmark::DoNotOptimize(loadFrameImage(ds, frame, 1).data);
    frame = (frame + 1) % ds.frames.size();
  }
  state.SetLabel(kKinds[state.range(0)]);
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_Ros2StereoFrameRead)->DenseRange(0, 3)->Unit(benchmark::kMillisecond);

// Opening the bag (every MCAP chunk decompressed once for the message heads; the stamps, IMU and
// CameraInfo decoded), per stereo frame in the bag.
void BM_Ros2Open(benchmark::State& state) {
  test::TempDir dir("ros2_bag_bench");
  writeStereoBag(dir.path(), static_cast<int>(state.range(0)));
  for (auto _ : state) {
    benchmark::DoNotOptimize(
        readDataset(dir.path(), DatasetFormat::kRos2Bag, ReaderConfig{}).frames);
  }
  state.SetLabel(kKinds[state.range(0)]);
  state.SetItemsProcessed(state.iterations() * kFrames);
}
BENCHMARK(BM_Ros2Open)->DenseRange(0, 3)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace gvio::io
