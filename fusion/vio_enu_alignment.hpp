#pragma once
// Registration of the VIO world frame to local ENU from pairs of positions (the antenna by VIO,
// the same antenna by GNSS). With an IMU the VIO world is gravity-aligned, so only yaw and a
// translation are free (4 DoF, closed form); without one the full rotation is estimated
// (Umeyama 1991, no scale).
#include <Eigen/Geometry>
#include <optional>
#include <vector>

#include "odometry/trajectory.hpp"

namespace gvio::fusion {

enum class AlignmentDof { kYawTranslation, kRotationTranslation };

// T_enu_w mapping VIO-world positions onto ENU in the least-squares sense; nullopt with fewer
// than 3 pairs or when the pairs span less than `min_extent_m` (the yaw is not determined).
// kRotationTranslation needs the VIO positions to spread across the path too: along a straight
// path the roll about it is unobservable, and a few noisy fixes then tilt the whole trajectory
// by tens of degrees. While the spread across the principal direction (standard deviation) is
// below `min_cross_extent_m`, the yaw + translation solution is returned instead: it assumes the
// VIO world's z axis is near up, which holds for a vehicle's stereo-only VIO (its world is the
// first body frame); callers check the residuals (alignmentConsistent) before trusting it.
std::optional<Eigen::Isometry3d> alignVioToEnu(const std::vector<Eigen::Vector3d>& p_w,
                                               const std::vector<Eigen::Vector3d>& p_enu,
                                               AlignmentDof dof, double min_extent_m = 10.0,
                                               double min_cross_extent_m = 0.0);

// Standard deviation of the positions across their principal direction (sqrt of the second
// eigenvalue of their covariance), 0 with fewer than 2 positions.
double crossExtent(const std::vector<Eigen::Vector3d>& p);

// Pose of a trajectory at t_ns: linear in position, slerp in rotation between the two poses around
// it; nullopt outside the trajectory or across a gap longer than max_gap_ns.
std::optional<Eigen::Isometry3d> interpolatePose(const Trajectory& traj, std::int64_t t_ns,
                                                 std::int64_t max_gap_ns = 500'000'000);

}  // namespace gvio::fusion
