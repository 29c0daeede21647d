#include "sim/trajectory_fit.hpp"

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "odometry/error.hpp"
#include "odometry/lie.hpp"

namespace gvio::sim {
namespace {

using odometry::eulerZyx;
using odometry::rotationZyx;
using Vector6d = Eigen::Matrix<double, 6, 1>;

constexpr double kNsPerS = 1e9;
constexpr double kMaxPitchRad = 80.0 * std::numbers::pi / 180.0;
// Smallest pivot of the LDL^T factorisation, relative to the largest, that counts as full rank.
constexpr double kMinRelativePivot = 1e-12;

// Uniform cubic B-spline basis on one segment (de Boor, "A Practical Guide to Splines", ch. IX):
// s(u) = sum_k c_{i+k} B_k(s), s in [0, 1] the local parameter of segment i, and its first and
// second derivatives with respect to s.
struct SplineBasis {
  int segment = 0;
  std::array<double, 4> b{}, db{}, ddb{};
};

SplineBasis basisAt(double t_s, double spacing_s, int segments) {
  const double u = t_s / spacing_s;
  SplineBasis out;
  out.segment = std::clamp(static_cast<int>(std::floor(u)), 0, segments - 1);
  const double s = std::clamp(u - out.segment, 0.0, 1.0);
  const double s2 = s * s, s3 = s2 * s, r = 1.0 - s;
  out.b = {r * r * r / 6.0, (3.0 * s3 - 6.0 * s2 + 4.0) / 6.0,
           (-3.0 * s3 + 3.0 * s2 + 3.0 * s + 1.0) / 6.0, s3 / 6.0};
  out.db = {-r * r / 2.0, (3.0 * s2 - 4.0 * s) / 2.0, (-3.0 * s2 + 2.0 * s + 1.0) / 2.0, s2 / 2.0};
  out.ddb = {r, 3.0 * s - 2.0, 1.0 - 3.0 * s, s};
  return out;
}

// Body angular rate from ZYX Euler rates: omega_b = E(roll, pitch) * (roll', pitch', yaw')
// for the 3-2-1 (ZYX) sequence (Diebel, "Representing Attitude", 2006, Euler angle rates).
Eigen::Vector3d bodyRateZyx(const Eigen::Vector3d& rpy, const Eigen::Vector3d& rpy_dot) {
  const double sr = std::sin(rpy.x()), cr = std::cos(rpy.x());
  const double sp = std::sin(rpy.y()), cp = std::cos(rpy.y());
  return {rpy_dot.x() - rpy_dot.z() * sp, rpy_dot.y() * cr + rpy_dot.z() * sr * cp,
          -rpy_dot.y() * sr + rpy_dot.z() * cr * cp};
}

// `angle` shifted by a multiple of 2 pi so it lies within pi of `previous`.
double unwrapNear(double angle, double previous) {
  constexpr double kTwoPi = 2.0 * std::numbers::pi;
  return angle + kTwoPi * std::round((previous - angle) / kTwoPi);
}

void validateInput(const Trajectory& T_w_b) {
  if (!T_w_b.hasTimestamps()) {
    throw InvalidInput("trajectory fit: the poses have no timestamps");
  }
  if (T_w_b.t_ns.size() != T_w_b.poses.size()) {
    throw InvalidInput("trajectory fit: " + std::to_string(T_w_b.t_ns.size()) + " timestamps for " +
                       std::to_string(T_w_b.poses.size()) + " poses");
  }
  if (T_w_b.size() < 4) {
    throw InvalidInput("trajectory fit: needs at least 4 poses (got " +
                       std::to_string(T_w_b.size()) + ")");
  }
  const std::int64_t bad = firstNonIncreasingStamp(T_w_b);
  if (bad >= 0) {
    throw InvalidInput("trajectory fit: timestamp of pose " + std::to_string(bad) +
                       " does not increase strictly");
  }
}

// Per-pose samples of the six channels (x, y, z, roll, pitch, yaw); roll and yaw are unwrapped
// so the splines see continuous angles across +-pi.
Eigen::MatrixXd channelSamples(const Trajectory& T_w_b) {
  Eigen::MatrixXd y(static_cast<Eigen::Index>(T_w_b.size()), 6);
  for (std::size_t i = 0; i < T_w_b.size(); ++i) {
    const auto row = static_cast<Eigen::Index>(i);
    Eigen::Vector3d rpy = eulerZyx(T_w_b.poses[i].linear());
    if (std::abs(rpy.y()) > kMaxPitchRad) {
      throw InvalidInput("trajectory fit: pose " + std::to_string(i) +
                         " pitches beyond +-80 deg (Euler angles degenerate)");
    }
    if (i > 0) {
      rpy.x() = unwrapNear(rpy.x(), y(row - 1, 3));
      rpy.z() = unwrapNear(rpy.z(), y(row - 1, 5));
    }
    y.row(row).head<3>() = T_w_b.poses[i].translation().transpose();
    y.row(row).tail<3>() = rpy.transpose();
  }
  return y;
}

// P-spline normal equations (Eilers & Marx 1996, eq. 5): (B^T B + lambda D2^T D2) c = B^T y,
// with B the banded B-spline design matrix and D2 the second-difference operator.
Eigen::SparseMatrix<double> normalMatrix(const std::vector<SplineBasis>& bases, int controls,
                                         double smoothing) {
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(bases.size() * 16 + static_cast<std::size_t>(controls) * 10);
  for (const SplineBasis& basis : bases) {
    for (int r = 0; r < 4; ++r) {
      for (int c = 0; c < 4; ++c) {
        entries.emplace_back(basis.segment + r, basis.segment + c, basis.b[r] * basis.b[c]);
      }
    }
  }
  constexpr std::array<double, 3> kSecondDifference = {1.0, -2.0, 1.0};
  for (int j = 0; j + 2 < controls; ++j) {
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) {
        entries.emplace_back(j + r, j + c, smoothing * kSecondDifference[r] * kSecondDifference[c]);
      }
    }
  }
  Eigen::SparseMatrix<double> normal(controls, controls);
  normal.setFromTriplets(entries.begin(), entries.end());
  return normal;
}

std::vector<Vector6d> solvePSpline(const std::vector<SplineBasis>& bases, const Eigen::MatrixXd& y,
                                   int controls, double smoothing) {
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(controls, 6);
  for (std::size_t i = 0; i < bases.size(); ++i) {
    for (int k = 0; k < 4; ++k) {
      rhs.row(bases[i].segment + k) += bases[i].b[k] * y.row(static_cast<Eigen::Index>(i));
    }
  }
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(
      normalMatrix(bases, controls, smoothing));
  // Without smoothing, a control point no sample constrains leaves the system singular.
  if (solver.info() != Eigen::Success ||
      !(solver.vectorD().minCoeff() > kMinRelativePivot * solver.vectorD().cwiseAbs().maxCoeff())) {
    throw InvalidInput(
        "trajectory fit: the poses do not determine the splines (raise smoothing or "
        "knot_spacing_s)");
  }
  const Eigen::MatrixXd solution = solver.solve(rhs);
  if (!solution.allFinite()) throw InvalidInput("trajectory fit: spline solve failed");
  std::vector<Vector6d> control(static_cast<std::size_t>(controls));
  for (int j = 0; j < controls; ++j) control[static_cast<std::size_t>(j)] = solution.row(j);
  return control;
}

// Residuals of the fit at the given stamps: position distance and rotation angle of
// R_fit^T R_given.
FitReport fitReport(const ContinuousTrajectory& fitted, const Trajectory& T_w_b) {
  FitReport report;
  report.poses = T_w_b.size();
  double position_sq = 0.0, rotation_sq = 0.0;
  for (std::size_t i = 0; i < T_w_b.size(); ++i) {
    const BodyState state = fitted.at(T_w_b.t_ns[i]);
    const double dp = (state.p_w - T_w_b.poses[i].translation()).norm();
    const double dr_deg =
        Eigen::AngleAxisd(state.R_w_b.transpose() * T_w_b.poses[i].linear()).angle() * 180.0 /
        std::numbers::pi;
    position_sq += dp * dp;
    rotation_sq += dr_deg * dr_deg;
    report.position_max_m = std::max(report.position_max_m, dp);
    report.rotation_max_deg = std::max(report.rotation_max_deg, dr_deg);
  }
  const auto n = static_cast<double>(report.poses);
  report.position_rms_m = std::sqrt(position_sq / n);
  report.rotation_rms_deg = std::sqrt(rotation_sq / n);
  return report;
}

}  // namespace

Eigen::Isometry3d BodyState::pose() const {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R_w_b;
  T.translation() = p_w;
  return T;
}

ContinuousTrajectory ContinuousTrajectory::fit(const Trajectory& T_w_b, const FitOptions& options) {
  if (!(options.knot_spacing_s > 0.0) || !std::isfinite(options.knot_spacing_s)) {
    throw InvalidInput("trajectory fit: knot_spacing_s must be a positive number");
  }
  if (!(options.smoothing >= 0.0) || !std::isfinite(options.smoothing)) {
    throw InvalidInput("trajectory fit: smoothing must be a non-negative number");
  }
  validateInput(T_w_b);
  const Eigen::MatrixXd y = channelSamples(T_w_b);

  ContinuousTrajectory out;
  out.t0_ns_ = T_w_b.t_ns.front();
  out.t1_ns_ = T_w_b.t_ns.back();
  // An integer number of segments spans [t0, t1] exactly, so the spacing shrinks slightly;
  // at least one segment keeps at least 4 control points.
  const double duration_s = static_cast<double>(out.t1_ns_ - out.t0_ns_) / kNsPerS;
  const int segments =
      std::max(1, static_cast<int>(std::ceil(duration_s / options.knot_spacing_s)));
  out.knot_spacing_s_ = duration_s / segments;

  std::vector<SplineBasis> bases;
  bases.reserve(T_w_b.size());
  for (const std::int64_t t_ns : T_w_b.t_ns) {
    bases.push_back(
        basisAt(static_cast<double>(t_ns - out.t0_ns_) / kNsPerS, out.knot_spacing_s_, segments));
  }
  out.control_ = solvePSpline(bases, y, segments + 3, options.smoothing);
  out.report_ = fitReport(out, T_w_b);
  return out;
}

BodyState ContinuousTrajectory::at(std::int64_t t_ns) const {
  if (control_.empty()) throw std::logic_error("ContinuousTrajectory::at before fit()");
  const std::int64_t clamped = std::clamp(t_ns, t0_ns_, t1_ns_);
  const double t_s = static_cast<double>(clamped - t0_ns_) / kNsPerS;
  const int segments = static_cast<int>(control_.size()) - 3;
  const SplineBasis basis = basisAt(t_s, knot_spacing_s_, segments);

  // d/dt = (1/h) d/ds, d2/dt2 = (1/h^2) d2/ds2 for the local parameter s = t/h - i.
  Vector6d value = Vector6d::Zero(), rate = Vector6d::Zero(), accel = Vector6d::Zero();
  for (int k = 0; k < 4; ++k) {
    const Vector6d& c = control_[static_cast<std::size_t>(basis.segment + k)];
    value += basis.b[k] * c;
    rate += basis.db[k] * c;
    accel += basis.ddb[k] * c;
  }
  rate /= knot_spacing_s_;
  accel /= knot_spacing_s_ * knot_spacing_s_;

  BodyState state;
  state.p_w = value.head<3>();
  state.v_w = rate.head<3>();
  state.a_w = accel.head<3>();
  state.R_w_b = rotationZyx(value.tail<3>());
  state.omega_b = bodyRateZyx(value.tail<3>(), rate.tail<3>());
  return state;
}

}  // namespace gvio::sim
