#include "odometry/landmarks.hpp"

#include <Eigen/SVD>
#include <cmath>
#include <limits>

#include "odometry/pose_manifold.hpp"

namespace gvio::odometry {
namespace {

// Two rays closer than this angle (rad) triangulate too poorly to be worth a landmark.
constexpr double kMinTriangulationAngleRad = 1.0 * M_PI / 180.0;

Eigen::Isometry3d cameraInWorld(const double* pose, const PinholeView& view) {
  return poseFromBlock(pose) * view.T_b_c;
}

double reprojectionErrorPx(const PinholeView& view, const Eigen::Isometry3d& T_w_c,
                           const Eigen::Vector3d& p_w, const Eigen::Vector2d& px) {
  const Eigen::Vector3d p_c = T_w_c.inverse() * p_w;
  if (p_c.z() <= 1e-6) return INFINITY;
  const Eigen::Vector2d proj(view.fx * p_c.x() / p_c.z() + view.cx,
                             view.fy * p_c.y() / p_c.z() + view.cy);
  return (proj - px).norm();
}

}  // namespace

const Observation* Landmark::in(std::uint64_t frame_uid) const {
  for (const Observation& o : observations) {
    if (o.frame_uid == frame_uid) return &o;
  }
  return nullptr;
}

bool LandmarkMap::observe(std::uint64_t id, const Observation& obs) {
  auto it = landmarks_.find(id);
  if (it == landmarks_.end()) return false;
  std::vector<Observation>& seen = it->second.observations;
  Observation& anchor = seen.front();
  if (seen.size() == 1 && anchor.velocity_pxps.isZero(0.0)) {
    // A feature detected in its anchor frame has no image velocity there yet: it takes the one it
    // shows next (its displacement to the next frame), which the time-offset factors need for the
    // anchor's bearing too. That is the velocity half way to the next frame...
    anchor.velocity_pxps = obs.velocity_pxps;
    anchor.velocity_right_pxps = obs.velocity_right_pxps;
    anchor.velocity_from_t_ns = obs.t_ns;
  } else if (anchor.velocity_from_t_ns > anchor.t_ns && obs.t_ns > anchor.velocity_from_t_ns) {
    // ... carried back to the anchor's stamp through the next velocity (the tracker's estimate at
    // its frame): a constant image acceleration, as the tracker assumes.
    const double mid = 0.5 * static_cast<double>(anchor.t_ns + anchor.velocity_from_t_ns);
    const double w =
        (mid - static_cast<double>(anchor.t_ns)) / (static_cast<double>(obs.t_ns) - mid);
    anchor.velocity_pxps -= w * (obs.velocity_pxps - anchor.velocity_pxps);
    anchor.velocity_right_pxps -= w * (obs.velocity_right_pxps - anchor.velocity_right_pxps);
    anchor.velocity_from_t_ns = -1;
  }
  seen.push_back(obs);
  return true;
}

void LandmarkMap::create(std::uint64_t id, const Observation& obs, const StereoGeometry& geometry,
                         double min_depth_m, double max_depth_m) {
  Landmark lm;
  lm.id = id;
  lm.observations.push_back(obs);
  if (geometry.stereo && obs.has_right) {
    // Rectified pair: depth = f b / disparity.
    const double disparity = obs.px_left.x() - obs.px_right.x();
    if (disparity > 0.0) {
      const double depth = geometry.left.fx * geometry.baseline_m / disparity;
      if (depth >= min_depth_m && depth <= max_depth_m) {
        lm.inv_depth = 1.0 / depth;
        lm.has_depth = true;
      }
    }
  }
  landmarks_[id] = std::move(lm);
}

Eigen::Vector3d LandmarkMap::worldPoint(const Landmark& lm, const double* anchor_pose,
                                        const StereoGeometry& geometry, double t_d_s) {
  const Eigen::Vector3d p_c = geometry.bearing(lm.anchor().leftAt(t_d_s)) / lm.inv_depth;
  return cameraInWorld(anchor_pose, geometry.left) * p_c;
}

void LandmarkMap::triangulate(const PoseLookup& poses, const StereoGeometry& geometry, double t_d_s,
                              double min_depth_m, double max_depth_m) {
  for (auto& [id, lm] : landmarks_) {
    if (lm.has_depth || lm.observations.size() < 2) continue;
    const double* pose_a = poses(lm.anchor().frame_uid);
    const double* pose_b = poses(lm.observations.back().frame_uid);
    if (pose_a == nullptr || pose_b == nullptr) continue;
    const Eigen::Isometry3d T_w_a = cameraInWorld(pose_a, geometry.left);
    const Eigen::Isometry3d T_w_b = cameraInWorld(pose_b, geometry.left);
    const Eigen::Vector3d u_a = geometry.bearing(lm.anchor().leftAt(t_d_s));
    const Eigen::Vector3d u_b = geometry.bearing(lm.observations.back().leftAt(t_d_s));
    const Eigen::Vector3d ray_a = T_w_a.rotation() * u_a.normalized();
    const Eigen::Vector3d ray_b = T_w_b.rotation() * u_b.normalized();
    if (std::acos(std::clamp(ray_a.dot(ray_b), -1.0, 1.0)) < kMinTriangulationAngleRad) continue;
    // DLT (Hartley & Zisserman, sec. 12.2) in the anchor camera frame.
    const Eigen::Isometry3d T_b_a = T_w_b.inverse() * T_w_a;
    Eigen::Matrix4d A;
    const Eigen::Matrix<double, 3, 4> P_a = Eigen::Matrix<double, 3, 4>::Identity();
    const Eigen::Matrix<double, 3, 4> P_b = T_b_a.matrix().topRows<3>();
    A.row(0) = u_a.x() * P_a.row(2) - P_a.row(0);
    A.row(1) = u_a.y() * P_a.row(2) - P_a.row(1);
    A.row(2) = u_b.x() * P_b.row(2) - P_b.row(0);
    A.row(3) = u_b.y() * P_b.row(2) - P_b.row(1);
    const Eigen::Vector4d X =
        Eigen::JacobiSVD<Eigen::Matrix4d>(A, Eigen::ComputeFullV).matrixV().col(3);
    if (std::abs(X.w()) < 1e-12) continue;
    const double depth = X.z() / X.w();
    if (depth >= min_depth_m && depth <= max_depth_m) {
      lm.inv_depth = 1.0 / depth;
      lm.has_depth = true;
    }
  }
}

void LandmarkMap::removeFrame(std::uint64_t frame_uid, const PoseLookup& poses,
                              const StereoGeometry& geometry, double t_d_s) {
  for (auto it = landmarks_.begin(); it != landmarks_.end();) {
    Landmark& lm = it->second;
    const bool anchored_here = lm.anchor().frame_uid == frame_uid;
    Eigen::Vector3d p_w = Eigen::Vector3d::Zero();
    const double* old_anchor = anchored_here ? poses(frame_uid) : nullptr;
    const bool carry_depth = anchored_here && lm.has_depth && old_anchor != nullptr;
    if (carry_depth) p_w = worldPoint(lm, old_anchor, geometry, t_d_s);
    std::erase_if(lm.observations,
                  [frame_uid](const Observation& o) { return o.frame_uid == frame_uid; });
    if (lm.observations.empty()) {
      it = landmarks_.erase(it);
      continue;
    }
    if (anchored_here) {
      lm.has_depth = false;
      const double* new_anchor = poses(lm.anchor().frame_uid);
      if (carry_depth && new_anchor != nullptr) {
        // The depth along the new anchor's (time-shifted) bearing that reproduces the point.
        const Eigen::Vector3d p_c = cameraInWorld(new_anchor, geometry.left).inverse() * p_w;
        if (p_c.z() > 1e-3) {
          lm.inv_depth = 1.0 / p_c.z();
          lm.has_depth = true;
        }
      }
    }
    ++it;
  }
}

double LandmarkMap::meanReprojectionPx(const Landmark& lm, const PoseLookup& poses,
                                       const StereoGeometry& geometry, double t_d_s) {
  const double* anchor_pose = lm.has_depth ? poses(lm.anchor().frame_uid) : nullptr;
  if (anchor_pose == nullptr) return INFINITY;
  const Eigen::Vector3d p_w = worldPoint(lm, anchor_pose, geometry, t_d_s);
  double sum = 0.0;
  int n = 0;
  for (const Observation& o : lm.observations) {
    const double* pose = poses(o.frame_uid);
    if (pose == nullptr) continue;
    sum += reprojectionErrorPx(geometry.left, cameraInWorld(pose, geometry.left), p_w,
                               o.leftAt(t_d_s));
    ++n;
    if (o.has_right && geometry.stereo) {
      sum += reprojectionErrorPx(geometry.right, cameraInWorld(pose, geometry.right), p_w,
                                 o.rightAt(t_d_s));
      ++n;
    }
  }
  return n > 0 ? sum / n : std::numeric_limits<double>::infinity();
}

int LandmarkMap::rejectOutliers(const PoseLookup& poses, const StereoGeometry& geometry,
                                double t_d_s, double max_px, double min_depth_m,
                                double max_depth_m) {
  int removed = 0;
  for (auto it = landmarks_.begin(); it != landmarks_.end();) {
    Landmark& lm = it->second;
    if (!lm.has_depth) {
      ++it;
      continue;
    }
    const double depth = 1.0 / lm.inv_depth;
    const double* anchor_pose = poses(lm.anchor().frame_uid);
    if (!std::isfinite(depth) || depth < min_depth_m || depth > max_depth_m ||
        anchor_pose == nullptr) {
      lm.has_depth = false;
      ++it;
      continue;
    }
    const Eigen::Vector3d p_w = worldPoint(lm, anchor_pose, geometry, t_d_s);
    bool anchor_bad = false;
    std::vector<Observation> kept;
    for (std::size_t k = 0; k < lm.observations.size(); ++k) {
      const Observation& o = lm.observations[k];
      const double* pose = poses(o.frame_uid);
      bool good = pose != nullptr;
      if (good) {
        good = reprojectionErrorPx(geometry.left, cameraInWorld(pose, geometry.left), p_w,
                                   o.leftAt(t_d_s)) <= max_px;
      }
      Observation copy = o;
      if (good && o.has_right && geometry.stereo &&
          reprojectionErrorPx(geometry.right, cameraInWorld(pose, geometry.right), p_w,
                              o.rightAt(t_d_s)) > max_px) {
        copy.has_right = false;  // keep the left observation, drop the bad stereo match
        ++removed;
      }
      if (!good) {
        ++removed;
        if (k == 0) anchor_bad = true;
        continue;
      }
      kept.push_back(copy);
    }
    if (anchor_bad || kept.empty()) {
      it = landmarks_.erase(it);
      continue;
    }
    lm.observations = std::move(kept);
    ++it;
  }
  return removed;
}

int LandmarkMap::countObservedWithDepth(std::uint64_t frame_uid) const {
  int n = 0;
  for (const auto& [id, lm] : landmarks_) {
    if (lm.has_depth && lm.in(frame_uid) != nullptr) ++n;
  }
  return n;
}

}  // namespace gvio::odometry
