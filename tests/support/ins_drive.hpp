#pragma once
// Pieces of the simulated drives the GNSS/INS tests build from an analytic velocity: the body
// positions on a 1 ms grid, their value at any time, and a fix reporting a position in ENU.
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "fusion/geodesy.hpp"
#include "odometry/measurements.hpp"

namespace gvio::test {

// Body positions every millisecond over duration_s, from 0 at t = 0 (trapezoidal integration of
// velocity(t), ENU m/s).
template <class Velocity>
std::vector<Eigen::Vector3d> positionsOnMsGrid(double duration_s, const Velocity& velocity) {
  const int n = static_cast<int>(duration_s * 1000.0) + 2;
  std::vector<Eigen::Vector3d> p(n, Eigen::Vector3d::Zero());
  for (int i = 1; i < n; ++i) {
    p[i] = p[i - 1] + 0.0005 * (velocity((i - 1) * 1e-3) + velocity(i * 1e-3));
  }
  return p;
}

// The grid's position at t s, linearly interpolated.
inline Eigen::Vector3d positionAt(const std::vector<Eigen::Vector3d>& grid, double t) {
  const auto i = static_cast<std::size_t>(std::floor(t * 1000.0));
  const double s = t * 1000.0 - static_cast<double>(i);
  return (1.0 - s) * grid[i] + s * grid[std::min(i + 1, grid.size() - 1)];
}

// A fix stamped t_ns reporting p_enu (in `enu`) with these 1-sigmas.
inline GnssFix fixAt(const fusion::EnuFrame& enu, std::int64_t t_ns, const Eigen::Vector3d& p_enu,
                     double sigma_h_m, double sigma_v_m) {
  const fusion::Lla lla = enu.toLla(p_enu);
  GnssFix f;
  f.t_ns = t_ns;
  f.lat_deg = lla.lat_deg;
  f.lon_deg = lla.lon_deg;
  f.h_ellipsoid_m = lla.h_ellipsoid_m;
  f.sigma_h_m = sigma_h_m;
  f.sigma_v_m = sigma_v_m;
  return f;
}

}  // namespace gvio::test
