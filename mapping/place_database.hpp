#pragma once
// A run's place database: what a later alignment with other drives needs of its keyframes (gvio
// merge's joint alignment, issue 18), kept after the run instead of freed. Per keyframe its loop
// features (mapping/loop_features.hpp: ORB descriptors, stereo 3-D points, thumbnail), its VIO
// pose (the relative factors and the tilt of the joint graph) and its final pose in the run's ENU
// frame (the pose its map points were placed with); the GNSS fixes the run's global graph used
// and the run's own loops that graph kept. With these, one graph over several drives is the
// union of their graphs plus the loops between them.
#include <Eigen/Geometry>
#include <vector>

#include "fusion/global_graph.hpp"
#include "mapping/loop_closure.hpp"
#include "mapping/loop_features.hpp"
#include "odometry/measurements.hpp"

namespace gvio::mapping {

struct PlaceDatabase {
  CameraModel camera;  // the rectified left camera of every keyframe (pinhole), with T_b_c
  bool has_imu = false;
  std::vector<LoopKeyframe> keyframes;
  // Parallel to keyframes: t_ns, T_ref_b = the final pose in the run's ENU frame, sigma_m (its
  // GNSS-fused 1-sigma position uncertainty before the loops), path_m; segment 0.
  std::vector<KeyframePrior> priors;
  std::vector<Eigen::Isometry3d> T_vio;  // parallel: the VIO poses
  std::vector<fusion::GraphFix> fixes;   // node = keyframe index, p_enu in the run's ENU frame
  std::vector<fusion::GraphLoop> loops;  // the run's accepted loops its global graph kept
};

}  // namespace gvio::mapping
