#include "sim/body_orientation.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <utility>
#include <vector>

#include "odometry/error.hpp"

namespace gvio::sim {
namespace {

constexpr double kDegPerRad = 180.0 / std::numbers::pi;

constexpr std::array<std::pair<std::string_view, OrientationSource>, 2> kSources{{
    {"file", OrientationSource::kFile},
    {"motion", OrientationSource::kMotion},
}};

// The path alone, for the simulator's own spline: the same smoothing the simulated drive gets,
// and no dependence on the file's orientations (which may be degenerate as Euler angles for a
// body mounted any way).
Trajectory positionsOnly(const Trajectory& T_w_b) {
  Trajectory positions = T_w_b;
  for (auto& T : positions.poses) T.linear().setIdentity();
  return positions;
}

// World velocity at every pose stamp.
std::vector<Eigen::Vector3d> velocitiesAtPoses(const Trajectory& T_w_b, const FitOptions& fit) {
  const ContinuousTrajectory fitted = ContinuousTrajectory::fit(positionsOnly(T_w_b), fit);
  std::vector<Eigen::Vector3d> v_w;
  v_w.reserve(T_w_b.size());
  for (const std::int64_t t_ns : T_w_b.t_ns) v_w.push_back(fitted.at(t_ns).v_w);
  return v_w;
}

// The fitted path sampled densely with its arc length; a step slower than min_speed_mps adds none.
struct ArcPath {
  std::int64_t t0_ns = 0, t1_ns = 0, step_ns = 0;
  std::vector<Eigen::Vector3d> p_w;
  std::vector<double> s_m;  // non-decreasing

  ArcPath(const Trajectory& T_w_b, const FitOptions& fit, double min_speed_mps) {
    constexpr std::int64_t kStepNs = 20'000'000;  // 50 Hz: 0.6 m apart at 100 km/h
    const ContinuousTrajectory fitted = ContinuousTrajectory::fit(positionsOnly(T_w_b), fit);
    t0_ns = fitted.t0_ns();
    t1_ns = fitted.t1_ns();
    step_ns = kStepNs;
    for (std::int64_t t = t0_ns;; t = std::min(t + kStepNs, t1_ns)) {
      const Eigen::Vector3d p = fitted.at(t).p_w;
      const double step_m = p_w.empty() ? 0.0 : (p - p_w.back()).norm();
      const bool advances = step_m >= min_speed_mps * 1e-9 * static_cast<double>(kStepNs);
      s_m.push_back(s_m.empty() ? 0.0 : s_m.back() + (advances ? step_m : 0.0));
      p_w.push_back(p);
      if (t == t1_ns) break;
    }
  }
  [[nodiscard]] double length() const { return s_m.back(); }
  // Arc length at a time, linear between the samples around it.
  [[nodiscard]] double arcAt(std::int64_t t_ns) const {
    if (t_ns <= t0_ns) return s_m.front();
    const auto k = static_cast<std::size_t>((t_ns - t0_ns) / step_ns);
    if (k + 1 >= s_m.size()) return s_m.back();
    const std::int64_t t_k = t0_ns + static_cast<std::int64_t>(k) * step_ns;
    const std::int64_t t_next = std::min(t_k + step_ns, t1_ns);  // the last step may be shorter
    const double f = static_cast<double>(t_ns - t_k) / static_cast<double>(t_next - t_k);
    return s_m[k] + std::min(f, 1.0) * (s_m[k + 1] - s_m[k]);
  }
  // Position at an arc length, linear in arc between the samples around it.
  [[nodiscard]] Eigen::Vector3d at(double s) const {
    const auto it = std::lower_bound(s_m.begin(), s_m.end(), s);
    if (it == s_m.begin()) return p_w.front();
    if (it == s_m.end()) return p_w.back();
    const auto k = static_cast<std::size_t>(it - s_m.begin());
    const double f = (s - s_m[k - 1]) / (s_m[k] - s_m[k - 1]);  // s_m[k - 1] < s <= s_m[k]
    return p_w[k - 1] + f * (p_w[k] - p_w[k - 1]);
  }
};

// A vehicle moving along v_w: x along it, y horizontal (no roll), z completing the frame.
// Rz(heading) * Ry(-climb) has x = (cos h cos c, sin h cos c, sin c).
Eigen::Matrix3d vehicleRotation(const Eigen::Vector3d& v_w) {
  const double heading_rad = std::atan2(v_w.y(), v_w.x());
  const double climb_rad = std::atan2(v_w.z(), v_w.head<2>().norm());
  return (Eigen::AngleAxisd(heading_rad, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(-climb_rad, Eigen::Vector3d::UnitY()))
      .toRotationMatrix();
}

double median(std::vector<double> values) {
  const auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), mid, values.end());
  return *mid;
}

}  // namespace

std::optional<OrientationSource> parseOrientationSource(std::string_view name) {
  for (const auto& [text, source] : kSources) {
    if (text == name) return source;
  }
  return std::nullopt;
}

const char* toString(OrientationSource source) {
  for (const auto& [text, s] : kSources) {
    if (s == source) return text.data();
  }
  return "file";
}

Trajectory orientationFromMotion(const Trajectory& T_w_b, const MotionOrientationOptions& options) {
  if (!(options.chord_m > 0.0) || !std::isfinite(options.chord_m) ||
      !(options.min_speed_mps >= 0.0) || !std::isfinite(options.min_speed_mps)) {
    throw InvalidInput(
        "orientation from motion: chord_m must be positive and min_speed_mps not negative");
  }
  const ArcPath path(T_w_b, options.fit, options.min_speed_mps);
  if (path.length() < options.chord_m) {
    throw InvalidInput(
        fmt::format("orientation from motion: the path covers {:.2f} m at over {} m/s, less "
                    "than the {} m a heading is taken over: it gives no heading",
                    path.length(), options.min_speed_mps, options.chord_m));
  }
  Trajectory out = T_w_b;
  std::optional<std::size_t> first_valid;
  for (std::size_t i = 0; i < out.size(); ++i) {
    const double s_begin = std::clamp(path.arcAt(out.t_ns[i]) - 0.5 * options.chord_m, 0.0,
                                      path.length() - options.chord_m);
    const Eigen::Vector3d chord_w = path.at(s_begin + options.chord_m) - path.at(s_begin);
    // A chord much shorter than its path folds back (reversing) or climbs straight up: it has no
    // horizontal direction to follow.
    if (chord_w.head<2>().norm() >= 0.5 * options.chord_m) {
      out.poses[i].linear() = vehicleRotation(chord_w);
      if (!first_valid) first_valid = i;
    } else if (first_valid) {
      out.poses[i].linear() = out.poses[i - 1].linear();
    }
  }
  if (!first_valid) {
    throw InvalidInput(fmt::format(
        "orientation from motion: the path never runs straight for {} m: it gives no heading",
        options.chord_m));
  }
  for (std::size_t i = 0; i < *first_valid; ++i) {
    out.poses[i].linear() = out.poses[*first_valid].linear();
  }
  return out;
}

std::optional<ForwardAxisCheck> checkForwardAxis(const Trajectory& T_w_b, const FitOptions& fit,
                                                 double min_speed_mps) {
  const std::vector<Eigen::Vector3d> v_w = velocitiesAtPoses(T_w_b, fit);
  // Angles of +x, -x, +y, -y, +z, -z of the body to the horizontal travel direction.
  static constexpr std::array<const char*, 6> kAxisNames = {"+x", "-x", "+y", "-y", "+z", "-z"};
  std::array<std::vector<double>, 6> angles_deg;
  for (std::size_t i = 0; i < T_w_b.size(); ++i) {
    const Eigen::Vector3d travel_w(v_w[i].x(), v_w[i].y(), 0.0);
    if (travel_w.norm() <= min_speed_mps) continue;
    const Eigen::Matrix3d R_w_b = T_w_b.poses[i].linear();
    for (std::size_t k = 0; k < 6; ++k) {
      const double sign = k % 2 == 0 ? 1.0 : -1.0;
      const double cosine =
          sign * R_w_b.col(static_cast<Eigen::Index>(k / 2)).dot(travel_w) / travel_w.norm();
      angles_deg[k].push_back(std::acos(std::clamp(cosine, -1.0, 1.0)) * kDegPerRad);
    }
  }
  if (angles_deg[0].empty()) return std::nullopt;
  ForwardAxisCheck check;
  check.moving_poses = angles_deg[0].size();
  check.x_median_deg = median(angles_deg[0]);
  check.closest_median_deg = check.x_median_deg;
  for (std::size_t k = 1; k < 6; ++k) {
    const double m = median(angles_deg[k]);
    if (m < check.closest_median_deg) {
      check.closest_median_deg = m;
      check.closest_axis = kAxisNames[k];
    }
  }
  return check;
}

std::optional<std::string> forwardAxisWarning(const std::optional<ForwardAxisCheck>& check,
                                              const std::string& file) {
  if (!check || check->x_median_deg <= kForwardAxisWarnDeg) return std::nullopt;
  std::string axis_hint;
  if (check->closest_axis != "+x" && check->closest_median_deg <= kForwardAxisWarnDeg) {
    axis_hint = fmt::format("; travel is along its {} axis ({:.1f} deg)", check->closest_axis,
                            check->closest_median_deg);
  }
  return fmt::format(
      "--trajectory {}: the body x axis, which the simulator takes as forward, is {:.1f} deg "
      "(median over {} moving poses) from the direction of travel{}: the simulated cameras will "
      "not look ahead; --orientation motion derives the orientation from the path",
      file, check->x_median_deg, check->moving_poses, axis_hint);
}

}  // namespace gvio::sim
