// Per-keyframe cost of the map (issue 8 targets: sparse update <= 10 ms, dense depth + OctoMap
// insertion <= 60 ms at 0.2 m), on a KITTI-size (1241 x 376) synthetic textured stereo pair: a
// road plane below the horizon (disparity growing to 62 px at the bottom row, 6 m) and a facade
// across the street at 40 px (9.7 m) above it, with default MapConfig. Time is wall-clock; CPU is
// the process's (SGBM_3WAY runs on OpenCV's thread pool).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "mapping/image_consistency.hpp"
#include "mapping/map_builder.hpp"
#include "mapping/occupancy_builder.hpp"
#include "mapping/stereo_depth.hpp"
#include "support/kitti_camera.hpp"

namespace gvio::mapping {
namespace {

CameraModel kittiCamera() {
  return test::kittiRectifiedCamera();
}
constexpr double kBaseline_m = test::kKittiBaselineM;

struct Pair {
  cv::Mat left, right;
};

// Right image by per-row disparity: right(v, u) = left(v, u + d(v)), bilinear.
const Pair& kittiPair() {
  static const Pair pair = [] {
    const CameraModel c = kittiCamera();
    cv::Mat noise(c.height_px, c.width_px + 128, CV_8UC1);
    cv::RNG(11).fill(noise, cv::RNG::UNIFORM, 0, 256);
    cv::GaussianBlur(noise, noise, cv::Size(0, 0), 1.2);
    cv::normalize(noise, noise, 0, 255, cv::NORM_MINMAX);
    cv::Mat map_x(c.height_px, c.width_px, CV_32FC1), map_y(c.height_px, c.width_px, CV_32FC1);
    for (int v = 0; v < c.height_px; ++v) {
      // Road at camera height 1.65 m: d = b (v - cy) / h; the facade keeps 40 px.
      const double d = std::max(40.0, kBaseline_m * (v - c.cy) / 1.65);
      for (int u = 0; u < c.width_px; ++u) {
        map_x.at<float>(v, u) = static_cast<float>(u + d);
        map_y.at<float>(v, u) = static_cast<float>(v);
      }
    }
    Pair p;
    p.left = noise.colRange(0, c.width_px).clone();
    cv::remap(noise, p.right, map_x, map_y, cv::INTER_LINEAR);
    return p;
  }();
  return pair;
}

CameraCloud keyframePoints() {
  StereoDepth depth(MapConfig{}.dense.stereo, kittiCamera(), kBaseline_m);
  return voxelDownsample(depth.compute(kittiPair().left, kittiPair().right), 0.1);
}

void BM_MappingDenseDepth(benchmark::State& state) {
  const MapConfig config;
  StereoDepth depth(config.dense.stereo, kittiCamera(), kBaseline_m);
  std::size_t raw = 0, kept = 0;
  for (auto _ : state) {
    const CameraCloud cloud = depth.compute(kittiPair().left, kittiPair().right);
    const CameraCloud down = voxelDownsample(cloud, config.dense.voxel_size_m);
    raw = cloud.size();
    kept = down.size();
    benchmark::DoNotOptimize(down.data());
  }
  state.counters["raw_points"] = static_cast<double>(raw);
  state.counters["kept_points"] = static_cast<double>(kept);
}
BENCHMARK(BM_MappingDenseDepth)
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();

void BM_MappingSparseUpdate(benchmark::State& state) {
  MapConfig config;
  config.dense.enabled = false;
  MapBuilder builder(config, kittiCamera(), kBaseline_m);
  // A window's worth of landmarks (the tracker keeps <= 200 features per image).
  std::vector<odometry::LandmarkEstimate> landmarks(static_cast<std::size_t>(state.range(0)));
  cv::RNG rng(3);
  for (std::size_t i = 0; i < landmarks.size(); ++i) {
    landmarks[i].id = i;
    landmarks[i].p_w =
        Eigen::Vector3d(rng.uniform(-10.0, 10.0), rng.uniform(-3.0, 3.0), rng.uniform(5.0, 40.0));
    landmarks[i].observations = 5;
    landmarks[i].mean_reprojection_px = 0.5;
  }
  std::int64_t t_ns = 0;
  for (auto _ : state) {
    const KeyframeTimings t = builder.addKeyframe(++t_ns, Eigen::Isometry3d::Identity(),
                                                  kittiPair().left, cv::Mat(), landmarks);
    benchmark::DoNotOptimize(t.ms_sparse);
  }
}
BENCHMARK(BM_MappingSparseUpdate)
    ->Arg(200)
    ->Arg(1000)
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();

// One keyframe's dense points into the OcTree + ColorOcTree at 0.2 m, the keyframe moving 2.5 m
// forward each time (KITTI-00: ~1500 keyframes over 3.7 km), so each insertion meets both known
// and new space, and the periodic prune is included.
void BM_MappingOctomapInsert(benchmark::State& state) {
  const CameraCloud points_c = keyframePoints();
  OccupancyBuilder occupancy(MapConfig{}.occupancy);
  double forward_m = 0.0;
  CameraCloud moved = points_c;
  for (auto _ : state) {
    state.PauseTiming();
    for (std::size_t i = 0; i < points_c.size(); ++i) {
      moved[i].z = points_c[i].z + static_cast<float>(forward_m);
    }
    state.ResumeTiming();
    occupancy.insert(moved, Eigen::Vector3d(0.0, 0.0, forward_m));
    forward_m += 2.5;
  }
  state.counters["points"] = static_cast<double>(points_c.size());
}
BENCHMARK(BM_MappingOctomapInsert)
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();

// The whole per-keyframe dense cost: depth + VoxelGrid + OctoMap insertion.
void BM_MappingDenseKeyframe(benchmark::State& state) {
  const MapConfig config;
  StereoDepth depth(config.dense.stereo, kittiCamera(), kBaseline_m);
  OccupancyBuilder occupancy(config.occupancy);
  double forward_m = 0.0;
  for (auto _ : state) {
    CameraCloud cloud = voxelDownsample(depth.compute(kittiPair().left, kittiPair().right),
                                        config.dense.voxel_size_m);
    for (auto& p : cloud) p.z += static_cast<float>(forward_m);
    occupancy.insert(cloud, Eigen::Vector3d(0.0, 0.0, forward_m));
    forward_m += 2.5;
  }
}
BENCHMARK(BM_MappingDenseKeyframe)
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();

// The scores of `gvio consistency --images` for one KITTI-size view (issue 19: <= 150 ms per
// keyframe in all): patch ZNCC and depth agreement, the render covering 60 % of the image.
void BM_ImageConsistencyScore(benchmark::State& state) {
  const cv::Size size(1241, 376);
  cv::Mat recorded(size, CV_8UC1), rendered;
  cv::RNG rng(3);
  rng.fill(recorded, cv::RNG::UNIFORM, 0, 256);
  cv::GaussianBlur(recorded, recorded, {0, 0}, 1.5);
  recorded.convertTo(rendered, CV_8UC1, 0.8, 20.0);
  cv::Mat covered(size, CV_8UC1, cv::Scalar(0));
  covered(cv::Rect(0, 150, 1241, 226)).setTo(255);
  const cv::Mat depth(size, CV_32FC1, cv::Scalar(12.0F));
  const ImageConsistencyConfig config;
  for (auto _ : state) {
    benchmark::DoNotOptimize(scoreView(recorded, rendered, covered, depth, depth, 194.0, config));
  }
}
BENCHMARK(BM_ImageConsistencyScore)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace gvio::mapping
