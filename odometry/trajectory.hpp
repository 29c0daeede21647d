#pragma once
// A stamped sequence of rigid poses T_w_b (body in some world frame), the unit of exchange between
// estimator, evaluation and export.
#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

namespace gvio {

struct Trajectory {
  // Empty when the source has no timestamps (a KITTI pose file without a times file).
  std::vector<std::int64_t> t_ns;
  std::vector<Eigen::Isometry3d> poses;

  [[nodiscard]] std::size_t size() const { return poses.size(); }
  [[nodiscard]] bool empty() const { return poses.empty(); }
  [[nodiscard]] bool hasTimestamps() const { return !t_ns.empty(); }
};

// Sum of the distances between consecutive positions, in metres.
double pathLengthM(const Trajectory& traj);

// Index of the first pose whose timestamp is not strictly greater than its predecessor's,
// or -1 when the stamps increase strictly (or there are none).
std::int64_t firstNonIncreasingStamp(const Trajectory& traj);

}  // namespace gvio
