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
std::optional<Eigen::Isometry3d> alignVioToEnu(const std::vector<Eigen::Vector3d>& p_w,
                                               const std::vector<Eigen::Vector3d>& p_enu,
                                               AlignmentDof dof, double min_extent_m = 10.0);

// Pose of a trajectory at t_ns: linear in position, slerp in rotation between the two poses around
// it; nullopt outside the trajectory or across a gap longer than max_gap_ns.
std::optional<Eigen::Isometry3d> interpolatePose(const Trajectory& traj, std::int64_t t_ns,
                                                 std::int64_t max_gap_ns = 500'000'000);

}  // namespace gvio::fusion
