// mapping/map_correction.hpp: a map carried onto corrected keyframe poses, each point rigidly with
// the keyframe nearest to it in the plane.
#include <gtest/gtest.h>

#include "mapping/map_correction.hpp"
#include "odometry/error.hpp"

namespace gvio::mapping {
namespace {

TEST(MapCorrection, EachPointFollowsItsNearestKeyframe) {
  std::vector<Eigen::Isometry3d> old_poses, new_poses;
  for (int k = 0; k < 11; ++k) {  // a straight road along x, a keyframe every 10 m
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = Eigen::Vector3d(10.0 * k, 0.0, 1.5);
    old_poses.push_back(T);
    Eigen::Isometry3d moved = T;  // shifted 0.5 m north, and the last one also turned 1 deg
    moved.translation().y() += 0.5;
    if (k == 10) {
      moved.linear() = Eigen::AngleAxisd(M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    }
    new_poses.push_back(moved);
  }
  MapCorrection correction(old_poses, new_poses, 2.0);
  // A facade point 8 m beside keyframe 3: moved with it.
  const Eigen::Vector3d p(31.0, 8.0, 4.0);
  EXPECT_EQ(correction.keyframeAt(p), 3U);
  EXPECT_LT((correction.apply(p) - (p + Eigen::Vector3d(0, 0.5, 0))).norm(), 1e-12);
  // Beyond the last keyframe: turned about it, then shifted.
  const Eigen::Vector3d q(110.0, 10.0, 2.0);
  EXPECT_EQ(correction.keyframeAt(q), 10U);
  const Eigen::Vector3d expected = new_poses[10] * (old_poses[10].inverse() * q);
  EXPECT_LT((correction.apply(q) - expected).norm(), 1e-12);
  EXPECT_GT((correction.apply(q) - (q + Eigen::Vector3d(0, 0.5, 0))).norm(), 0.1);
  // Unchanged poses leave the map as it is.
  MapCorrection none(old_poses, old_poses);
  EXPECT_LT((none.apply(q) - q).norm(), 1e-12);
  EXPECT_THROW(MapCorrection({}, {}), InvalidInput);
  EXPECT_THROW(MapCorrection(old_poses, {}), InvalidInput);
}

}  // namespace
}  // namespace gvio::mapping
