// The registration consensus that keeps a burst of gross GNSS outliers from deciding the VIO ->
// ENU registration (fusion/alignment_consensus.hpp).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "fusion/alignment_consensus.hpp"

namespace gvio::fusion {
namespace {

constexpr double kGate = 16.27;  // chi-square, 3 dof, 99.9 %
constexpr double kFloor = 0.5;

// 20 fixes, one per second, along an L-shaped path at 8 m/s; the VIO world is the ENU frame
// turned by 30 degrees and shifted; SPP-grade noise (1.5 m horizontal, 3 m vertical).
std::vector<AlignmentSample> drive(std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> h(0.0, 1.5), v(0.0, 3.0);
  Eigen::Isometry3d T_enu_w = Eigen::Isometry3d::Identity();
  T_enu_w.linear() = Eigen::AngleAxisd(M_PI / 6, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T_enu_w.translation() = Eigen::Vector3d(120.0, -40.0, 3.0);
  std::vector<AlignmentSample> samples;
  for (int k = 0; k < 20; ++k) {
    const Eigen::Vector3d p_enu =
        k < 10 ? Eigen::Vector3d(8.0 * k, 0.0, 0.0) : Eigen::Vector3d(72.0, 8.0 * (k - 9), 0.0);
    AlignmentSample s;
    s.p_w = T_enu_w.inverse() * p_enu;
    const double dx = h(rng), dy = h(rng), dz = v(rng);
    s.p_enu = p_enu + Eigen::Vector3d(dx, dy, dz);
    s.sigma_h_m = 1.5;
    s.sigma_v_m = 3.0;
    samples.push_back(s);
  }
  return samples;
}

TEST(AlignmentConsensus, CleanFixesAreAllInliers) {
  for (std::uint32_t seed = 1; seed <= 5; ++seed) {
    const std::vector<bool> inliers = consensusInliers(drive(seed), kGate, kFloor);
    EXPECT_EQ(std::count(inliers.begin(), inliers.end(), true), 20) << "seed " << seed;
  }
}

TEST(AlignmentConsensus, AKilometreBurstIsOutvotedWhereverItFalls) {
  for (int first = 0; first <= 14; first += 7) {
    std::vector<AlignmentSample> samples = drive(3);
    for (int k = first; k < first + 4; ++k) samples[k].p_enu.y() += 1000.0;  // 4 fixes, 1 km north
    const std::vector<bool> inliers = consensusInliers(samples, kGate, kFloor);
    for (int k = 0; k < 20; ++k) {
      EXPECT_EQ(inliers[k], k < first || k >= first + 4) << "burst at " << first << ", fix " << k;
    }
  }
}

TEST(AlignmentConsensus, ATripleSpanningTooLittleFixesNothing) {
  std::vector<AlignmentSample> samples(3);
  for (auto& s : samples) s.p_w = s.p_enu = Eigen::Vector3d(1.0, 2.0, 0.0);
  const std::vector<bool> inliers = consensusInliers(samples, kGate, kFloor);
  EXPECT_EQ(std::count(inliers.begin(), inliers.end(), true), 0);
}

TEST(AlignmentConsensus, ChiSquareInflatesTheSigmaByTheFloor) {
  AlignmentSample s;
  s.p_w = Eigen::Vector3d::Zero();
  s.p_enu = Eigen::Vector3d(3.0, 4.0, 0.0);
  s.sigma_h_m = std::sqrt(24.75);  // with the 0.5 m floor: variance 25
  EXPECT_NEAR(registrationChi2(Eigen::Isometry3d::Identity(), s, 0.5), 1.0, 1e-12);
}

}  // namespace
}  // namespace gvio::fusion
