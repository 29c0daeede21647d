// `--orientation motion` on a real drive's poses: KITTI-00's ground truth (../shared/data/kitti00)
// loaded as `gvio simulate` loads it, its orientation derived from the path and compared with the
// file's own. The figures docs/cli/simulate.md gives come from this test's output.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include "io/trajectory_io.hpp"
#include "sim/body_orientation.hpp"
#include "sim/kitti_convention.hpp"
#include "sim/sim_config.hpp"
#include "support/fixtures.hpp"

namespace gvio::sim {
namespace {

constexpr double kDeg = 180.0 / std::numbers::pi;

// Yaw (about up), pitch (nose up) and roll (about forward) of a body in ENU (Z-Y-X angles), deg.
Eigen::Vector3d yawPitchRollDeg(const Eigen::Matrix3d& R_w_b) {
  const double yaw = std::atan2(R_w_b(1, 0), R_w_b(0, 0));
  const double pitch = -std::asin(std::clamp(R_w_b(2, 0), -1.0, 1.0));
  const double roll = std::atan2(R_w_b(2, 1), R_w_b(2, 2));
  return Eigen::Vector3d(yaw, pitch, roll) * kDeg;
}

double wrapDeg(double a) {
  return std::remainder(a, 360.0);
}

double quantile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))];
}

TEST(SimOrientationKitti, MotionAgreesWithTheFilesHeading) {
  const std::filesystem::path data = test::sharedData("kitti00");
  if (data.empty()) GTEST_SKIP() << "shared data absent: ../shared/data/kitti00";
  const SimConfig config;  // the simulator's defaults: heading, spline
  const Trajectory file = kittiCameraToEnuBody(
      io::readTrajectory(data / "KITTI_00_gt.txt", io::TrajectoryFormat::kKitti,
                         data / "KITTI_00_gt_times.txt"),
      config.heading_deg);
  MotionOrientationOptions motion;
  motion.fit = {config.knot_spacing_s, config.smoothing};
  const Trajectory derived = orientationFromMotion(file, motion);
  ASSERT_EQ(derived.size(), file.size());

  std::vector<double> yaw, pitch, roll;
  for (std::size_t i = 0; i < file.size(); ++i) {
    const Eigen::Vector3d a = yawPitchRollDeg(file.poses[i].linear());
    const Eigen::Vector3d b = yawPitchRollDeg(derived.poses[i].linear());
    yaw.push_back(std::abs(wrapDeg(b.x() - a.x())));
    pitch.push_back(std::abs(b.y() - a.y()));
    roll.push_back(std::abs(b.z() - a.z()));
  }
  // Where the heading differs by more than 10 deg: seconds since the start, one per second.
  std::string far;
  for (std::size_t i = 0, last = 1u << 30; i < file.size(); ++i) {
    const auto second = static_cast<std::size_t>((file.t_ns[i] - file.t_ns[0]) / 1'000'000'000);
    if (yaw[i] > 10.0 && second != last) far += " " + std::to_string(last = second);
  }
  const auto check = checkForwardAxis(file, motion.fit);
  ASSERT_TRUE(check);
  std::printf(
      "KITTI-00, motion against the file: yaw median %.2f deg, p95 %.2f, max %.1f; pitch median "
      "%.2f deg; roll median %.2f deg; the file's x axis %.1f deg (median) from travel; yaw off by "
      "more "
      "than 10 deg at%s s\n",
      quantile(yaw, 0.5), quantile(yaw, 0.95), quantile(yaw, 1.0), quantile(pitch, 0.5),
      quantile(roll, 0.5), check->x_median_deg, far.c_str());
  // The path gives the heading to within a degree or so; pitch and roll differ by the car's own
  // attitude on the road (a path alone has no cross slope).
  EXPECT_LT(quantile(yaw, 0.5), 1.0);
  EXPECT_LT(quantile(yaw, 0.95), 5.0);
  EXPECT_LT(quantile(pitch, 0.5), 3.0);
  EXPECT_LT(quantile(roll, 0.5), 3.0);
  EXPECT_LT(check->x_median_deg, kForwardAxisWarnDeg);  // no warning on a vehicle's own file
}

}  // namespace
}  // namespace gvio::sim
