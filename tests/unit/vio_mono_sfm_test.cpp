// Monocular SfM of the VIO initialisation on exact synthetic geometry: random points seen by a
// few cameras of known pose. The recovered window must equal the truth up to one similarity
// (the visual frame is the reference camera, the scale is free), and degenerate input fails.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "odometry/lie.hpp"
#include "odometry/mono_sfm.hpp"

namespace gvio::odometry {
namespace {

struct Scene {
  std::vector<Eigen::Isometry3d> T_w_c;
  std::vector<Eigen::Vector3d> points_w;
  std::vector<SfmTrack> tracks;
};

// Cameras looking along +z; projections are exact, tracks keep points inside a 90 deg view.
Scene makeScene(int frames, int points, const Eigen::Vector3d& step, double yaw_step_rad) {
  Scene s;
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> ux(-12.0, 12.0), uy(-4.0, 4.0), uz(12.0, 40.0);
  for (int k = 0; k < frames; ++k) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = expSo3(Eigen::Vector3d(0.01 * k, yaw_step_rad * k, -0.005 * k));
    T.translation() = static_cast<double>(k) * step;
    s.T_w_c.push_back(T);
  }
  for (int i = 0; i < points; ++i) {
    s.points_w.push_back(Eigen::Vector3d{ux(rng), uy(rng), uz(rng)});
    SfmTrack t;
    t.id = static_cast<std::uint64_t>(100 + i);
    for (int k = 0; k < frames; ++k) {
      const Eigen::Vector3d p_c =
          s.T_w_c[static_cast<std::size_t>(k)].inverse() * s.points_w.back();
      const Eigen::Vector2d uv = p_c.head<2>() / p_c.z();
      if (p_c.z() > 0.5 && uv.cwiseAbs().maxCoeff() < 1.0) t.observations.emplace_back(k, uv);
    }
    s.tracks.push_back(t);
  }
  return s;
}

TEST(VioMonoSfm, RecoversTheWindowUpToOneSimilarity) {
  const int n = 7;
  const Scene scene = makeScene(n, 150, Eigen::Vector3d(0.25, 0.03, 0.9), 0.02);
  const auto result = solveMonoSfm(scene.tracks, n);
  ASSERT_TRUE(result.has_value());
  ASSERT_EQ(result->T_v_c.size(), static_cast<std::size_t>(n));
  EXPECT_LT(result->rms_px, 1e-6);
  const Eigen::Isometry3d T_ref_w =
      scene.T_w_c[static_cast<std::size_t>(result->reference)].inverse();
  EXPECT_TRUE(result->T_v_c[static_cast<std::size_t>(result->reference)].isApprox(
      Eigen::Isometry3d::Identity(), 1e-12));
  // The one scale: the newest camera's distance from the reference.
  const double s = (T_ref_w * scene.T_w_c.back()).translation().norm() /
                   result->T_v_c.back().translation().norm();
  for (int k = 0; k < n; ++k) {
    const Eigen::Isometry3d truth = T_ref_w * scene.T_w_c[static_cast<std::size_t>(k)];
    const Eigen::Isometry3d& est = result->T_v_c[static_cast<std::size_t>(k)];
    EXPECT_LT((est.linear() - truth.linear()).norm(), 1e-6) << "frame " << k;
    EXPECT_LT((s * est.translation() - truth.translation()).norm(), 1e-6 * s) << "frame " << k;
  }
  ASSERT_GE(result->points_v.size(), 100U);
  for (const auto& [id, p] : result->points_v) {
    const Eigen::Vector3d truth = T_ref_w * scene.points_w[static_cast<std::size_t>(id - 100)];
    EXPECT_LT((s * p - truth).norm(), 1e-6 * truth.norm()) << "point " << id;
  }
}

TEST(VioMonoSfm, FailsCleanlyOnDegenerateInput) {
  // Pure rotation: plenty of image motion, no baseline.
  const Scene rotation = makeScene(6, 150, Eigen::Vector3d::Zero(), 0.04);
  EXPECT_FALSE(solveMonoSfm(rotation.tracks, 6).has_value());
  // Good motion but too few points.
  const Scene sparse = makeScene(6, 20, Eigen::Vector3d(0.25, 0.03, 0.9), 0.02);
  EXPECT_FALSE(solveMonoSfm(sparse.tracks, 6).has_value());
  // Nothing, a single frame, and observations naming frames outside the window.
  EXPECT_FALSE(solveMonoSfm({}, 6).has_value());
  const Scene good = makeScene(6, 150, Eigen::Vector3d(0.25, 0.03, 0.9), 0.02);
  EXPECT_FALSE(solveMonoSfm(good.tracks, 1).has_value());
  EXPECT_FALSE(solveMonoSfm(good.tracks, 3).has_value());
}

}  // namespace
}  // namespace gvio::odometry
