// The map's poses at each keyframe's exposure (run/map_run.hpp mapPoses): with a camera whose
// stamps lag its exposures by t_d, the points of a keyframe are placed with the body's pose t_d
// before its stamp, from the final trajectory when there is one, else from the VIO's.
#include <gtest/gtest.h>

#include "run/map_run.hpp"

namespace gvio::run {
namespace {

// Straight along x at 10 m/s, turning at 0.5 rad/s, poses every 100 ms from t = 1 s.
Trajectory drive(double offset_y_m) {
  Trajectory t;
  for (int k = 0; k <= 10; ++k) {
    const double s = 0.1 * k;
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::AngleAxisd(0.5 * s, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    T.translation() = Eigen::Vector3d(10.0 * s, offset_y_m, 0.0);
    t.t_ns.push_back(1'000'000'000 + 100'000'000LL * k);
    t.poses.push_back(T);
  }
  return t;
}

TEST(MapPoses, KeyframesArePlacedAtTheirExposures) {
  const MapRecorder recorder{mapping::MapConfig{}};  // no keyframe: only the trajectories are read
  const Trajectory fused = drive(0.0);
  const Trajectory vio = drive(5.0);
  const std::int64_t stamp = 1'300'000'000;

  const auto lagged = mapPoses(recorder, MapPoseSource{&fused, &vio, 0.02});
  const auto at_stamp = mapPoses(recorder, MapPoseSource{&fused, &vio, 0.0});
  ASSERT_TRUE(lagged(stamp) && at_stamp(stamp));
  EXPECT_NEAR(at_stamp(stamp)->translation().x(), 3.0, 1e-12);
  EXPECT_NEAR(lagged(stamp)->translation().x(), 2.8, 1e-9);   // 20 ms earlier at 10 m/s
  EXPECT_NEAR(lagged(stamp)->translation().y(), 0.0, 1e-12);  // the fused trajectory first
  const double yaw = Eigen::AngleAxisd(lagged(stamp)->rotation()).angle();
  EXPECT_NEAR(yaw, 0.5 * 0.28, 1e-9);

  // Without a final trajectory: the VIO's, at the exposure as well.
  const auto vio_only = mapPoses(recorder, MapPoseSource{nullptr, &vio, 0.02});
  ASSERT_TRUE(vio_only(stamp));
  EXPECT_NEAR(vio_only(stamp)->translation().x(), 2.8, 1e-9);
  EXPECT_NEAR(vio_only(stamp)->translation().y(), 5.0, 1e-12);

  // A first keyframe whose exposure precedes the trajectory keeps its stamp's pose; a negative
  // lag (stamps ahead of the exposures) looks later.
  ASSERT_TRUE(lagged(1'000'000'000));
  EXPECT_NEAR(lagged(1'000'000'000)->translation().x(), 0.0, 1e-12);
  const auto leading = mapPoses(recorder, MapPoseSource{&fused, &vio, -0.02});
  EXPECT_NEAR(leading(stamp)->translation().x(), 3.2, 1e-9);
  // Outside both: nothing.
  EXPECT_FALSE(lagged(5'000'000'000));
}

}  // namespace
}  // namespace gvio::run
