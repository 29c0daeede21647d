#include "fusion/ins_heading_bank.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <numbers>

namespace gvio::fusion {
namespace {

double yawOf(const Eigen::Matrix3d& R) {
  return std::atan2(R(1, 0), R(0, 0));
}

// The heading's variance: the attitude error is body-frame (R = R_hat Exp(dtheta)), its ENU
// vertical component R dtheta.
double headingVariance(const GnssIns& f) {
  const Eigen::Matrix3d& R = f.state().R_enu_b;
  const Eigen::Matrix3d P = f.covariance().block<3, 3>(kInsTheta, kInsTheta);
  return (R * P * R.transpose())(2, 2);
}

}  // namespace

HeadingBank::HeadingBank(const InsConfig& config, const EnuFrame& enu, const ImuSample& anchor,
                         const InsState& start, const InsMatrix& P)
    : config_(config) {
  InsConfig scout = config;
  scout.use_nhc = false;
  scout.estimate_mount = false;
  scout.align.hypotheses = 0;
  const int n = config.align.hypotheses;
  const double spacing = 2.0 * std::numbers::pi / n;
  const double sigma = 0.5 * spacing;
  for (int k = 0; k < n; ++k) {
    InsState x = start;
    x.R_enu_b =
        Eigen::AngleAxisd(k * spacing, Eigen::Vector3d::UnitZ()).toRotationMatrix() * start.R_enu_b;
    InsMatrix Pk = P;
    // Heading sigma about the ENU vertical, as body-frame attitude error.
    const Eigen::Matrix3d Rt = x.R_enu_b.transpose();
    const Eigen::Vector3d up_b = Rt.col(2);
    Pk.block<3, 3>(kInsTheta, kInsTheta) += sigma * sigma * up_b * up_b.transpose();
    scouts_.emplace_back(scout, enu);
    scouts_.back().startAt(anchor, x, Pk, false);
  }
}

void HeadingBank::addImu(const ImuSample& s) {
  for (GnssIns& f : scouts_) f.addImu(s);
}

void HeadingBank::addFix(const GnssFix& fix) {
  for (GnssIns& f : scouts_) f.addFix(fix);
}

std::optional<HeadingChoice> HeadingBank::choose(double max_sigma_rad) const {
  std::size_t best = 0;
  for (std::size_t k = 1; k < scouts_.size(); ++k) {
    if (scouts_[k].stats().position_nll < scouts_[best].stats().position_nll) best = k;
  }
  const double best_yaw = yawOf(scouts_[best].state().R_enu_b);
  const double same = config_.align.same_solution_deg * std::numbers::pi / 180.0;
  double competitor = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < scouts_.size(); ++k) {
    const double d =
        std::remainder(yawOf(scouts_[k].state().R_enu_b) - best_yaw, 2.0 * std::numbers::pi);
    if (std::abs(d) > same) competitor = std::min(competitor, scouts_[k].stats().position_nll);
  }
  HeadingChoice c;
  c.nll_gap = competitor - scouts_[best].stats().position_nll;
  c.sigma_rad = std::sqrt(std::max(0.0, headingVariance(scouts_[best])));
  if (!(c.nll_gap >= config_.align.min_nll_gap) || !(c.sigma_rad <= max_sigma_rad)) {
    return std::nullopt;
  }
  c.R_enu_b = scouts_[best].state().R_enu_b;
  c.hypothesis = static_cast<int>(best);
  return c;
}

}  // namespace gvio::fusion
