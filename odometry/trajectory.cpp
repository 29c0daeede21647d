#include "odometry/trajectory.hpp"

namespace gvio {

double pathLengthM(const Trajectory& traj) {
  double length_m = 0.0;
  for (std::size_t i = 1; i < traj.poses.size(); ++i) {
    length_m += (traj.poses[i].translation() - traj.poses[i - 1].translation()).norm();
  }
  return length_m;
}

std::int64_t firstNonIncreasingStamp(const Trajectory& traj) {
  for (std::size_t i = 1; i < traj.t_ns.size(); ++i) {
    if (traj.t_ns[i] <= traj.t_ns[i - 1]) return static_cast<std::int64_t>(i);
  }
  return -1;
}

}  // namespace gvio
