#include "odometry/imu_buffer.hpp"

#include <algorithm>
#include <cmath>

namespace gvio::odometry {

bool ImuBuffer::add(const ImuSample& sample) {
  if (!samples_.empty() && sample.t_ns <= samples_.back().t_ns) return false;
  if (!sample.acc_b_mps2.allFinite() || !sample.gyr_b_radps.allFinite()) return false;
  samples_.push_back(sample);
  return true;
}

void ImuBuffer::dropBefore(std::int64_t t_ns) {
  // Keep the last sample at or before t_ns: it is needed to interpolate at t_ns.
  while (samples_.size() >= 2 && samples_[1].t_ns <= t_ns) samples_.pop_front();
}

bool ImuBuffer::covers(std::int64_t t0_ns, std::int64_t t1_ns,
                       std::int64_t max_extrapolation_ns) const {
  if (samples_.empty() || t1_ns <= t0_ns) return false;
  return samples_.front().t_ns <= t0_ns && t1_ns <= samples_.back().t_ns + max_extrapolation_ns;
}

double ImuBuffer::largestGapS(std::int64_t t0_ns, std::int64_t t1_ns) const {
  std::int64_t largest = 0;
  for (std::size_t k = 1; k < samples_.size(); ++k) {
    if (samples_[k].t_ns <= t0_ns || samples_[k - 1].t_ns >= t1_ns) continue;
    largest = std::max(largest, samples_[k].t_ns - samples_[k - 1].t_ns);
  }
  return static_cast<double>(largest) * 1e-9;
}

ImuSample ImuBuffer::interpolate(std::int64_t t_ns) const {
  // Past the last sample the last measurement is held (a frame may arrive a few ms after it).
  if (t_ns >= samples_.back().t_ns) {
    ImuSample s = samples_.back();
    s.t_ns = t_ns;
    return s;
  }
  const auto it = std::lower_bound(samples_.begin(), samples_.end(), t_ns,
                                   [](const ImuSample& s, std::int64_t t) { return s.t_ns < t; });
  if (it == samples_.begin() || it->t_ns == t_ns) {
    ImuSample s = *it;
    s.t_ns = t_ns;
    return s;
  }
  const ImuSample& b = *it;
  const ImuSample& a = *(it - 1);
  const double w = static_cast<double>(t_ns - a.t_ns) / static_cast<double>(b.t_ns - a.t_ns);
  ImuSample s;
  s.t_ns = t_ns;
  s.acc_b_mps2 = (1.0 - w) * a.acc_b_mps2 + w * b.acc_b_mps2;
  s.gyr_b_radps = (1.0 - w) * a.gyr_b_radps + w * b.gyr_b_radps;
  return s;
}

std::shared_ptr<ImuPreintegration> ImuBuffer::preintegrate(std::int64_t t0_ns, std::int64_t t1_ns,
                                                           const ImuBias& bias,
                                                           const ImuNoise& noise) const {
  auto pre = std::make_shared<ImuPreintegration>(bias, noise);
  ImuSample prev = interpolate(t0_ns);
  for (const ImuSample& s : samples_) {
    if (s.t_ns <= t0_ns) continue;
    if (s.t_ns >= t1_ns) break;
    pre->integrate(prev, s);
    prev = s;
  }
  const ImuSample last = interpolate(t1_ns);
  if (last.t_ns > prev.t_ns) pre->integrate(prev, last);
  return pre;
}

ImuStats ImuBuffer::stats(std::int64_t t0_ns, std::int64_t t1_ns) const {
  ImuStats st;
  Eigen::Vector3d sum_a = Eigen::Vector3d::Zero(), sum_g = Eigen::Vector3d::Zero();
  Eigen::Vector3d sq_a = Eigen::Vector3d::Zero(), sq_g = Eigen::Vector3d::Zero();
  for (const ImuSample& s : samples_) {
    if (s.t_ns < t0_ns || s.t_ns > t1_ns) continue;
    ++st.samples;
    sum_a += s.acc_b_mps2;
    sum_g += s.gyr_b_radps;
    sq_a += s.acc_b_mps2.cwiseAbs2();
    sq_g += s.gyr_b_radps.cwiseAbs2();
  }
  if (st.samples == 0) return st;
  const double n = st.samples;
  st.mean_acc = sum_a / n;
  st.mean_gyr = sum_g / n;
  st.acc_std = std::sqrt(std::max(0.0, (sq_a / n - st.mean_acc.cwiseAbs2()).sum()));
  st.gyr_std = std::sqrt(std::max(0.0, (sq_g / n - st.mean_gyr.cwiseAbs2()).sum()));
  return st;
}

}  // namespace gvio::odometry
