#pragma once
// The city block the loop-closure tests drive: a rounded 80 x 50 m rectangle (corner radius 12 m)
// counter-clockwise from the origin heading east, at 8 m/s for 55 s (1.3 laps), body poses at
// 10 Hz with z up, 0.93 m above the road.
#include <fmt/format.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <string>

#include "io/trajectory_io.hpp"
#include "odometry/trajectory.hpp"
#include "support/fixtures.hpp"

namespace gvio::test {

// Position (x, y) and heading (z) at arc length s.
inline Eigen::Vector3d blockPose(double s) {
  constexpr double kLong = 80.0, kShort = 50.0, kCorner = 12.0;
  const double arc = std::numbers::pi / 2.0 * kCorner;
  const double perimeter = 2.0 * (kLong + kShort) + 4.0 * arc;
  s = std::fmod(s, perimeter);
  Eigen::Vector2d p = Eigen::Vector2d::Zero();
  double heading = 0.0;
  for (const double straight : {kLong, kShort, kLong, kShort}) {
    const Eigen::Vector2d t(std::cos(heading), std::sin(heading));
    if (s <= straight) return {p.x() + s * t.x(), p.y() + s * t.y(), heading};
    p += straight * t;
    s -= straight;
    const Eigen::Vector2d centre = p + kCorner * Eigen::Vector2d(-t.y(), t.x());
    const double a = std::min(s, arc) / kCorner;
    const auto on_corner = [&](double angle) {
      return Eigen::Vector2d(centre.x() + kCorner * std::sin(heading + angle),
                             centre.y() - kCorner * std::cos(heading + angle));
    };
    if (s <= arc) {
      const Eigen::Vector2d q = on_corner(a);
      return {q.x(), q.y(), heading + a};
    }
    p = on_corner(std::numbers::pi / 2.0);
    heading += std::numbers::pi / 2.0;
    s -= arc;
  }
  return {p.x(), p.y(), heading};
}

inline Trajectory blockDrive() {
  Trajectory t;
  for (int i = 0; i <= 550; ++i) {  // 55 s at 10 Hz
    const Eigen::Vector3d p = blockPose(8.0 * 0.1 * i);
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::AngleAxisd(p.z(), Eigen::Vector3d::UnitZ()).toRotationMatrix();
    T.translation() = Eigen::Vector3d(p.x(), p.y(), 0.93);
    t.poses.push_back(T);
    t.t_ns.push_back(static_cast<std::int64_t>(i) * 100'000'000LL);
  }
  return t;
}

// The block drive simulated with SPP-grade GNSS, seed 1 and `extra_args`, once for all test
// processes: the drive is written to `file_name` in the test cache, a stable path, because the
// simulation cache is keyed by the arguments.
inline std::filesystem::path simulatedBlockDrive(const std::string& file_name,
                                                 const std::string& extra_args = "") {
  const std::filesystem::path drive = std::filesystem::path(GVIO_TEST_CACHE_DIR) / file_name;
  std::filesystem::create_directories(drive.parent_path());
  io::writeTum(drive, blockDrive());
  return cachedSimulation(
      fmt::format("--trajectory {} --gnss-noise spp --seed 1{}", quoted(drive), extra_args));
}

}  // namespace gvio::test
