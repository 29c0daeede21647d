// The window landmarks' mean reprojection error (LandmarkMap::meanReprojectionPx), which the map's
// sparse filter relies on: exact pixels give 0, a known pixel offset gives its share of the mean.
#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "odometry/landmarks.hpp"
#include "odometry/pose_manifold.hpp"
#include "support/stereo_rig.hpp"

namespace gvio::odometry {
namespace {

using test::project;
using test::stereoRig;

class LandmarkReprojection : public ::testing::Test {
 protected:
  void SetUp() override {
    T_w_b2_.translation() = Eigen::Vector3d(1.0, 0.2, 0.5);
    poseToBlock(Eigen::Isometry3d::Identity(), blocks_[1].data());
    poseToBlock(T_w_b2_, blocks_[2].data());
  }
  [[nodiscard]] PoseLookup poses() const {
    return [this](std::uint64_t uid) -> const double* {
      const auto it = blocks_.find(uid);
      return it == blocks_.end() ? nullptr : it->second.data();
    };
  }
  // Landmark at p_w_ anchored in frame 1 (left only), seen in frame 2 by both cameras, the left
  // observation moved by `offset_px`.
  [[nodiscard]] Landmark landmark(const Eigen::Vector2d& offset_px) const {
    Landmark lm;
    lm.id = 7;
    lm.inv_depth = 1.0 / p_w_.z();
    lm.has_depth = true;
    Observation a;
    a.frame_uid = 1;
    a.px_left = project(geometry_.left, Eigen::Isometry3d::Identity(), p_w_);
    Observation b;
    b.frame_uid = 2;
    b.px_left = project(geometry_.left, T_w_b2_, p_w_) + offset_px;
    b.has_right = true;
    b.px_right = project(geometry_.right, T_w_b2_, p_w_);
    lm.observations = {a, b};
    return lm;
  }

  StereoGeometry geometry_ = stereoRig();
  Eigen::Isometry3d T_w_b2_ = Eigen::Isometry3d::Identity();
  Eigen::Vector3d p_w_{2.0, -1.0, 12.0};
  std::map<std::uint64_t, std::array<double, 7>> blocks_;
};

TEST_F(LandmarkReprojection, ExactObservationsGiveZero) {
  EXPECT_NEAR(LandmarkMap::meanReprojectionPx(landmark({0.0, 0.0}), poses(), geometry_, 0.0), 0.0,
              1e-9);
}

TEST_F(LandmarkReprojection, OffsetCountsOverEveryImage) {
  // Three projections (anchor left, frame 2 left and right), one 3-4-5 px off: mean 5/3 px.
  EXPECT_NEAR(LandmarkMap::meanReprojectionPx(landmark({3.0, 4.0}), poses(), geometry_, 0.0),
              5.0 / 3.0, 1e-9);
}

TEST_F(LandmarkReprojection, NoDepthOrNoAnchorPoseIsInfinite) {
  Landmark lm = landmark({0.0, 0.0});
  blocks_.erase(2);
  EXPECT_NEAR(LandmarkMap::meanReprojectionPx(lm, poses(), geometry_, 0.0), 0.0, 1e-9);
  lm.has_depth = false;
  EXPECT_TRUE(std::isinf(LandmarkMap::meanReprojectionPx(lm, poses(), geometry_, 0.0)));
  lm.has_depth = true;
  blocks_.erase(1);
  EXPECT_TRUE(std::isinf(LandmarkMap::meanReprojectionPx(lm, poses(), geometry_, 0.0)));
}

// A camera whose stamps lag the exposures by t_d saw frame 2's feature t_d V earlier on its path:
// measured at the stamps (Observation::leftAt) the observation is exact again, so the outlier test
// keeps it, while read as stamped it is rejected.
TEST_F(LandmarkReprojection, ObservationsAreMeasuredAtTheStampsForTheTimeOffset) {
  const double t_d = 0.02;
  const Eigen::Vector2d velocity(400.0, -150.0);  // px/s: 8 px and 3 px in 20 ms
  Landmark lm = landmark({0.0, 0.0});
  lm.observations[1].px_left -= t_d * velocity;
  lm.observations[1].velocity_pxps = velocity;
  lm.observations[1].has_right = false;
  EXPECT_NEAR(LandmarkMap::meanReprojectionPx(lm, poses(), geometry_, t_d), 0.0, 1e-9);
  EXPECT_NEAR(LandmarkMap::meanReprojectionPx(lm, poses(), geometry_, 0.0),
              0.5 * (t_d * velocity).norm(), 1e-9);

  const auto rejected = [&](double time_offset_s) {
    LandmarkMap map;
    map.all()[lm.id] = lm;
    return map.rejectOutliers(poses(), geometry_, time_offset_s, 3.0, 0.5, 100.0);
  };
  EXPECT_EQ(rejected(t_d), 0);
  EXPECT_EQ(rejected(0.0), 1);
}

// A feature new in its anchor frame has no velocity there: it takes the backward difference it
// shows at the next frame (the velocity half way there) and, at the frame after, is carried back
// to its own stamp through the tracker's velocity there (constant acceleration: exact for a
// velocity linear in time).
TEST(LandmarkVelocities, ANewFeatureGetsItsVelocityCarriedBackToItsAnchor) {
  const auto velocity = [](double t_s) {
    return Eigen::Vector2d(100.0 + 400.0 * t_s, -20.0 - 150.0 * t_s);
  };
  const auto observation = [](std::uint64_t uid, std::int64_t t_ns, const Eigen::Vector2d& v) {
    Observation o;
    o.frame_uid = uid;
    o.t_ns = t_ns;
    o.px_left = Eigen::Vector2d(300.0, 200.0);
    o.velocity_pxps = v;
    o.velocity_right_pxps = v - Eigen::Vector2d(3.0, 0.0);
    return o;
  };
  LandmarkMap map;
  map.create(7, observation(1, 0, Eigen::Vector2d::Zero()), StereoGeometry{}, 0.5, 100.0);
  // The tracker's backward difference at 0.1 s is the velocity at 0.05 s.
  ASSERT_TRUE(map.observe(7, observation(2, 100'000'000, velocity(0.05))));
  const auto anchor = [&map] { return map.all().at(7).observations.front(); };
  EXPECT_EQ(anchor().velocity_pxps, velocity(0.05));  // provisional
  EXPECT_EQ(anchor().velocity_from_t_ns, 100'000'000);
  ASSERT_TRUE(map.observe(7, observation(3, 200'000'000, velocity(0.2))));
  EXPECT_LT((anchor().velocity_pxps - velocity(0.0)).norm(), 1e-9);
  EXPECT_LT((anchor().velocity_right_pxps - (velocity(0.0) - Eigen::Vector2d(3.0, 0.0))).norm(),
            1e-9);
  EXPECT_EQ(anchor().velocity_from_t_ns, -1);
  // Final: later observations leave it alone.
  ASSERT_TRUE(map.observe(7, observation(4, 300'000'000, velocity(5.0))));
  EXPECT_LT((anchor().velocity_pxps - velocity(0.0)).norm(), 1e-9);
}

// A frame re-timed by t_d_base (its state at the stamp less that) leaves only t_d - t_d_base to the
// pixel's motion, and the factors' form (px + t_d V) must give the same pixel as leftAt.
TEST(LandmarkVelocities, AReTimedObservationMovesByTheRestOfTheOffset) {
  Observation o;
  o.px_left = Eigen::Vector2d(300.0, 200.0);
  o.px_right = Eigen::Vector2d(280.0, 200.0);
  o.velocity_pxps = Eigen::Vector2d(120.0, -40.0);
  o.velocity_right_pxps = Eigen::Vector2d(110.0, -40.0);
  o.t_d_base_s = 0.018;
  EXPECT_LT((o.leftAt(0.018) - o.px_left).norm(), 1e-12);  // the state is at the estimate
  EXPECT_LT((o.leftAt(0.020) - Eigen::Vector2d(300.24, 199.92)).norm(), 1e-9);
  EXPECT_LT((o.rightAt(0.010) - Eigen::Vector2d(279.12, 200.32)).norm(), 1e-9);
  for (const double t_d : {-0.01, 0.0, 0.018, 0.05}) {
    const MovingPixel left = o.movingLeft();
    const MovingPixel right = o.movingRight();
    EXPECT_LT((left.px + t_d * left.velocity_pxps - o.leftAt(t_d)).norm(), 1e-9) << t_d;
    EXPECT_LT((right.px + t_d * right.velocity_pxps - o.rightAt(t_d)).norm(), 1e-9) << t_d;
  }
  o.t_d_base_s = 0.0;  // not re-timed: the pixel itself
  EXPECT_EQ(o.movingLeft().px, o.px_left);
}

}  // namespace
}  // namespace gvio::odometry
