#include "viz/image_check.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <list>
#include <map>
#include <optional>
#include <unordered_map>

#include <opencv2/imgproc.hpp>

#include "io/image_loader.hpp"
#include "mapping/map_builder.hpp"
#include "mapping/stereo_depth.hpp"
#include "odometry/error.hpp"
#include "odometry/rectifier.hpp"
#include "render/camera.hpp"
#include "render/egl_context.hpp"
#include "render/framebuffer.hpp"
#include "render/renderer.hpp"
#include "viz/camera_view.hpp"

namespace gvio::viz {
namespace {

constexpr float kMinSplatPx = 1.5F;
constexpr float kMaxSplatPx = 12.0F;
constexpr double kNearM = 0.5;
// A pixel counts as drawn when all its multisamples were (edges blend with the background).
constexpr std::uint8_t kCoveredAlpha = 250;
// A keyframe's own image and depth, kept from when its cloud was computed (as a source of an
// earlier check) until it is checked itself: a sweep along the drive then runs SGBM once per
// keyframe. ~2.3 MB each at KITTI's size; the keyframes ahead of a sweep within the neighbour
// radius are ~35.
constexpr std::size_t kPendingInputs = 48;

// One keyframe's voxelised stereo points in the map frame.
struct KeyframeCloud {
  std::vector<Eigen::Vector3f> p_map;
  std::vector<std::uint8_t> grey;
};

}  // namespace

void ImageCheckOptions::validate() const {
  const auto positive = [](double v, const char* name) {
    if (!(v > 0.0) || !std::isfinite(v)) throw InvalidInput(fmt::format("{} must be > 0", name));
  };
  if (!(exclude_s >= 0.0) || !std::isfinite(exclude_s)) {
    throw InvalidInput("--exclude must be >= 0 s");
  }
  positive(neighbour_radius_m, "the neighbour radius");
  positive(max_depth_m, "the maximum depth");
  positive(splat_m, "the splat size");
  if (!(max_view_angle_deg > 0.0 && max_view_angle_deg <= 180.0)) {
    throw InvalidInput("the maximum view angle must be in (0, 180] degrees");
  }
  if (cache_keyframes < 1) throw InvalidInput("the keyframe cache must hold >= 1 keyframe");
  if (!(min_self_depth_agreement >= 0.0 && min_self_depth_agreement <= 1.0)) {
    throw InvalidInput("the self-check's minimum depth agreement must be in [0, 1]");
  }
  score.validate();
}

struct ImageCheck::State {
  const io::RunFiles* run = nullptr;
  const io::Dataset* ds = nullptr;
  ImageCheckOptions options;
  mapping::DenseMapConfig dense;
  std::optional<odometry::Rectifier> rectifier;
  std::optional<mapping::StereoDepth> stereo;
  render::PinholeIntrinsics K;
  double focal_baseline_px_m = 0.0;  // of the SGBM's downscaled images
  std::vector<MapKeyframe> keyframes;
  std::unordered_map<std::size_t, KeyframeCloud> cache;
  std::list<std::size_t> lru;  // most recently used first
  struct OwnInputs {
    cv::Mat recorded, depth;
  };
  std::map<std::size_t, OwnInputs> pending;  // of keyframes not checked yet
  std::vector<bool> checked;
  render::EglContext context;
  render::Renderer renderer{context};
  std::optional<render::Framebuffer> target;

  void selectKeyframes();
  mapping::CameraCloud stereoPoints(std::size_t frame, cv::Mat* left_out);
  const KeyframeCloud& cloudOf(std::size_t keyframe);
  void remember(std::size_t keyframe, const mapping::CameraCloud& raw);
  void trimCache();
  void ownInputs(std::size_t k, cv::Mat& recorded, cv::Mat& depth);
  render::PointCloud pointsInView(std::size_t k, const std::vector<std::size_t>& sources,
                                  double& median_depth_m);
  void draw(render::PointCloud points, const render::RenderCamera& camera, CheckImages& out,
            cv::Mat& depth);
  cv::Mat stereoDepthImage(const mapping::CameraCloud& raw) const;
  std::vector<std::size_t> sourcesFor(std::size_t keyframe) const;
  std::vector<std::size_t> otherPasses(std::size_t keyframe,
                                       const std::vector<std::size_t>& sources) const;
  bool noneAhead(std::size_t keyframe, const std::vector<std::size_t>& sources) const;
  mapping::ViewScore scoreAgainst(std::size_t k, const std::vector<std::size_t>& sources,
                                  const cv::Mat& stereo_depth, CheckImages& drawn,
                                  std::size_t& points_drawn);
};

void ImageCheck::State::selectKeyframes() {
  const Eigen::Isometry3d& T_b_c = rectifier->left().T_b_c;
  for (std::size_t i = 0; i < ds->frames.size(); ++i) {
    const std::int64_t t_ns = ds->frames[i].t_ns;
    const auto T_map_c = cameraPoseAt(*run, t_ns, T_b_c);
    if (!T_map_c) continue;
    if (!keyframes.empty() &&
        !mapping::depthSpacingReached(dense, keyframes.back().T_map_c, *T_map_c)) {
      continue;
    }
    keyframes.push_back({i, t_ns, *T_map_c});
  }
}

mapping::CameraCloud ImageCheck::State::stereoPoints(std::size_t frame, cv::Mat* left_out) {
  const cv::Mat raw_left = io::loadFrameImage(*ds, frame, 0);
  const cv::Mat raw_right = io::loadFrameImage(*ds, frame, 1);
  const odometry::RectifiedImages rect = rectifier->rectify(raw_left, raw_right);
  if (left_out != nullptr) *left_out = rect.left;
  return stereo->compute(rect.left, rect.right);
}

void ImageCheck::State::remember(std::size_t keyframe, const mapping::CameraCloud& raw) {
  if (cache.count(keyframe) != 0) return;
  const mapping::CameraCloud voxels = mapping::voxelDownsample(raw, dense.voxel_size_m);
  const Eigen::Isometry3d& T_map_c = keyframes[keyframe].T_map_c;
  KeyframeCloud cloud;
  cloud.p_map.reserve(voxels.size());
  cloud.grey.reserve(voxels.size());
  for (const pcl::PointXYZI& p : voxels.points) {
    cloud.p_map.push_back((T_map_c * Eigen::Vector3d(p.x, p.y, p.z)).cast<float>());
    cloud.grey.push_back(static_cast<std::uint8_t>(std::clamp(p.intensity, 0.0F, 255.0F)));
  }
  cache.emplace(keyframe, std::move(cloud));
  lru.push_front(keyframe);
}

// After a check only: during one, its sources' clouds must all stay (they may outnumber the cap).
void ImageCheck::State::trimCache() {
  while (lru.size() > options.cache_keyframes) {
    cache.erase(lru.back());
    lru.pop_back();
  }
}

const KeyframeCloud& ImageCheck::State::cloudOf(std::size_t keyframe) {
  if (const auto it = cache.find(keyframe); it != cache.end()) {
    lru.remove(keyframe);
    lru.push_front(keyframe);
    return it->second;
  }
  cv::Mat recorded;
  const mapping::CameraCloud raw = stereoPoints(keyframes[keyframe].frame, &recorded);
  if (!checked[keyframe]) {
    pending[keyframe] = {recorded, stereoDepthImage(raw)};
    // Beyond the cap, the keyframe farthest along the drive waits longest: drop it.
    if (pending.size() > kPendingInputs) pending.erase(std::prev(pending.end()));
  }
  remember(keyframe, raw);
  return cache.at(keyframe);
}

// The keyframe's own stereo depth at full resolution: each SGBM pixel (downscaled) covers a block
// of 1/downscale pixels; the nearest depth wins where blocks overlap.
cv::Mat ImageCheck::State::stereoDepthImage(const mapping::CameraCloud& raw) const {
  cv::Mat depth(K.height, K.width, CV_32FC1, cv::Scalar(0.0F));
  const int block = std::max(1, static_cast<int>(std::lround(1.0 / dense.stereo.downscale)));
  for (const pcl::PointXYZI& p : raw.points) {
    if (!(p.z > 0.0F)) continue;
    const double x = p.x, y = p.y, z = p.z;
    const double u = K.fx * x / z + K.cx, v = K.fy * y / z + K.cy;
    const long u0 = std::lround(u) - block / 2, v0 = std::lround(v) - block / 2;
    for (long row = v0; row < v0 + block; ++row) {
      for (long col = u0; col < u0 + block; ++col) {
        if (col < 0 || row < 0 || col >= K.width || row >= K.height) continue;
        float& d = depth.at<float>(static_cast<int>(row), static_cast<int>(col));
        if (d == 0.0F || p.z < d) d = p.z;
      }
    }
  }
  return depth;
}

// Keyframes at least exclude_s away whose camera is near and whose points (within the stereo
// gate ahead of it) are not all behind the checked camera.
std::vector<std::size_t> ImageCheck::State::sourcesFor(std::size_t k) const {
  const MapKeyframe& kf = keyframes[k];
  const Eigen::Vector3d c_k = kf.T_map_c.translation();
  const Eigen::Vector3d fwd_k = kf.T_map_c.linear().col(2);
  const double reach = dense.stereo.max_range_m;
  const auto min_dt = static_cast<std::int64_t>(options.exclude_s * 1e9);
  const double min_cos = std::cos(options.max_view_angle_deg * M_PI / 180.0);
  std::vector<std::size_t> out;
  for (std::size_t j = 0; j < keyframes.size(); ++j) {
    const MapKeyframe& other = keyframes[j];
    if (std::llabs(other.t_ns - kf.t_ns) < min_dt) continue;
    const Eigen::Vector3d c_j = other.T_map_c.translation();
    if ((c_j - c_k).norm() > options.neighbour_radius_m) continue;
    if (other.T_map_c.linear().col(2).dot(fwd_k) < min_cos) continue;
    const Eigen::Vector3d mid_j = c_j + 0.5 * reach * other.T_map_c.linear().col(2);
    if ((mid_j - c_k).dot(fwd_k) < -reach) continue;
    out.push_back(j);
  }
  return out;
}

// The sources not on the keyframe's own pass: its pass is the run of consecutive keyframes around
// it that all stay within the neighbour radius of it (a car stopped at a light has no keyframes
// while it stands, so the keyframes before and after the stop are one pass).
std::vector<std::size_t> ImageCheck::State::otherPasses(
    std::size_t k, const std::vector<std::size_t>& sources) const {
  const Eigen::Vector3d c_k = keyframes[k].T_map_c.translation();
  const auto near = [&](std::size_t j) {
    return (keyframes[j].T_map_c.translation() - c_k).norm() <= options.neighbour_radius_m;
  };
  std::size_t first = k, last = k;
  while (first > 0 && near(first - 1)) --first;
  while (last + 1 < keyframes.size() && near(last + 1)) ++last;
  std::vector<std::size_t> out;
  for (const std::size_t j : sources) {
    if (j < first || j > last) out.push_back(j);
  }
  return out;
}

// True when no source camera lies ahead of keyframe k's camera (along its optical axis): the map
// it sees was measured from behind only.
bool ImageCheck::State::noneAhead(std::size_t k, const std::vector<std::size_t>& sources) const {
  const Eigen::Vector3d c_k = keyframes[k].T_map_c.translation();
  const Eigen::Vector3d fwd_k = keyframes[k].T_map_c.linear().col(2);
  return std::none_of(sources.begin(), sources.end(), [&](std::size_t j) {
    return (keyframes[j].T_map_c.translation() - c_k).dot(fwd_k) > 0.0;
  });
}

ImageCheck::ImageCheck(const io::RunFiles& run, const io::Dataset& dataset,
                       const mapping::DenseMapConfig& dense, const ImageCheckOptions& options)
    : state_(std::make_unique<State>()) {
  options.validate();
  State& s = *state_;
  s.run = &run;
  s.ds = &dataset;
  s.options = options;
  s.dense = dense;
  if (dataset.cameras.size() < 2) {
    throw InvalidInput(dataset.root.string() +
                       ": the image check needs a stereo camera (it rebuilds the map's stereo "
                       "points); this dataset has one camera");
  }
  s.rectifier.emplace(dataset.cameras[0], std::optional<CameraModel>(dataset.cameras[1]));
  const CameraModel& cam = s.rectifier->left();
  s.stereo.emplace(dense.stereo, cam, s.rectifier->baselineM());
  s.K = renderIntrinsics(cam, kNearM, 2.0 * options.max_depth_m);
  s.focal_baseline_px_m = cam.fx * dense.stereo.downscale * s.rectifier->baselineM();
  s.target.emplace(s.K.width, s.K.height);
  s.selectKeyframes();
  if (s.keyframes.empty()) {
    throw InvalidInput(run.dir.string() + ": no image of the dataset has a pose on the trajectory");
  }
  s.checked.assign(s.keyframes.size(), false);
}

ImageCheck::~ImageCheck() = default;

const std::vector<MapKeyframe>& ImageCheck::keyframes() const {
  return state_->keyframes;
}

std::size_t ImageCheck::keyframeNearest(std::int64_t t_ns) const {
  const auto& kfs = state_->keyframes;
  std::size_t best = 0;
  for (std::size_t i = 1; i < kfs.size(); ++i) {
    if (std::llabs(kfs[i].t_ns - t_ns) < std::llabs(kfs[best].t_ns - t_ns)) best = i;
  }
  return best;
}

// The keyframe's own rectified image and stereo depth: kept from when its cloud was computed, or
// computed now.
void ImageCheck::State::ownInputs(std::size_t k, cv::Mat& recorded, cv::Mat& depth) {
  if (const auto it = pending.find(k); it != pending.end()) {
    recorded = it->second.recorded;
    depth = it->second.depth;
  } else {
    const mapping::CameraCloud own = stereoPoints(keyframes[k].frame, &recorded);
    depth = stereoDepthImage(own);
    remember(k, own);
  }
  checked[k] = true;
  // A sweep goes forward: inputs kept for keyframes behind it would wait forever.
  pending.erase(pending.begin(), pending.upper_bound(k));
}

// The sources' points in view, the nearest per pixel only (farther ones could only be hidden), as
// grey splats sized by their distance; median_depth_m gets their median depth (NaN: none).
render::PointCloud ImageCheck::State::pointsInView(std::size_t k,
                                                   const std::vector<std::size_t>& sources,
                                                   double& median_depth_m) {
  const Eigen::Isometry3d T_c_map = keyframes[k].T_map_c.inverse();
  std::vector<float> nearest_z(static_cast<std::size_t>(K.width) * K.height,
                               std::numeric_limits<float>::infinity());
  std::vector<std::pair<const KeyframeCloud*, std::size_t>> nearest(nearest_z.size(), {nullptr, 0});
  for (const std::size_t j : sources) {
    const KeyframeCloud& cloud = cloudOf(j);
    for (std::size_t i = 0; i < cloud.p_map.size(); ++i) {
      const Eigen::Vector3d p_c = T_c_map * cloud.p_map[i].cast<double>();
      if (p_c.z() < kNearM || p_c.z() > options.max_depth_m) continue;
      const long u = std::lround(K.fx * p_c.x() / p_c.z() + K.cx);
      const long v = std::lround(K.fy * p_c.y() / p_c.z() + K.cy);
      if (u < 0 || v < 0 || u >= K.width || v >= K.height) continue;
      const std::size_t px = static_cast<std::size_t>(v) * K.width + static_cast<std::size_t>(u);
      if (static_cast<float>(p_c.z()) < nearest_z[px]) {
        nearest_z[px] = static_cast<float>(p_c.z());
        nearest[px] = {&cloud, i};
      }
    }
  }
  render::PointCloud points;
  std::vector<float> depths;
  for (std::size_t px = 0; px < nearest.size(); ++px) {
    const auto [cloud, i] = nearest[px];
    if (cloud == nullptr) continue;
    depths.push_back(nearest_z[px]);
    const float g = cloud->grey[i] / 255.0F;
    points.points.push_back(cloud->p_map[i].cast<double>());
    points.colors.emplace_back(g, g, g, 1.0F);
    points.sizes_px.push_back(
        std::clamp(static_cast<float>(K.fx * options.splat_m / static_cast<double>(nearest_z[px])),
                   kMinSplatPx, kMaxSplatPx));
  }
  median_depth_m = std::numeric_limits<double>::quiet_NaN();
  if (!depths.empty()) {
    const auto mid = depths.begin() + static_cast<std::ptrdiff_t>(depths.size() / 2);
    std::nth_element(depths.begin(), mid, depths.end());
    median_depth_m = static_cast<double>(*mid);
  }
  return points;
}

// Draws the points from the camera: grey level, coverage and depth of the fully covered pixels.
void ImageCheck::State::draw(render::PointCloud points, const render::RenderCamera& camera,
                             CheckImages& out, cv::Mat& depth) {
  out.rendered = cv::Mat(K.height, K.width, CV_8UC1, cv::Scalar(0));
  out.covered = cv::Mat(K.height, K.width, CV_8UC1, cv::Scalar(0));
  depth = cv::Mat(K.height, K.width, CV_32FC1, cv::Scalar(0.0F));
  if (points.points.empty()) return;
  render::Scene scene;
  scene.background = {0, 0, 0, 0};
  scene.point_clouds.push_back(std::move(points));
  const render::GpuScene gpu(scene);
  const render::ImageRgba rgba = renderer.renderColor(gpu, camera, *target);
  const std::vector<float> window = target->readDepth();
  for (int y = 0; y < K.height; ++y) {
    for (int x = 0; x < K.width; ++x) {
      const std::uint8_t* c = rgba.pixel(x, y);
      if (c[3] < kCoveredAlpha) continue;
      const std::size_t px = static_cast<std::size_t>(y) * K.width + static_cast<std::size_t>(x);
      out.rendered.at<std::uint8_t>(y, x) = c[0];
      out.covered.at<std::uint8_t>(y, x) = 255;
      depth.at<float>(y, x) = static_cast<float>(render::windowDepthToMetric(camera, window[px]));
    }
  }
}

// The map of `sources` drawn from keyframe k and scored against its image and stereo depth.
mapping::ViewScore ImageCheck::State::scoreAgainst(std::size_t k,
                                                   const std::vector<std::size_t>& sources,
                                                   const cv::Mat& stereo_depth, CheckImages& drawn,
                                                   std::size_t& points_drawn) {
  double median_depth_m = 0.0;
  render::PointCloud points = pointsInView(k, sources, median_depth_m);
  points_drawn = points.points.size();
  cv::Mat rendered_depth;
  draw(std::move(points), render::pinholeCamera(K, keyframes[k].T_map_c), drawn, rendered_depth);
  mapping::ViewScore score =
      mapping::scoreView(drawn.recorded, drawn.rendered, drawn.covered, rendered_depth,
                         stereo_depth, focal_baseline_px_m, options.score);
  score.drawn_depth_m = median_depth_m;
  return score;
}

CheckedView ImageCheck::check(std::size_t k, CheckImages* images) {
  State& s = *state_;
  const auto start = std::chrono::steady_clock::now();
  if (k >= s.keyframes.size()) throw InvalidInput("image check: keyframe index out of range");
  CheckImages drawn;
  cv::Mat stereo_depth;
  s.ownInputs(k, drawn.recorded, stereo_depth);
  const std::vector<std::size_t> sources = s.sourcesFor(k);
  CheckedView view;
  view.keyframe = k;
  view.t_ns = s.keyframes[k].t_ns;
  view.source_keyframes = sources.size();
  if (s.options.revisits) {
    const std::vector<std::size_t> others = s.otherPasses(k, sources);
    view.revisit_sources = others.size();
    if (!others.empty()) {
      CheckImages revisit = drawn;
      std::size_t points = 0;
      view.revisit = s.scoreAgainst(k, others, stereo_depth, revisit, points);
      view.revisit.one_sided = s.noneAhead(k, others);
    }
  }
  view.score = s.scoreAgainst(k, sources, stereo_depth, drawn, view.points_drawn);
  view.score.one_sided = s.noneAhead(k, sources);
  if (images != nullptr) *images = drawn;
  s.trimCache();
  view.ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return view;
}

mapping::ViewScore ImageCheck::selfCheck(std::size_t k) {
  State& s = *state_;
  if (k >= s.keyframes.size()) throw InvalidInput("image check: keyframe index out of range");
  CheckImages drawn;
  const mapping::CameraCloud own = s.stereoPoints(s.keyframes[k].frame, &drawn.recorded);
  const cv::Mat stereo_depth = s.stereoDepthImage(own);
  s.remember(k, own);
  std::size_t points = 0;
  const mapping::ViewScore score = s.scoreAgainst(k, {k}, stereo_depth, drawn, points);
  s.trimCache();
  return score;
}

cv::Mat sideBySide(const CheckImages& im) {
  if (im.recorded.type() != CV_8UC1 || im.rendered.size() != im.recorded.size() ||
      im.covered.size() != im.recorded.size()) {
    throw InvalidInput("side-by-side: images of different sizes or types");
  }
  cv::Scalar mean_rec, std_rec, mean_ren, std_ren;
  cv::meanStdDev(im.recorded, mean_rec, std_rec, im.covered);
  cv::meanStdDev(im.rendered, mean_ren, std_ren, im.covered);
  const double gain = std_ren[0] > 1e-6 ? std_rec[0] / std_ren[0] : 1.0;
  cv::Mat matched;
  im.rendered.convertTo(matched, CV_8UC1, gain, mean_rec[0] - gain * mean_ren[0]);
  matched.setTo(0, im.covered == 0);
  cv::Mat diff;
  cv::absdiff(im.recorded, matched, diff);
  cv::Mat diff_colour;
  cv::applyColorMap(diff, diff_colour, cv::COLORMAP_MAGMA);
  diff_colour.setTo(cv::Scalar(0, 0, 0), im.covered == 0);
  cv::Mat rec_bgr, ren_bgr, out;
  cv::cvtColor(im.recorded, rec_bgr, cv::COLOR_GRAY2BGR);
  cv::cvtColor(matched, ren_bgr, cv::COLOR_GRAY2BGR);
  cv::hconcat(std::vector<cv::Mat>{rec_bgr, ren_bgr, diff_colour}, out);
  return out;
}

}  // namespace gvio::viz
