#include "mapping/keyframe_store.hpp"

#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "odometry/error.hpp"

namespace gvio::mapping {
namespace {

constexpr float kMmPerM = 1000.0f;
constexpr float kMaxAbs_mm = std::numeric_limits<std::int16_t>::max();

bool packable(float v_m) {
  return std::isfinite(v_m) && std::abs(v_m * kMmPerM) <= kMaxAbs_mm;
}

std::int16_t toMm(float v_m) {
  return static_cast<std::int16_t>(std::lround(v_m * kMmPerM));
}

}  // namespace

std::size_t KeyframeStore::addKeyframe(std::int64_t t_ns, const Eigen::Isometry3d& T_w_b) {
  if (!keyframes_.empty() && t_ns <= keyframes_.back().t_ns) {
    throw InvalidInput("keyframe store: keyframe times must increase (got " + std::to_string(t_ns) +
                       " ns after " + std::to_string(keyframes_.back().t_ns) + " ns)");
  }
  StoredKeyframe kf;
  kf.t_ns = t_ns;
  kf.T_w_b = T_w_b;
  keyframes_.push_back(std::move(kf));
  return keyframes_.size() - 1;
}

void KeyframeStore::releaseDense(std::size_t index) {
  StoredKeyframe& kf = keyframes_.at(index);
  dense_points_ -= kf.dense_c.size();
  std::vector<PackedPoint>().swap(kf.dense_c);
  kf.has_dense = false;
}

void KeyframeStore::setDense(std::size_t index, const CameraCloud& points_c) {
  StoredKeyframe& kf = keyframes_.at(index);
  dense_points_ -= kf.dense_c.size();
  kf.dense_c.clear();
  kf.dense_c.reserve(points_c.size());
  for (const auto& p : points_c) {
    if (packable(p.x) && packable(p.y) && packable(p.z)) kf.dense_c.push_back(pack(p));
  }
  kf.dense_c.shrink_to_fit();
  kf.has_dense = true;
  dense_points_ += kf.dense_c.size();
}

void KeyframeStore::updateLandmark(std::uint64_t id, std::size_t index, const Eigen::Vector3d& p_b,
                                   int observations, double mean_reprojection_px, float intensity) {
  const auto [it, inserted] = landmarks_.try_emplace(id);
  StoredLandmark& lm = it->second;
  if (!inserted && observations < lm.observations) return;
  lm.keyframe = index;
  lm.p_b = p_b;
  lm.observations = observations;
  lm.mean_reprojection_px = mean_reprojection_px;
  if (intensity >= 0.0f) lm.intensity = intensity;
}

std::size_t KeyframeStore::memoryBytes() const {
  // std::map nodes: the value plus three pointers and a colour word.
  const std::size_t landmark_node = sizeof(std::pair<const std::uint64_t, StoredLandmark>) + 32;
  return keyframes_.capacity() * sizeof(StoredKeyframe) + dense_points_ * sizeof(PackedPoint) +
         landmarks_.size() * landmark_node;
}

PackedPoint KeyframeStore::pack(const pcl::PointXYZI& p_c) {
  PackedPoint q;
  q.x_mm = toMm(p_c.x);
  q.y_mm = toMm(p_c.y);
  q.z_mm = toMm(p_c.z);
  const float i = std::round(p_c.intensity);
  q.intensity = static_cast<std::uint8_t>(i < 0.0f ? 0.0f : (i > 255.0f ? 255.0f : i));
  return q;
}

Eigen::Vector3f KeyframeStore::unpack(const PackedPoint& p) {
  return Eigen::Vector3f(p.x_mm, p.y_mm, p.z_mm) / kMmPerM;
}

}  // namespace gvio::mapping
