#pragma once
// Geometric verification of a loop candidate (VINS-Mono / ORB-SLAM class): the candidate's ORB
// descriptors with 3-D points are matched to the query's keypoints (Hamming distance, Lowe's ratio
// test, one match per query keypoint), then PnP-RANSAC (AP3P minimal sets) gives the query camera
// in the candidate camera's frame, refined by Levenberg-Marquardt on the inliers. Its covariance
// comes from the inliers' reprojection Jacobians scaled by their residual variance, carried to the
// body frames; it weights the loop in the global pose graph.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <limits>
#include <string>

#include "mapping/loop_features.hpp"
#include "odometry/measurements.hpp"

namespace gvio::mapping {

struct LoopMatchConfig {
  int max_hamming = 64;  // descriptor distance of a match, bits of 256 (ORB-SLAM: 50-100)
  double ratio = 0.8;    // best / second best distance (Lowe 2004)
  int min_inliers = 25;  // PnP-RANSAC inliers (VINS-Mono: 25)
  double ransac_threshold_px = 2.0;  // inlier reprojection error
  int ransac_iterations = 300;
  double max_reprojection_px = 1.5;  // mean over the inliers after refinement
  void validate() const;             // throws InvalidInput naming the key
};

// Why a candidate failed verification; kOk when it passed.
enum class LoopCheck { kOk, kNoPoints, kFewMatches, kPnpFailed, kFewInliers, kReprojection };
std::string toString(LoopCheck check);  // ok | no_points | few_matches | pnp_failed | ...

using Matrix6d = Eigen::Matrix<double, 6, 6>;

struct LoopMeasurement {
  LoopCheck check = LoopCheck::kNoPoints;
  int matches = 0;  // after the ratio test and the one-to-one rule
  int inliers = 0;  // PnP inliers after refinement (0 when PnP did not run)
  double reprojection_px = std::numeric_limits<double>::quiet_NaN();  // mean over the inliers
  // Query body in the candidate body's frame, T_bc_bq = T_bc^-1 T_bq (valid when check is kOk),
  // and the covariance of its error as fusion::RelativePoseFactor states it (rotation on the
  // right (rad), then translation in the candidate's frame (m)).
  Eigen::Isometry3d T_cand_query = Eigen::Isometry3d::Identity();
  Matrix6d covariance = Matrix6d::Identity();
};

// `camera` is the rectified left camera of both keyframes (T_b_c its pose in the body).
LoopMeasurement verifyLoop(const LoopKeyframe& query, const LoopKeyframe& candidate,
                           const CameraModel& camera, const LoopMatchConfig& config);

}  // namespace gvio::mapping
