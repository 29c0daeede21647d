// What the window keeps of its landmarks when the oldest frame is marginalised: a landmark whose
// residuals were folded into the prior leaves with the frame (its observations in the frames
// that stay are in the prior already, and must not be counted again); one that had no residuals
// (no depth yet) moves its anchor to its next observation; the others are not touched.
#include <gtest/gtest.h>

#include <memory>

#include "odometry/pose_manifold.hpp"
#include "odometry/sliding_window.hpp"
#include "support/stereo_rig.hpp"

namespace gvio::odometry {
namespace {

using test::project;
using test::stereoRig;

// Body = left camera, driving 1 m per frame along the optical axis.
Eigen::Isometry3d poseOf(int k) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(0.0, 0.0, 1.0 * k);
  return T;
}

class WindowMarginalization : public ::testing::Test {
 protected:
  void SetUp() override {
    for (int k = 0; k < 3; ++k) {
      auto f = std::make_unique<WindowFrame>();
      f->uid = static_cast<std::uint64_t>(k + 1);
      f->t_ns = static_cast<std::int64_t>(k) * 100'000'000;
      f->keyframe = true;
      poseToBlock(poseOf(k), f->pose.data());
      window_.frames().push_back(std::move(f));
    }
  }

  // A landmark at p_w seen from frames first..last (uids first + 1...), with its true depth in
  // the first when `with_depth`.
  void addLandmark(std::uint64_t id, const Eigen::Vector3d& p_w, int first, int last,
                   bool with_depth) {
    const StereoGeometry& g = window_.geometry();
    for (int k = first; k <= last; ++k) {
      Observation o;
      o.frame_uid = static_cast<std::uint64_t>(k + 1);
      o.t_ns = static_cast<std::int64_t>(k) * 100'000'000;
      o.px_left = project(g.left, poseOf(k), p_w);
      o.px_right = project(g.right, poseOf(k), p_w);
      o.has_right = true;
      if (k == first) {
        window_.landmarks().create(id, o, g, 0.5, with_depth ? 80.0 : 1.0);
      } else {
        ASSERT_TRUE(window_.landmarks().observe(id, o));
      }
    }
    ASSERT_EQ(window_.landmarks().all().at(id).has_depth, with_depth);
  }

  SlidingWindow window_{EstimatorConfig{}, stereoRig()};
};

TEST_F(WindowMarginalization, AFoldedLandmarkLeavesWithTheFrameAndNoOtherIsTouched) {
  addLandmark(1, {1.0, 0.5, 12.0}, 0, 2, true);    // folded into the prior
  addLandmark(2, {-2.0, 0.3, 15.0}, 0, 2, false);  // no depth: nothing to fold
  addLandmark(3, {0.5, -1.0, 9.0}, 1, 2, true);    // anchored in a frame that stays
  const Landmark before3 = window_.landmarks().all().at(3);

  window_.marginalizeOldest(false);

  ASSERT_TRUE(window_.hasPrior());
  ASSERT_EQ(window_.frames().size(), 2U);
  const auto& all = window_.landmarks().all();
  EXPECT_EQ(all.count(1), 0U) << "its observations in frames 2 and 3 are in the prior";
  ASSERT_EQ(all.count(2), 1U);
  EXPECT_EQ(all.at(2).anchor().frame_uid, 2U);
  EXPECT_EQ(all.at(2).observations.size(), 2U);
  ASSERT_EQ(all.count(3), 1U);
  EXPECT_EQ(all.at(3).anchor().frame_uid, before3.anchor().frame_uid);
  EXPECT_EQ(all.at(3).observations.size(), before3.observations.size());
  EXPECT_EQ(all.at(3).inv_depth, before3.inv_depth);

  // The track goes on: its next observation starts a new landmark (a keyframe's create()).
  Observation next;
  next.frame_uid = 4;
  EXPECT_FALSE(window_.landmarks().observe(1, next));
}

TEST_F(WindowMarginalization, WithoutAnyFoldedResidualNoPriorIsMadeAndLandmarksMoveOn) {
  addLandmark(2, {-2.0, 0.3, 15.0}, 0, 2, false);

  window_.marginalizeOldest(false);

  EXPECT_FALSE(window_.hasPrior());
  ASSERT_EQ(window_.landmarks().all().count(2), 1U);
  EXPECT_EQ(window_.landmarks().all().at(2).anchor().frame_uid, 2U);
}

}  // namespace
}  // namespace gvio::odometry
