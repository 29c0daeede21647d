#include "support/true_motion.hpp"

#include <algorithm>
#include <map>

namespace gvio::test {

std::vector<double> trueMotionErrors(const io::Dataset& dataset,
                                     const std::vector<odometry::TrackedFrame>& tracked) {
  const CameraModel& cam = dataset.cameras.at(0);
  const double baseline =
      (dataset.cameras.at(1).T_b_c.translation() - cam.T_b_c.translation()).norm();
  const Trajectory& gt = *dataset.groundtruth;
  // True camera-to-world pose of the left camera at frame k; at(): a frame without a truth pose
  // throws instead of reading past the end.
  const auto cameraPose = [&](std::size_t k) {
    const auto it = std::find(gt.t_ns.begin(), gt.t_ns.end(), dataset.frames.at(k).t_ns);
    return gt.poses.at(static_cast<std::size_t>(it - gt.t_ns.begin())) * cam.T_b_c;
  };
  std::vector<double> errors;
  for (std::size_t k = 0; k + 1 < tracked.size(); ++k) {
    const Eigen::Isometry3d T_next_cur = cameraPose(k + 1).inverse() * cameraPose(k);
    std::map<std::uint64_t, Eigen::Vector2d> next;
    for (const odometry::Feature& f : tracked[k + 1].features) next[f.id] = f.px_left;
    for (const odometry::Feature& f : tracked[k].features) {
      const auto it = next.find(f.id);
      const double disparity = f.px_left.x() - f.px_right.x();
      // Below 2 px the depth (and with it the prediction) is too uncertain to judge the track.
      if (!f.has_right || disparity < 2.0 || it == next.end()) continue;
      const double z = cam.fx * baseline / disparity;
      const Eigen::Vector3d p_cur((f.px_left.x() - cam.cx) / cam.fx * z,
                                  (f.px_left.y() - cam.cy) / cam.fy * z, z);
      const Eigen::Vector3d p = T_next_cur * p_cur;
      const Eigen::Vector2d predicted(cam.fx * p.x() / p.z() + cam.cx,
                                      cam.fy * p.y() / p.z() + cam.cy);
      errors.push_back((predicted - it->second).norm());
    }
  }
  return errors;
}

}  // namespace gvio::test
