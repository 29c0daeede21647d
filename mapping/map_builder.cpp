#include "mapping/map_builder.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "mapping/dense_fusion.hpp"
#include "mapping/occupancy_builder.hpp"
#include "odometry/error.hpp"

namespace gvio::mapping {
namespace {

using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// Bilinear grey value at (u, v) (pixel centres at integer coordinates), or -1 outside.
float sampleGrey(const cv::Mat& image, double u, double v) {
  if (image.empty() || !(u >= 0.0) || !(v >= 0.0) || u > image.cols - 1.0 || v > image.rows - 1.0) {
    return -1.0f;
  }
  cv::Mat patch;
  cv::getRectSubPix(image, cv::Size(1, 1),
                    cv::Point2f(static_cast<float>(u), static_cast<float>(v)), patch, CV_32F);
  return patch.at<float>(0, 0);
}

pcl::PointXYZI makePoint(const Eigen::Vector3d& p, float intensity) {
  pcl::PointXYZI q;
  q.x = static_cast<float>(p.x());
  q.y = static_cast<float>(p.y());
  q.z = static_cast<float>(p.z());
  q.intensity = intensity;
  return q;
}

}  // namespace

MapBuilder::MapBuilder(const MapConfig& config, const CameraModel& left, double baseline_m)
    : config_(config), camera_(left) {
  config_.validate();
  if (left.width_px <= 0 || left.height_px <= 0 || !(left.fx > 0.0) || !(left.fy > 0.0)) {
    throw InvalidInput("map builder: camera '" + left.name + "' has no valid size or focal length");
  }
  if (!std::isfinite(baseline_m) || baseline_m < 0.0) {
    throw InvalidInput("map builder: baseline must be >= 0 m (0 for a mono rig)");
  }
  if (config_.dense.enabled && baseline_m > 0.0) {
    stereo_ = std::make_unique<StereoDepth>(config_.dense.stereo, left, baseline_m);
  }
}

KeyframeTimings MapBuilder::addKeyframe(std::int64_t t_ns, const Eigen::Isometry3d& T_w_b,
                                        const cv::Mat& left, const cv::Mat& right,
                                        const std::vector<odometry::LandmarkEstimate>& landmarks) {
  for (const cv::Mat* image : {&left, &right}) {
    if (!image->empty() && (image->type() != CV_8UC1 || image->cols != camera_.width_px ||
                            image->rows != camera_.height_px)) {
      throw InvalidInput("map builder: keyframe images must be 8-bit grey of the camera's size");
    }
  }
  KeyframeTimings timings;
  const std::size_t index = store_.addKeyframe(t_ns, T_w_b);

  auto start = Clock::now();
  const Eigen::Isometry3d T_b_w = T_w_b.inverse();
  const Eigen::Isometry3d T_c_b = camera_.T_b_c.inverse();
  for (const auto& lm : landmarks) {
    const Eigen::Vector3d p_b = T_b_w * lm.p_w;
    const Eigen::Vector3d p_c = T_c_b * p_b;
    float intensity = -1.0f;
    if (p_c.z() > 0.0) {
      intensity = sampleGrey(left, camera_.fx * p_c.x() / p_c.z() + camera_.cx,
                             camera_.fy * p_c.y() / p_c.z() + camera_.cy);
    }
    store_.updateLandmark(lm.id, index, p_b, lm.observations, lm.mean_reprojection_px, intensity);
  }
  timings.ms_sparse = msSince(start);

  if (stereo_ && denseTurn(index, T_w_b) && !left.empty() && !right.empty()) {
    last_dense_T_w_b_ = T_w_b;
    start = Clock::now();
    const CameraCloud points_c =
        voxelDownsample(stereo_->compute(left, right), config_.dense.voxel_size_m);
    store_.setDense(index, points_c);
    timings.ms_dense = msSince(start);
    timings.dense_points = store_.keyframes()[index].dense_c.size();
  }
  return timings;
}

bool depthSpacingReached(const DenseMapConfig& dense, const Eigen::Isometry3d& T_last,
                         const Eigen::Isometry3d& T_now) {
  const Eigen::Isometry3d T_rel = T_last.inverse() * T_now;
  const double moved_m = T_rel.translation().norm();
  const double turned_deg = Eigen::AngleAxisd(T_rel.rotation()).angle() * 180.0 / M_PI;
  return moved_m >= dense.min_spacing_m || turned_deg >= dense.min_rotation_deg;
}

bool MapBuilder::denseTurn(std::size_t index, const Eigen::Isometry3d& T_w_b) const {
  const DenseMapConfig& c = config_.dense;
  if (index % static_cast<std::size_t>(c.every_n_keyframes) != 0) return false;
  if (!last_dense_T_w_b_) return true;
  return depthSpacingReached(c, *last_dense_T_w_b_, T_w_b);
}

bool MapBuilder::landmarkAccepted(const StoredLandmark& lm) const {
  return lm.observations >= config_.sparse.min_landmark_observations &&
         lm.mean_reprojection_px <= config_.sparse.max_landmark_reprojection_px &&
         lm.p_b.norm() <= config_.sparse.max_landmark_range_m;
}

std::vector<std::vector<std::uint64_t>> MapBuilder::attachedLandmarks() const {
  std::vector<std::vector<std::uint64_t>> attached(store_.keyframes().size());
  for (const auto& [id, lm] : store_.landmarks()) {
    if (landmarkAccepted(lm)) attached[lm.keyframe].push_back(id);
  }
  return attached;
}

CameraCloud MapBuilder::pointsOf(std::size_t index, const Eigen::Isometry3d& T_target_b,
                                 const std::vector<std::vector<std::uint64_t>>& attached) const {
  const StoredKeyframe& kf = store_.keyframes()[index];
  CameraCloud out;
  if (kf.has_dense) {
    const Eigen::Isometry3d T_target_c = T_target_b * camera_.T_b_c;
    out.reserve(kf.dense_c.size());
    for (const auto& q : kf.dense_c) {
      out.push_back(makePoint(T_target_c * KeyframeStore::unpack(q).cast<double>(), q.intensity));
    }
  } else {
    for (const std::uint64_t id : attached[index]) {
      const StoredLandmark& lm = store_.landmarks().at(id);
      out.push_back(makePoint(T_target_b * lm.p_b, lm.intensity));
    }
  }
  return out;
}

MapBuildResult MapBuilder::build(const PoseLookup& pose_of) const {
  MapBuildResult result = buildClouds(pose_of);
  MapCounts scratch;
  occupancyInto(placedPoses(pose_of, scratch), result, nullptr);
  return result;
}

void MapBuilder::buildOccupancyReleasing(const PoseLookup& pose_of, MapBuildResult& into) {
  MapCounts scratch;  // the placement was counted by buildClouds
  occupancyInto(placedPoses(pose_of, scratch), into, &store_);
}

void MapBuilder::buildOccupancy(const PoseLookup& pose_of, MapBuildResult& into) const {
  MapCounts scratch;
  occupancyInto(placedPoses(pose_of, scratch), into, nullptr);
}

void MapBuilder::releaseDense() {
  for (std::size_t i = 0; i < store_.keyframes().size(); ++i) {
    if (store_.keyframes()[i].has_dense) store_.releaseDense(i);
  }
}

std::vector<std::optional<Eigen::Isometry3d>> MapBuilder::placedPoses(const PoseLookup& pose_of,
                                                                      MapCounts& counts) const {
  const auto& keyframes = store_.keyframes();
  std::vector<std::optional<Eigen::Isometry3d>> poses(keyframes.size());
  for (std::size_t i = 0; i < keyframes.size(); ++i) {
    poses[i] = pose_of(keyframes[i].t_ns);
    ++(poses[i] ? counts.keyframes_used : counts.keyframes_skipped);
  }
  return poses;
}

MapBuildResult MapBuilder::buildClouds(const PoseLookup& pose_of) const {
  MapBuildResult result;
  MapCounts& counts = result.counts;
  const auto& keyframes = store_.keyframes();
  counts.keyframes = keyframes.size();
  counts.landmarks_stored = store_.landmarks().size();
  counts.store_bytes = store_.memoryBytes();
  const auto poses = placedPoses(pose_of, counts);

  for (const auto& [id, lm] : store_.landmarks()) {
    if (!landmarkAccepted(lm)) {
      ++counts.landmarks_rejected;
    } else if (!poses[lm.keyframe]) {
      ++counts.landmarks_unplaced;
    } else {
      const Eigen::Vector3f p = (*poses[lm.keyframe] * lm.p_b).cast<float>();
      result.sparse.push_back(makeMapPoint(p.x(), p.y(), p.z(), lm.intensity,
                                           static_cast<std::uint32_t>(lm.observations),
                                           MapPointSource::kSparseLandmark));
    }
  }
  counts.sparse_points = result.sparse.size();

  DenseFusion fusion(config_.dense.voxel_size_m, config_.dense.sor_mean_k,
                     config_.dense.sor_stddev_mul);
  const std::vector<std::vector<std::uint64_t>> no_landmarks(keyframes.size());
  for (std::size_t i = 0; i < keyframes.size(); ++i) {
    if (poses[i] && keyframes[i].has_dense) fusion.add(pointsOf(i, *poses[i], no_landmarks));
  }
  counts.dense_points_raw = fusion.pointsAdded();
  const auto start = Clock::now();
  result.dense = fusion.finish();
  result.ms_dense_fusion = msSince(start);
  counts.dense_points_voxel = fusion.pointsAfterVoxel();
  counts.dense_points = result.dense.size();
  return result;
}

void MapBuilder::occupancyInto(const std::vector<std::optional<Eigen::Isometry3d>>& poses,
                               MapBuildResult& result, KeyframeStore* release) const {
  const auto& keyframes = store_.keyframes();
  const auto attached = attachedLandmarks();
  OccupancyBuilder occupancy(config_.occupancy);
  result.ms_octomap_per_keyframe.clear();
  for (std::size_t i = 0; i < keyframes.size(); ++i) {
    if (!poses[i]) continue;
    const CameraCloud points = pointsOf(i, *poses[i], attached);
    const auto start = Clock::now();
    occupancy.insert(points, *poses[i] * camera_.T_b_c.translation());
    result.ms_octomap_per_keyframe.push_back(msSince(start));
    if (release != nullptr && keyframes[i].has_dense) release->releaseDense(i);
  }
  auto trees = occupancy.finish();
  MapCounts& counts = result.counts;
  counts.occupied_leaves = 0;
  for (auto it = trees.occupancy->begin_leafs(); it != trees.occupancy->end_leafs(); ++it) {
    if (trees.occupancy->isNodeOccupied(*it)) ++counts.occupied_leaves;
  }
  counts.octree_bytes = trees.occupancy->memoryUsage();
  counts.color_octree_bytes = trees.color->memoryUsage();
  result.occupancy = std::move(trees.occupancy);
  result.occupancy_color = std::move(trees.color);
}

MapCloud MapBuilder::keyframePoints(std::int64_t t0_ns, std::int64_t t1_ns,
                                    const PoseLookup& pose_of) const {
  std::vector<std::size_t> indices;
  const auto& keyframes = store_.keyframes();
  for (std::size_t i = 0; i < keyframes.size(); ++i) {
    if (keyframes[i].t_ns >= t0_ns && keyframes[i].t_ns <= t1_ns) indices.push_back(i);
  }
  return keyframePoints(indices, pose_of);
}

MapCloud MapBuilder::keyframePoints(const std::vector<std::size_t>& indices,
                                    const PoseLookup& pose_of) const {
  const auto attached = attachedLandmarks();
  MapCloud out;
  const auto& keyframes = store_.keyframes();
  for (const std::size_t i : indices) {
    const auto pose = pose_of(keyframes.at(i).t_ns);
    if (!pose) continue;
    const auto source =
        keyframes[i].has_dense ? MapPointSource::kDenseStereo : MapPointSource::kSparseLandmark;
    for (const auto& p : pointsOf(i, *pose, attached)) {
      out.push_back(makeMapPoint(p.x, p.y, p.z, p.intensity, 0, source));
    }
  }
  return out;
}

PoseLookup MapBuilder::vioPoses() const {
  return [this](std::int64_t t_ns) -> std::optional<Eigen::Isometry3d> {
    const auto& keyframes = store_.keyframes();
    const auto it =
        std::lower_bound(keyframes.begin(), keyframes.end(), t_ns,
                         [](const StoredKeyframe& kf, std::int64_t t) { return kf.t_ns < t; });
    if (it == keyframes.end() || it->t_ns != t_ns) return std::nullopt;
    return it->T_w_b;
  };
}

}  // namespace gvio::mapping
