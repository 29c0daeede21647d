#pragma once
// What the map keeps of each keyframe so that the whole map can be rebuilt from corrected poses:
// the keyframe's VIO pose and time, its dense points in its own LEFT CAMERA frame, and the sparse
// landmarks, each attached to the latest keyframe that saw it and stored in that keyframe's BODY
// frame (p_b = T_w_b^-1 p_w). A corrected keyframe pose T_target_b therefore re-places both
// rigidly; nothing in the store is expressed in a world frame that could go stale.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>
#include <map>
#include <vector>

#include "mapping/stereo_depth.hpp"

namespace gvio::mapping {

// A dense point in its keyframe's camera frame, millimetre int16 coordinates (+-32.7 m, so the
// dense range is capped at 32 m) and 8-bit intensity: 8 bytes instead of pcl::PointXYZI's 32.
// KITTI-00 (~1500 keyframes of ~30 k points at 0.1 m) then needs ~0.4 GB instead of ~1.4 GB.
struct PackedPoint {
  std::int16_t x_mm = 0, y_mm = 0, z_mm = 0;
  std::uint8_t intensity = 0;
  std::uint8_t unused = 0;
};

struct StoredKeyframe {
  std::int64_t t_ns = 0;
  Eigen::Isometry3d T_w_b = Eigen::Isometry3d::Identity();  // VIO pose when it was added
  bool has_dense = false;
  std::vector<PackedPoint> dense_c;  // left camera frame
};

struct StoredLandmark {
  std::size_t keyframe = 0;                       // index of the latest keyframe that saw it
  Eigen::Vector3d p_b = Eigen::Vector3d::Zero();  // in that keyframe's body frame
  int observations = 0;
  double mean_reprojection_px = 0.0;
  float intensity = 0.0f;  // grey value 0..255 where it last projected into a left image
};

class KeyframeStore {
 public:
  // Appends a keyframe; returns its index. Times must increase (throws InvalidInput otherwise).
  std::size_t addKeyframe(std::int64_t t_ns, const Eigen::Isometry3d& T_w_b);
  // Dense points of keyframe `index` (left camera frame); points beyond +-32.7 m are dropped.
  void setDense(std::size_t index, const CameraCloud& points_c);
  // Frees keyframe `index`'s dense points (after the map has used them); it then contributes its
  // landmarks only, like a keyframe without depth.
  void releaseDense(std::size_t index);
  // Attaches landmark `id` to keyframe `index` with this estimate when it rests on at least as
  // many window observations as the stored one: as frames leave the sliding window a landmark
  // loses observations, so its last estimates (one or two frames) are its weakest and would hide
  // how well it was once seen. `intensity` < 0 keeps the previous intensity (the landmark did
  // not project into this keyframe's image).
  void updateLandmark(std::uint64_t id, std::size_t index, const Eigen::Vector3d& p_b,
                      int observations, double mean_reprojection_px, float intensity);

  [[nodiscard]] const std::vector<StoredKeyframe>& keyframes() const { return keyframes_; }
  [[nodiscard]] const std::map<std::uint64_t, StoredLandmark>& landmarks() const {
    return landmarks_;
  }
  [[nodiscard]] std::size_t densePointCount() const { return dense_points_; }
  // Approximate heap bytes held (dense points + landmarks + keyframe records).
  [[nodiscard]] std::size_t memoryBytes() const;

  [[nodiscard]] static PackedPoint pack(const pcl::PointXYZI& p_c);
  [[nodiscard]] static Eigen::Vector3f unpack(const PackedPoint& p);

 private:
  std::vector<StoredKeyframe> keyframes_;
  std::map<std::uint64_t, StoredLandmark> landmarks_;
  std::size_t dense_points_ = 0;
};

}  // namespace gvio::mapping
