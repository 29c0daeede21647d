#pragma once
// IMU samples kept between keyframes, and preintegration over any time interval of them: a frame
// rarely coincides with an IMU sample, so the interval ends are linearly interpolated between the
// samples around them (the usual practice of VINS-Mono and OpenVINS).
#include <cstdint>
#include <deque>
#include <memory>

#include "odometry/imu_preintegration.hpp"
#include "odometry/measurements.hpp"

namespace gvio::odometry {

struct ImuStats {
  int samples = 0;
  Eigen::Vector3d mean_acc = Eigen::Vector3d::Zero(), mean_gyr = Eigen::Vector3d::Zero();
  double acc_std = 0.0, gyr_std = 0.0;  // root of the summed per-axis variances
};

class ImuBuffer {
 public:
  // Samples must arrive in time order; returns false (and drops the sample) otherwise.
  bool add(const ImuSample& sample);
  // Forgets samples no longer needed for intervals starting at t_ns or later.
  void dropBefore(std::int64_t t_ns);
  void clear() { samples_.clear(); }

  [[nodiscard]] bool empty() const { return samples_.empty(); }
  [[nodiscard]] std::int64_t lastStamp() const { return samples_.back().t_ns; }
  [[nodiscard]] std::int64_t firstStamp() const { return samples_.front().t_ns; }
  // True when [t0_ns, t1_ns] lies within the buffered samples (the end may reach up to
  // `max_extrapolation_ns` past the last sample, which is then held).
  [[nodiscard]] bool covers(std::int64_t t0_ns, std::int64_t t1_ns,
                            std::int64_t max_extrapolation_ns) const;
  // Longest spacing between consecutive samples inside [t0_ns, t1_ns] (seconds).
  [[nodiscard]] double largestGapS(std::int64_t t0_ns, std::int64_t t1_ns) const;

  // Preintegrates [t0_ns, t1_ns] (midpoint rule on the interpolated samples). Requires covers().
  [[nodiscard]] std::shared_ptr<ImuPreintegration> preintegrate(std::int64_t t0_ns,
                                                                std::int64_t t1_ns,
                                                                const ImuBias& bias,
                                                                const ImuNoise& noise) const;
  // Mean and spread of the samples in [t0_ns, t1_ns].
  [[nodiscard]] ImuStats stats(std::int64_t t0_ns, std::int64_t t1_ns) const;

 private:
  [[nodiscard]] ImuSample interpolate(std::int64_t t_ns) const;
  std::deque<ImuSample> samples_;
};

}  // namespace gvio::odometry
