// The visual front end's per-frame cost: FeatureTracker::track (stereo, default config) on
// consecutive simulated KITTI-size frames (1241 x 376). Context: the whole VIO must stay within
// 30 ms per frame on a 2-core machine; VINS-Fusion's tracker spends about 21 ms on KITTI.
#include <benchmark/benchmark.h>

#include <memory>
#include <vector>

#include "io/dataset.hpp"
#include "io/image_loader.hpp"
#include "io/trajectory_io.hpp"
#include "odometry/feature_tracker.hpp"
#include "sim/simulator.hpp"
#include "support/fixtures.hpp"

namespace gvio::odometry {
namespace {

struct StereoFrames {
  std::vector<std::int64_t> t_ns;
  std::vector<cv::Mat> left, right;
};

// 3 s of the demo drive through the simulator (31 stereo frames), made once for every benchmark.
const StereoFrames& frames() {
  static const StereoFrames instance = [] {
    const test::TempDir dir("tracker_bench");
    io::writeTum(dir.path() / "drive.tum", test::demoDrive());
    sim::SimRequest request;
    request.trajectory = dir.path() / "drive.tum";
    request.seconds = 3.0;
    request.seed = 11;
    request.out = dir.path() / "sim";
    sim::simulate(request, sim::SimConfig{}, ImuNoise{}, [](std::size_t, std::size_t) {});
    const io::Dataset ds = io::readDataset(request.out, std::nullopt, io::ReaderConfig{});
    StereoFrames f;
    for (const auto& frame : ds.frames) {
      f.t_ns.push_back(frame.t_ns);
      f.left.push_back(io::loadGrayImage(frame.image_paths[0], ds.cameras[0]));
      f.right.push_back(io::loadGrayImage(frame.image_paths[1], ds.cameras[1]));
    }
    return f;
  }();
  return instance;
}

// One iteration = one frame, in drive order; at the end of the drive the tracker starts over
// (reset outside the timing), so about 1 frame in 31 pays for a full detection. The argument is
// the full-resolution KLT pass's window (0: without it; 7: the default).
void BM_FeatureTrackerStereoKitti(benchmark::State& state) {
  const StereoFrames& f = frames();
  TrackerConfig config;
  config.klt_refine_window_px = static_cast<int>(state.range(0));
  FeatureTracker tracker{config};
  std::size_t k = 0;
  double features = 0, ms_track = 0, ms_detect = 0, ms_stereo = 0;
  for (auto _ : state) {
    const TrackedFrame out = tracker.track(f.t_ns[k], f.left[k], f.right[k]);
    features += static_cast<double>(out.features.size());
    ms_track += out.stats.ms_track;
    ms_detect += out.stats.ms_detect;
    ms_stereo += out.stats.ms_stereo;
    if (++k == f.left.size()) {
      state.PauseTiming();
      tracker.reset();
      k = 0;
      state.ResumeTiming();
    }
  }
  const auto avg = benchmark::Counter::kAvgIterations;
  state.counters["features"] = benchmark::Counter(features, avg);
  state.counters["ms_track"] = benchmark::Counter(ms_track, avg);
  state.counters["ms_detect"] = benchmark::Counter(ms_detect, avg);
  state.counters["ms_stereo"] = benchmark::Counter(ms_stereo, avg);
}
// Five passes over the drive, so every run averages the same mix of frames.
BENCHMARK(BM_FeatureTrackerStereoKitti)
    ->Arg(0)
    ->Arg(TrackerConfig{}.klt_refine_window_px)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(155);

}  // namespace
}  // namespace gvio::odometry
