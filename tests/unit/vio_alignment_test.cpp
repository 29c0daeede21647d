// Visual-inertial alignment on exact synthetic data: poses and IMU of a known accelerating,
// turning motion, expressed in a visual frame rotated away from gravity.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "odometry/lie.hpp"
#include "odometry/vi_alignment.hpp"

namespace gvio::odometry {
namespace {

struct Truth {
  std::vector<AlignmentFrame> frames;
  std::vector<Eigen::Vector3d> v_v;
  Eigen::Vector3d g_v;
};

// Frames every 0.1 s over 1.2 s. The truth is propagated with the same discrete model the
// preintegration uses (constant measurement per 5 ms step), so the alignment equations hold
// exactly; the gyroscope measures with a constant bias.
Truth makeTruth(const Eigen::Vector3d& gyr_bias, const Eigen::Matrix3d& R_v_w,
                double acc_scale = 1.0) {
  const Eigen::Vector3d g_w(0, 0, -kGravity_mps2);
  const double dt = 0.005;
  Truth t;
  t.g_v = R_v_w * g_w;
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d p = Eigen::Vector3d::Zero(), v(8.0, 0.5, 0.0);
  std::shared_ptr<ImuPreintegration> pending;
  for (int k = 0; k <= 12; ++k) {
    AlignmentFrame f;
    f.R_v_b = R_v_w * R;
    f.p_v_b = R_v_w * p;
    f.preintegration = pending;
    t.frames.push_back(f);
    t.v_v.push_back(R_v_w * v);
    pending = std::make_shared<ImuPreintegration>(ImuBias{}, ImuNoise{});
    for (int s = 0; s < 20; ++s) {
      const double time = 0.1 * k + dt * s;
      const Eigen::Vector3d omega(0.05 * std::sin(time), -0.02, 0.2 * std::cos(time));
      const Eigen::Vector3d a_b(0.8 * std::sin(2.0 * time), 0.6 * std::cos(time), 0.1);
      const Eigen::Vector3d acc_b = a_b - R.transpose() * g_w;  // specific force
      pending->integrate(dt, acc_scale * acc_b, omega + gyr_bias);
      const Eigen::Vector3d a_w = R * acc_b + g_w;
      p += v * dt + 0.5 * a_w * dt * dt;
      v += a_w * dt;
      R = normalizeRotation(R * expSo3(omega * dt));
    }
  }
  return t;
}

TEST(ViAlignment, RecoversGravityVelocitiesAndGyroBias) {
  const Eigen::Vector3d gyr_bias(0.01, -0.02, 0.015);
  const Eigen::Matrix3d R_v_w = expSo3(Eigen::Vector3d(0.3, -0.2, 1.0));
  Truth truth = makeTruth(gyr_bias, R_v_w);
  const auto result = alignVisualInertial(truth.frames, false);
  ASSERT_TRUE(result.has_value());
  EXPECT_LT((result->gyr_bias - gyr_bias).norm(), 2e-4);
  const double angle =
      std::acos(std::clamp(result->g_v.normalized().dot(truth.g_v.normalized()), -1.0, 1.0));
  EXPECT_LT(angle * 180.0 / M_PI, 0.05);
  EXPECT_NEAR(result->g_v.norm(), kGravity_mps2, 1e-9);
  for (std::size_t k = 0; k < truth.v_v.size(); ++k) {
    EXPECT_LT((result->v_v[k] - truth.v_v[k]).norm(), 0.02) << "frame " << k;
  }
  // The returned rotation makes the visual frame gravity-aligned.
  EXPECT_LT((result->R_w_v * truth.g_v.normalized() - Eigen::Vector3d(0, 0, -1)).norm(), 1e-3);
}

TEST(ViAlignment, EstimatesScaleForAMonocularWindow) {
  Truth truth = makeTruth(Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity());
  for (AlignmentFrame& f : truth.frames) f.p_v_b *= 0.5;  // vision sees half the true size
  const auto result = alignVisualInertial(truth.frames, true);
  ASSERT_TRUE(result.has_value());
  EXPECT_NEAR(result->scale, 2.0, 0.02);
}

TEST(ViAlignment, EstimatesScaleWithACameraLeverArm) {
  // A monocular camera 1.5 m from the IMU: vision sees the camera's path at half the true size,
  // and the lever arm R_v_c t_c_b (metric) moves with the body's rotation only.
  Truth truth = makeTruth(Eigen::Vector3d::Zero(), expSo3(Eigen::Vector3d(0.1, -0.2, 0.4)));
  const Eigen::Vector3d t_b_c(0.8, -0.3, 1.2);  // camera position in the body
  for (AlignmentFrame& f : truth.frames) {
    const Eigen::Vector3d p_v_c = f.p_v_b + f.R_v_b * t_b_c;
    f.p_v_b = 0.5 * p_v_c;
    f.lever_v = -f.R_v_b * t_b_c;  // R_v_c t_c_b with the camera axes of the body
  }
  const auto result = alignVisualInertial(truth.frames, true);
  ASSERT_TRUE(result.has_value());
  EXPECT_NEAR(result->scale, 2.0, 1e-3);
  EXPECT_LT(result->scale_rel_sigma, 0.01);
  for (std::size_t k = 0; k < truth.v_v.size(); ++k) {
    EXPECT_LT((result->v_v[k] - truth.v_v[k]).norm(), 0.02) << "frame " << k;
  }
}

TEST(ViAlignment, RefusesAnUnobservableScale) {
  // Constant velocity, no rotation: s (p_{k+1} - p_k) = v dt holds for every s, so only the
  // visual noise (1 mm here) decides the scale: the alignment must wait rather than guess.
  const Eigen::Vector3d g_w(0, 0, -kGravity_mps2), v(8.0, 0.5, 0.0);
  std::vector<AlignmentFrame> frames;
  std::shared_ptr<ImuPreintegration> pending;
  for (int k = 0; k <= 12; ++k) {
    AlignmentFrame f;
    const double n = static_cast<double>(k);
    f.p_v_b = 0.1 * n * v +
              1e-3 * Eigen::Vector3d(std::sin(1.3 * n), std::cos(2.1 * n), std::sin(0.7 * n));
    f.preintegration = pending;
    frames.push_back(f);
    pending = std::make_shared<ImuPreintegration>(ImuBias{}, ImuNoise{});
    for (int s = 0; s < 20; ++s) pending->integrate(0.005, -g_w, Eigen::Vector3d::Zero());
  }
  EXPECT_FALSE(alignVisualInertial(frames, true).has_value());
  EXPECT_TRUE(alignVisualInertial(frames, false).has_value());  // stereo: scale known
}

// The reported tilt sigma follows the gravity direction's actual spread: over noisy visual
// positions it is conservative (1.6-1.8x the RMS tilt error here: unit weights over rows whose
// noise differs, and each position enters two rows), never below it, and grows with the noise
// (the estimator waits on a large sigma: vio.init_max_tilt_sigma_deg).
TEST(ViAlignment, TiltSigmaMatchesTheSpreadOfTheGravityDirection) {
  const Eigen::Matrix3d R_v_w = expSo3(Eigen::Vector3d(0.3, -0.2, 1.0));
  std::mt19937 rng(7);
  std::normal_distribution<double> normal(0.0, 1.0);
  double previous_sigma = 0.0;
  for (const double noise_m : {0.002, 0.01, 0.03}) {
    double sum_sq_error = 0.0, sum_sigma = 0.0;
    const int trials = 60;
    for (int trial = 0; trial < trials; ++trial) {
      Truth truth = makeTruth(Eigen::Vector3d::Zero(), R_v_w);
      for (AlignmentFrame& f : truth.frames) {
        f.p_v_b += noise_m * Eigen::Vector3d{normal(rng), normal(rng), normal(rng)};
      }
      const auto result = alignVisualInertial(truth.frames, false, 0.5);
      ASSERT_TRUE(result.has_value()) << "noise " << noise_m << " trial " << trial;
      const double error =
          std::acos(std::clamp(result->g_v.normalized().dot(truth.g_v.normalized()), -1.0, 1.0));
      sum_sq_error += error * error;
      sum_sigma += result->tilt_sigma_rad;
    }
    const double rms_error = std::sqrt(sum_sq_error / trials);
    const double mean_sigma = sum_sigma / trials;
    EXPECT_GT(mean_sigma, rms_error) << "noise " << noise_m;
    EXPECT_LT(mean_sigma, 2.5 * rms_error) << "noise " << noise_m;
    EXPECT_GT(mean_sigma, previous_sigma);
    previous_sigma = mean_sigma;
  }
  // Exact data: no spread.
  Truth exact = makeTruth(Eigen::Vector3d::Zero(), R_v_w);
  const auto result = alignVisualInertial(exact.frames, false);
  ASSERT_TRUE(result.has_value());
  EXPECT_LT(result->tilt_sigma_rad * 180.0 / M_PI, 0.01);
}

TEST(ViAlignment, RefusesAnInconsistentWindow) {
  // An accelerometer reading 1.5x too much: the free gravity estimate is far from 9.81 m/s^2.
  Truth truth = makeTruth(Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity(), 1.5);
  EXPECT_FALSE(alignVisualInertial(truth.frames, false).has_value());
  std::vector<AlignmentFrame> too_few(truth.frames.begin(), truth.frames.begin() + 2);
  EXPECT_FALSE(alignVisualInertial(too_few, false).has_value());
}

TEST(ViAlignment, GravityAlignmentKeepsTheVerticalAxisOnly) {
  const Eigen::Vector3d g_v(0.5, -0.3, -9.7);
  const Eigen::Matrix3d R = gravityAlignment(g_v);
  EXPECT_LT((R * g_v.normalized() - Eigen::Vector3d(0, 0, -1)).norm(), 1e-12);
  EXPECT_NEAR(R.determinant(), 1.0, 1e-12);
}

}  // namespace
}  // namespace gvio::odometry
