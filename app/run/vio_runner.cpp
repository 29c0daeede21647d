#include "run/vio_runner.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <map>
#include <optional>
#include <utility>

#include "io/dataset_summary.hpp"
#include "io/image_loader.hpp"
#include "io/input_error.hpp"
#include "io/measurement_stream.hpp"
#include "odometry/error.hpp"
#include "odometry/rectifier.hpp"
#include "run/frame_stepper.hpp"
#include "run/ordered_work.hpp"
#include "run/stats.hpp"

namespace gvio::run {
namespace {
using Clock = std::chrono::steady_clock;
using odometry::VioMode;

// A real recording may list images that are missing or damaged: each skips its frame. The first
// one per folder (or bag topic) is a warning, the rest are counted, so a long gap does not flood
// the log.
class UnreadableImages {
 public:
  std::optional<cv::Mat> load(const io::Dataset& ds, std::size_t frame, std::size_t camera) {
    try {
      return io::loadFrameImage(ds, frame, camera);
    } catch (const io::InputError& e) {
      Source& source = sources_[io::imageSource(ds, frame, camera)];
      if (source.count++ == 0) spdlog::warn("{} (frame skipped)", e.what());
      return std::nullopt;
    }
  }
  void logSummary() const {
    for (const auto& [name, source] : sources_) {
      if (source.count > 1) {
        spdlog::warn("{}: {} images could not be read, their frames were skipped", name,
                     source.count);
      }
    }
  }

 private:
  struct Source {
    int count = 0;
  };
  std::map<std::string, Source> sources_;
};

// Every event goes to report.json; the state changes a user watches for (waiting for motion,
// initialised, lost, restarted) are also logged as they happen, the frequent ones at debug level.
void appendEvents(odometry::VioEstimator& estimator, std::vector<odometry::VioEvent>& events) {
  for (auto& e : estimator.takeEvents()) {
    const bool notable = e.kind == "waiting" || e.kind == "initialized" || e.kind == "lost" ||
                         e.kind == "reinitialized" || e.kind == "time_jump" || e.kind == "coasting";
    spdlog::log(notable ? spdlog::level::info : spdlog::level::debug, "vio {:.3f} s: {}: {}",
                static_cast<double>(e.t_ns) * 1e-9, e.kind, e.message);
    events.push_back(std::move(e));
  }
}

}  // namespace

double imuRateHz(const io::Dataset& dataset) {
  std::vector<std::int64_t> stamps;
  stamps.reserve(dataset.imu.size());
  for (const ImuSample& s : dataset.imu) stamps.push_back(s.t_ns);
  return stamps.size() < 2 ? 0.0 : io::streamStats(stamps, 2.0).rate_hz;
}

VioMode chooseVioMode(const std::string& mode, const io::Dataset& ds) {
  const std::string where = ds.root.string();
  const std::size_t cameras = ds.cameras.size();
  const double rate_hz = imuRateHz(ds);
  const bool imu = rate_hz >= kMinImuRateHz;
  if (ds.frames.empty() || cameras == 0) {
    throw InvalidInput(where + ": no camera frames: gvio run needs a camera");
  }
  const std::string imu_text =
      ds.imu.empty() ? "no IMU" : fmt::format("an IMU at {:.1f} Hz", rate_hz);
  if (mode == "auto") {
    if (cameras >= 2) return imu ? VioMode::kStereoImu : VioMode::kStereo;
    if (imu) return VioMode::kMonoImu;
    throw InvalidInput(fmt::format(
        "{}: one camera and {}: no VIO mode fits (mono-imu needs an IMU of >= {:.0f} Hz; a single "
        "camera alone has no metric scale)",
        where, imu_text, kMinImuRateHz));
  }
  const VioMode chosen = odometry::parseVioMode(mode);
  if (odometry::usesStereo(chosen) && cameras < 2) {
    throw InvalidInput(fmt::format(
        "{}: vio.mode={} needs two cameras, the dataset has one (use vio.mode=mono-imu or auto)",
        where, mode));
  }
  if (odometry::usesImu(chosen) && !imu) {
    throw InvalidInput(
        fmt::format("{}: vio.mode={} needs an IMU of >= {:.0f} Hz, the dataset has "
                    "{} (use vio.mode=stereo or auto)",
                    where, mode, kMinImuRateHz, imu_text));
  }
  return chosen;
}

namespace {

// A frame's images, decoded and rectified (ahead of the estimator when threaded).
struct LoadedFrame {
  bool readable = false;  // both images loaded: else the frame is skipped
  odometry::RectifiedImages images;
  double load_ms = 0.0, rectify_ms = 0.0;
};

LoadedFrame loadFrame(const io::Dataset& ds, std::size_t frame, bool stereo,
                      const odometry::Rectifier& rectifier, UnreadableImages& unreadable) {
  LoadedFrame f;
  const auto t_load = Clock::now();
  std::optional<cv::Mat> left = unreadable.load(ds, frame, 0);
  std::optional<cv::Mat> right;
  if (left && stereo) right = unreadable.load(ds, frame, 1);
  if (!left || (stereo && !right)) return f;
  f.load_ms = msSince(t_load);
  const auto t_rectify = Clock::now();
  f.images = rectifier.rectify(*left, right ? *right : cv::Mat());
  f.rectify_ms = msSince(t_rectify);
  f.readable = true;
  return f;
}

// Keyframe work queued with everything it needs, so the estimator never waits for it.
KeyframeInput keyframeInput(std::int64_t t_ns, const odometry::FrameResult& result,
                            const odometry::RectifiedImages& images,
                            const odometry::Rectifier& rectifier,
                            const odometry::VioEstimator& estimator) {
  KeyframeInput kf;
  kf.t_ns = t_ns;
  kf.T_w_b = result.T_w_b;
  kf.left = images.left;
  kf.right = images.right;
  kf.left_camera = rectifier.left();
  kf.baseline_m = rectifier.baselineM();
  kf.landmarks = estimator.landmarks();
  kf.features = estimator.lastFeatures();
  return kf;
}

}  // namespace

VioRunResult runVio(const io::Dataset& ds, odometry::EstimatorConfig config,
                    const VioRunOptions& options) {
  const auto start = Clock::now();
  VioRunResult r;
  r.mode = config.mode;
  const bool stereo = odometry::usesStereo(config.mode);
  if (ds.cameras.empty() || (stereo && ds.cameras.size() < 2)) {
    throw InvalidInput(ds.root.string() + ": not enough cameras for " + toString(config.mode));
  }
  const odometry::Rectifier rectifier(
      ds.cameras[0], stereo ? std::optional<CameraModel>(ds.cameras[1]) : std::nullopt);
  r.rectification_identity = rectifier.isIdentity();
  r.baseline_m = rectifier.baselineM();
  config.tracker.stereo = stereo;
  odometry::VioEstimator estimator(config, rectifier.left(), rectifier.right());
  r.time_offset_estimated = config.estimate_time_offset && odometry::usesImu(config.mode);

  // Decoding runs ahead by a few frames; the keyframe hook runs behind by a few keyframes (both
  // queues bound the images held). The estimator's inputs and the hook's order are those of the
  // single-threaded run.
  const bool threaded = options.threads >= 2;
  UnreadableImages unreadable;  // used by the decoding side only
  Prefetcher<LoadedFrame> frames(threaded, 4, [&](std::size_t i) -> std::optional<LoadedFrame> {
    if (i >= ds.frames.size()) return std::nullopt;
    return loadFrame(ds, i, stereo, rectifier, unreadable);
  });
  OrderedWorker keyframe_work(threaded, 4);
  FrameStepper stepper(estimator, threaded);
  std::optional<LoadedFrame> peeked;  // the frame after the current one, taken early
  const ProgressFn& progress = options.progress;

  io::MeasurementStream stream(ds);
  std::size_t frames_done = 0;
  while (const auto m = stream.next()) {
    if (const auto* imu = std::get_if<const ImuSample*>(&*m)) {
      estimator.addImu(**imu);
      ++r.imu_samples;
      continue;
    }
    if (std::holds_alternative<const GnssFix*>(*m)) {
      ++r.gnss_fixes;  // counted only: GNSS fusion is not part of this build
      continue;
    }
    const io::FrameRecord& frame = *std::get<const io::FrameRecord*>(*m);
    if (options.stop && options.stop()) {
      r.stopped = true;
      break;
    }
    if (progress) progress(frames_done, ds.frames.size());
    ++frames_done;
    std::optional<LoadedFrame> loaded =
        peeked ? std::exchange(peeked, std::nullopt) : frames.next();
    if (!loaded || !loaded->readable) {
      ++r.frames_skipped_unreadable;  // the estimator sees a gap, as after a dropped frame
      continue;
    }
    // The next frame, decoded already when threaded, is tracked while this one is estimated.
    const std::size_t index = frames_done - 1;
    std::optional<FrameStepper::Next> next;
    if (threaded && index + 1 < ds.frames.size()) {
      peeked = frames.next();
      if (peeked && peeked->readable)
        next = FrameStepper::Next{ds.frames[index + 1].t_ns, &peeked->images};
    }
    const odometry::RectifiedImages& images = loaded->images;
    const int free_before = estimator.counters().time_offset_free_solves;
    const odometry::FrameResult result = stepper.step(frame.t_ns, images, next ? &*next : nullptr);
    if (estimator.counters().time_offset_free_solves > free_before) {
      r.time_offset_free_estimates.push_back(estimator.timeOffsetS());
    }
    r.timings.load_ms.push_back(loaded->load_ms);
    r.timings.rectify_ms.push_back(loaded->rectify_ms);
    r.timings.tracking_ms.push_back(result.ms_tracking);
    r.timings.estimator_ms.push_back(result.ms_estimator);
    r.timings.total_ms.push_back(loaded->load_ms + loaded->rectify_ms + result.ms_tracking +
                                 result.ms_estimator);
    appendEvents(estimator, r.events);
    if (!result.initialized) continue;
    if (r.time_offset_estimated &&
        (r.time_offset_history.empty() ||
         frame.t_ns - r.time_offset_history.back().first >= 1'000'000'000)) {
      r.time_offset_history.emplace_back(frame.t_ns, estimator.timeOffsetS());
    }
    // Never write NaN; a stamp that does not increase would break TUM readers' association.
    if (!result.T_w_b.matrix().allFinite()) {
      ++r.nonfinite_poses;
      continue;
    }
    if (!r.trajectory.t_ns.empty() && frame.t_ns <= r.trajectory.t_ns.back()) continue;
    r.trajectory.t_ns.push_back(frame.t_ns);
    r.trajectory.poses.push_back(result.T_w_b);
    if (result.keyframe && options.on_keyframe) {
      keyframe_work.submit([&options, kf = keyframeInput(frame.t_ns, result, images, rectifier,
                                                         estimator)] { options.on_keyframe(kf); });
    }
  }
  keyframe_work.drain();
  if (progress) progress(frames_done, ds.frames.size());
  appendEvents(estimator, r.events);
  unreadable.logSummary();
  if (r.nonfinite_poses > 0) {
    spdlog::warn("{} initialised frames had a non-finite pose and were left out of the trajectory",
                 r.nonfinite_poses);
  }
  r.counters = estimator.counters();
  r.time_offset_s = estimator.timeOffsetS();
  r.wall_s = std::chrono::duration<double>(Clock::now() - start).count();
  return r;
}

}  // namespace gvio::run
