#pragma once
// Sigma scaling learned online, per fix quality, for the paper's KF (fusion/gnss_fusion.cpp):
// real receivers' stated sigmas are optimistic (Nagoya's SPP by 2-5x), and a filter that believes
// them gates good fixes out and lets its state jump to bad ones. The smoother learns its scale
// after the drive (fusion/gnss_smoother.hpp); a causal filter can only learn from what it has
// seen. It is given normalised squared errors, one per axis, whose median is 0.455 (chi-square,
// 1 dof) when the stated sigmas are right (the KF: consecutive fixes' displacement against the
// VIO's, over the sum of their stated variances, which the filter's own error does not enter);
// their median's ratio to that scales the sigmas, never down (as the smoother; innovation-based
// adaptive estimation, Mohamed and Schwarz, "Adaptive Kalman filtering for INS/GPS", J. Geodesy
// 1999).
#include <Eigen/Core>
#include <deque>
#include <map>

namespace gvio::fusion {

struct OnlineSigmaScaleConfig {
  int window = 100;      // recent fixes of one quality the median is taken over
  int min_samples = 10;  // fewer: the stated sigmas are used
  double max_scale = 10.0;
};

class OnlineSigmaScale {
 public:
  explicit OnlineSigmaScale(const OnlineSigmaScaleConfig& config = {}) : config_(config) {}
  // One fix's normalised squared errors: horizontal axes (two values) and vertical.
  void add(int quality, const Eigen::Vector2d& z2_horizontal, double z2_vertical);
  // The factor for the stated (horizontal, vertical) sigmas of a fix of this quality, >= 1.
  [[nodiscard]] Eigen::Vector2d scale(int quality) const;
  // Every quality's current factor.
  [[nodiscard]] std::map<int, Eigen::Vector2d> scales() const;

 private:
  struct Samples {
    std::deque<double> horizontal, vertical;
  };
  OnlineSigmaScaleConfig config_;
  std::map<int, Samples> samples_;
};

}  // namespace gvio::fusion
