#pragma once
// Sigma scaling learned online, per fix quality, for the paper's KF (fusion/gnss_fusion.cpp):
// real receivers' stated sigmas are optimistic (Nagoya's SPP by 2-5x), and a filter that believes
// them gates good fixes out and lets its state jump to bad ones. The smoother learns its scale
// after the drive (fusion/gnss_smoother.hpp); a causal filter can only learn from what it has
// seen. It is given normalised squared errors, one per axis, whose median is 0.455 (chi-square,
// 1 dof) when the stated sigmas are right (the KF: consecutive fixes' displacement against the
// VIO's, whitened by the sum of their stated covariances, along the track while moving: see
// differencedNoiseSample);
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

// The samples of two consecutive fixes for the KF: d_enu = their displacement less the VIO's over
// the same interval (the VIO's rotated into ENU by the filter's estimate), vio_step_en = the VIO's
// horizontal displacement, cov_enu = the sum of both fixes' stated covariances (their ellipses
// included). The horizontal error is whitened by cov_enu; while the VIO moves (beyond
// kAlongTrackMinStepM) only its along-track component is sampled: the filter's heading error
// rotates the VIO's step and puts heading error x step length across the track (0.17 m per
// degree at 10 m/s and 1 Hz: a thin ellipse's short axis or an RTK fix's centimetres would
// learn the filter's error, not the receiver's), while along the track it is second order.
struct DifferencedNoiseSample {
  Eigen::Vector2d z2_horizontal = Eigen::Vector2d::Zero();  // y NaN: one sample (along-track)
  double z2_vertical = 0.0;
};
inline constexpr double kAlongTrackMinStepM = 0.1;
DifferencedNoiseSample differencedNoiseSample(const Eigen::Vector3d& d_enu,
                                              const Eigen::Vector2d& vio_step_en,
                                              const Eigen::Matrix3d& cov_enu);

class OnlineSigmaScale {
 public:
  explicit OnlineSigmaScale(const OnlineSigmaScaleConfig& config = {}) : config_(config) {}
  // One fix's normalised squared errors: horizontal (two values, or one and a NaN where only one
  // direction was sampled) and vertical.
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
