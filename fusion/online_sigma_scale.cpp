#include "fusion/online_sigma_scale.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace gvio::fusion {
namespace {

constexpr double kChi2Median1Dof = 0.454936;

double medianOf(const std::deque<double>& d) {
  std::vector<double> v(d.begin(), d.end());
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  if (v.size() % 2 == 1) return *mid;
  return 0.5 * (*mid + *std::max_element(v.begin(), mid));
}

}  // namespace

DifferencedNoiseSample differencedNoiseSample(const Eigen::Vector3d& d_enu,
                                              const Eigen::Vector2d& vio_step_en,
                                              const Eigen::Matrix3d& cov_enu) {
  DifferencedNoiseSample out;
  out.z2_vertical = d_enu.z() * d_enu.z() / cov_enu(2, 2);
  const Eigen::Matrix2d cov_h = cov_enu.topLeftCorner<2, 2>();
  const double step_m = vio_step_en.norm();
  if (step_m > kAlongTrackMinStepM) {
    const Eigen::Vector2d along = vio_step_en / step_m;
    const double u = along.dot(d_enu.head<2>());
    out.z2_horizontal = {u * u / along.dot(cov_h * along),
                         std::numeric_limits<double>::quiet_NaN()};
  } else if (cov_h(0, 1) == 0.0) {  // a circle or an axis-aligned ellipse: per axis, exactly
    out.z2_horizontal = d_enu.head<2>().cwiseAbs2().cwiseQuotient(cov_h.diagonal());
  } else {
    out.z2_horizontal = cov_h.llt().matrixL().solve(d_enu.head<2>()).cwiseAbs2();
  }
  return out;
}

void OnlineSigmaScale::add(int quality, const Eigen::Vector2d& z2_h, double z2_v) {
  Samples& s = samples_[quality];
  const auto push = [&](std::deque<double>& d, double value, std::size_t cap) {
    if (!std::isfinite(value)) return;
    d.push_back(value);
    while (d.size() > cap) d.pop_front();
  };
  const auto cap = static_cast<std::size_t>(config_.window);
  push(s.horizontal, z2_h.x(), 2 * cap);
  push(s.horizontal, z2_h.y(), 2 * cap);
  push(s.vertical, z2_v, cap);
}

Eigen::Vector2d OnlineSigmaScale::scale(int quality) const {
  const auto it = samples_.find(quality);
  if (it == samples_.end()) return Eigen::Vector2d::Ones();
  const auto factor = [&](const std::deque<double>& d, std::size_t min_count) {
    if (d.size() < min_count) return 1.0;
    return std::clamp(std::sqrt(medianOf(d) / kChi2Median1Dof), 1.0, config_.max_scale);
  };
  const auto min_count = static_cast<std::size_t>(config_.min_samples);
  return {factor(it->second.horizontal, 2 * min_count), factor(it->second.vertical, min_count)};
}

std::map<int, Eigen::Vector2d> OnlineSigmaScale::scales() const {
  std::map<int, Eigen::Vector2d> out;
  for (const auto& [quality, samples] : samples_) out[quality] = scale(quality);
  return out;
}

}  // namespace gvio::fusion
