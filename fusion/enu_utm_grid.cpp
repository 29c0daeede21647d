#include "fusion/enu_utm_grid.hpp"

#include <cmath>

namespace gvio::fusion {
namespace {

// Two 32-bit cell indices in one key (grids span far less than 2^31 cells).
std::uint64_t key(std::int64_t i, std::int64_t j) {
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(i)) << 32) |
         static_cast<std::uint32_t>(j);
}

}  // namespace

EnuToUtmGrid::EnuToUtmGrid(const Lla& enu_origin, int zone, bool north, double cell_m)
    : enu_(enu_origin), zone_(zone), north_(north), cell_m_(cell_m) {}

Eigen::Vector3d EnuToUtmGrid::exactUtm(const Eigen::Vector3d& p_enu) const {
  const Lla lla = enu_.toLla(p_enu);
  const Utm utm = llaToUtm(lla, zone_, north_);
  return {utm.easting_m, utm.northing_m, lla.h_ellipsoid_m};
}

const EnuToUtmGrid::Corner& EnuToUtmGrid::corner(std::int64_t i, std::int64_t j) {
  const auto [it, inserted] = corners_.try_emplace(key(i, j));
  if (inserted) {
    const Eigen::Vector3d ground(static_cast<double>(i) * cell_m_, static_cast<double>(j) * cell_m_,
                                 0.0);
    it->second.at0 = exactUtm(ground);
    it->second.per_up =
        (exactUtm(ground + Eigen::Vector3d(0.0, 0.0, kUpStepM)) - it->second.at0) / kUpStepM;
  }
  return it->second;
}

Eigen::Vector3d EnuToUtmGrid::toUtm(const Eigen::Vector3d& p_enu) {
  if (!p_enu.allFinite()) return Eigen::Vector3d::Constant(std::nan(""));
  const double fe = p_enu.x() / cell_m_, fn = p_enu.y() / cell_m_;
  const auto i = static_cast<std::int64_t>(std::floor(fe));
  const auto j = static_cast<std::int64_t>(std::floor(fn));
  const double a = fe - static_cast<double>(i), b = fn - static_cast<double>(j);
  if (i != last_i_ || j != last_j_) {
    last_[0] = &corner(i, j);
    last_[1] = &corner(i + 1, j);
    last_[2] = &corner(i, j + 1);
    last_[3] = &corner(i + 1, j + 1);
    last_i_ = i;
    last_j_ = j;
  }
  const Corner &c00 = *last_[0], &c10 = *last_[1], &c01 = *last_[2], &c11 = *last_[3];
  const double w00 = (1 - a) * (1 - b), w10 = a * (1 - b), w01 = (1 - a) * b, w11 = a * b;
  const Eigen::Vector3d at0 = w00 * c00.at0 + w10 * c10.at0 + w01 * c01.at0 + w11 * c11.at0;
  const Eigen::Vector3d per_up =
      w00 * c00.per_up + w10 * c10.per_up + w01 * c01.per_up + w11 * c11.per_up;
  return at0 + p_enu.z() * per_up;
}

}  // namespace gvio::fusion
