#pragma once
// A climbing left curve for the orientation tests: 10 m/s horizontally around a 60 m radius on a
// 5 % grade, starting at the origin heading east, sampled at 10 Hz with the body mounted on the
// vehicle (x forward, y left, z up) by a fixed rotation R_v_b.
#include <Eigen/Geometry>
#include <cmath>

#include "odometry/trajectory.hpp"

namespace gvio::test {

struct ClimbingCurve {
  double radius_m = 60.0, speed_mps = 10.0, grade = 0.05;

  [[nodiscard]] double climbRad() const { return std::atan(grade); }
  [[nodiscard]] double headingRad(double t_s) const { return speed_mps / radius_m * t_s; }
  [[nodiscard]] Eigen::Vector3d position(double t_s) const {
    const double h = headingRad(t_s);
    return {radius_m * std::sin(h), radius_m * (1.0 - std::cos(h)), grade * speed_mps * t_s};
  }
  // Unit direction of travel (3-D, along the road's slope) at t_s, or where the path passes p_w.
  [[nodiscard]] Eigen::Vector3d travel(double t_s) const {
    return travelAtHeading(headingRad(t_s));
  }
  [[nodiscard]] Eigen::Vector3d travelAt(const Eigen::Vector3d& p_w) const {
    return travelAtHeading(std::atan2(p_w.x(), radius_m - p_w.y()));
  }
  [[nodiscard]] Eigen::Vector3d travelAtHeading(double h) const {
    const double c = climbRad();
    return {std::cos(h) * std::cos(c), std::sin(h) * std::cos(c), std::sin(c)};
  }
  // The vehicle: x along travel, y horizontal to the left, z up.
  [[nodiscard]] Eigen::Matrix3d R_w_v(double t_s) const {
    return (Eigen::AngleAxisd(headingRad(t_s), Eigen::Vector3d::UnitZ()) *
            Eigen::AngleAxisd(-climbRad(), Eigen::Vector3d::UnitY()))
        .toRotationMatrix();
  }
  // Stamps from 0 s, T_w_b = T_w_v * R_v_b.
  [[nodiscard]] Trajectory poses(double duration_s, const Eigen::Matrix3d& R_v_b) const {
    Trajectory traj;
    for (int i = 0; i <= static_cast<int>(std::lround(duration_s * 10.0)); ++i) {
      const double t_s = 0.1 * i;
      Eigen::Isometry3d T_w_b = Eigen::Isometry3d::Identity();
      T_w_b.linear() = R_w_v(t_s) * R_v_b;
      T_w_b.translation() = position(t_s);
      traj.t_ns.push_back(static_cast<std::int64_t>(i) * 100'000'000LL);
      traj.poses.push_back(T_w_b);
    }
    return traj;
  }
  // A camera-like mount (x right, y up, z backward): travel along the body's -z axis.
  static Eigen::Matrix3d mountTravelAlongMinusZ() {
    Eigen::Matrix3d R_v_b;
    R_v_b << 0, 0, -1, -1, 0, 0, 0, 1, 0;
    return R_v_b;
  }
};

}  // namespace gvio::test
