#pragma once
// Landmarks of the sliding window: feature observations grouped by tracker id, each landmark
// anchored in the first window frame that observed it, with its inverse depth there (the Ceres
// parameter). Node-based storage keeps every inverse depth at a stable address for Ceres.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <functional>
#include <map>
#include <vector>

#include "odometry/reprojection_factor.hpp"
#include "odometry/time_offset_factor.hpp"

namespace gvio::odometry {

struct Observation {
  std::uint64_t frame_uid = 0;
  Eigen::Vector2d px_left = Eigen::Vector2d::Zero();
  bool has_right = false;
  Eigen::Vector2d px_right = Eigen::Vector2d::Zero();
  Eigen::Vector2d velocity_pxps = Eigen::Vector2d::Zero();        // left image, px/s (tracker's)
  Eigen::Vector2d velocity_right_pxps = Eigen::Vector2d::Zero();  // right image
  std::int64_t t_ns = 0;                                          // the frame's stamp
  // >= 0 while the velocities are provisional: a feature new in this frame took the backward
  // difference it showed at the frame stamped here, i.e. its velocity half way there.
  std::int64_t velocity_from_t_ns = -1;
  // The t_d (s) its frame's state was re-timed by: the state belongs to the stamp minus this
  // (WindowFrame::retime_ns), so only the rest of t_d is left to the pixel's motion.
  double t_d_base_s = 0.0;

  // Where the feature is at its frame's state time when the stamps lag the exposures by t_d (s):
  // the first-order shift z + (t_d - t_d_base) V of the time-offset factors (Qin and Shen 2018).
  // Every geometric use of an observation (triangulation, outlier test, re-anchoring) must see the
  // same pixel as the solver, or it rejects exactly the fast-moving features that make t_d
  // observable.
  [[nodiscard]] Eigen::Vector2d leftAt(double t_d_s) const {
    return px_left + (t_d_s - t_d_base_s) * velocity_pxps;
  }
  [[nodiscard]] Eigen::Vector2d rightAt(double t_d_s) const {
    return px_right + (t_d_s - t_d_base_s) * velocity_right_pxps;
  }
  // The same as the factors take it: pixel at t_d = 0 and velocity (z(t_d) = px + t_d V).
  [[nodiscard]] MovingPixel movingLeft() const {
    return {px_left - t_d_base_s * velocity_pxps, velocity_pxps};
  }
  [[nodiscard]] MovingPixel movingRight() const {
    return {px_right - t_d_base_s * velocity_right_pxps, velocity_right_pxps};
  }
};

struct Landmark {
  std::uint64_t id = 0;
  std::vector<Observation> observations;  // time order; [0] is the anchor
  double inv_depth = 0.0;                 // 1/m along the anchor's left-camera z axis
  bool has_depth = false;

  [[nodiscard]] const Observation& anchor() const { return observations.front(); }
  [[nodiscard]] const Observation* in(std::uint64_t frame_uid) const;
};

// Camera geometry shared by the window: rectified left (and right) pinhole views.
struct StereoGeometry {
  PinholeView left;
  PinholeView right;  // valid when stereo
  bool stereo = false;
  double baseline_m = 0.0;

  [[nodiscard]] Eigen::Vector3d bearing(const Eigen::Vector2d& px) const {
    return {(px.x() - left.cx) / left.fx, (px.y() - left.cy) / left.fy, 1.0};
  }
};

// Pose lookup of a window frame by uid (body in world); returns nullptr if not in the window.
using PoseLookup = std::function<const double*(std::uint64_t frame_uid)>;

class LandmarkMap {
 public:
  std::map<std::uint64_t, Landmark>& all() { return landmarks_; }
  [[nodiscard]] const std::map<std::uint64_t, Landmark>& all() const { return landmarks_; }

  // Appends an observation to an existing landmark; returns false when the id is unknown.
  bool observe(std::uint64_t id, const Observation& obs);
  // Creates a landmark anchored at obs (depth from the stereo disparity when in range).
  void create(std::uint64_t id, const Observation& obs, const StereoGeometry& geometry,
              double min_depth_m, double max_depth_m);

  // World point of a landmark with depth (its anchor pixel at the stamp for the time offset t_d).
  [[nodiscard]] static Eigen::Vector3d worldPoint(const Landmark& lm, const double* anchor_pose,
                                                  const StereoGeometry& geometry, double t_d_s);
  // Landmarks without depth (mono, or no stereo match) seen from two poses with enough parallax
  // get a depth by linear triangulation (DLT) of the anchor and latest observations.
  void triangulate(const PoseLookup& poses, const StereoGeometry& geometry, double t_d_s,
                   double min_depth_m, double max_depth_m);

  // Removes every observation of a frame that leaves the window. Landmarks anchored there are
  // re-anchored to their next observation (depth carried over from the current estimate:
  // VINS-Mono's removeBackShiftDepth); landmarks left without observations are erased.
  void removeFrame(std::uint64_t frame_uid, const PoseLookup& poses, const StereoGeometry& geometry,
                   double t_d_s);
  // Every function taking t_d_s (the camera-IMU time offset, 0 when not estimated) measures the
  // observations at the stamps, Observation::leftAt(t_d_s).
  // Drops observations whose reprojection error exceeds max_px (a bad anchor drops the landmark)
  // and depths out of range. Returns the number of observations removed.
  int rejectOutliers(const PoseLookup& poses, const StereoGeometry& geometry, double t_d_s,
                     double max_px, double min_depth_m, double max_depth_m);
  // Mean reprojection error (px) of a landmark with depth over its window observations, left and
  // right images (a stereo match counts as a second observation); infinity when none can be
  // projected. The map's sparse filter (mapping::SparseConfig) uses it.
  [[nodiscard]] static double meanReprojectionPx(const Landmark& lm, const PoseLookup& poses,
                                                 const StereoGeometry& geometry, double t_d_s);
  // Number of landmarks with depth that are observed in frame_uid.
  [[nodiscard]] int countObservedWithDepth(std::uint64_t frame_uid) const;
  void clear() { landmarks_.clear(); }

 private:
  std::map<std::uint64_t, Landmark> landmarks_;
};

}  // namespace gvio::odometry
