#pragma once
// A synthetic drive for the GNSS fusion tests: the truth, a drifting VIO in its own world, and
// GNSS fixes with known errors (white noise, optional Gauss-Markov bias, outliers, an outage).
#include <Eigen/Cholesky>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "fusion/geodesy.hpp"
#include "fusion/gnss_covariance.hpp"
#include "fusion/gnss_fusion.hpp"
#include "odometry/lie.hpp"
#include "odometry/measurements.hpp"
#include "odometry/trajectory.hpp"
#include "support/ins_drive.hpp"

namespace gvio::test {

inline constexpr std::int64_t kSecond = 1'000'000'000;

struct GnssDrive {
  Trajectory truth;  // T_enu_b at 10 Hz
  Trajectory vio;    // drifting VIO in its own world
  std::vector<GnssFix> fixes;
  std::vector<bool> outlier;
  fusion::EnuFrame enu{fusion::Lla{48.98, 8.39, 116.0}};
  Eigen::Vector3d lever{0.5, 0.0, 1.5};
};

// 300 s at 10 m/s on a winding road; VIO with 0.2 % scale error and 0.01 deg/s yaw drift;
// GNSS at 1 Hz with white noise (1.5 m h, 3 m v), 2 % outliers of 15-30 m and, when bias_m > 0, a
// Gauss-Markov bias per axis of that steady-state sigma and correlation time.
inline GnssDrive makeGnssDrive(double outage_t0_s = -1, double outage_t1_s = -1,
                               double bias_m = 0.0, double bias_tau_s = 60.0) {
  GnssDrive d;
  std::mt19937_64 rng(7);
  std::normal_distribution<double> n01(0.0, 1.0);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d T_vio = Eigen::Isometry3d::Identity();
  T_vio.linear() = Eigen::AngleAxisd(1.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T_vio.translation() = Eigen::Vector3d(-30, 12, 4);
  // The bias has its own generator so that the other draws do not depend on it.
  std::mt19937_64 rng_bias(11);
  std::normal_distribution<double> n_bias(0.0, 1.0);
  Eigen::Vector3d bias = Eigen::Vector3d::Zero();
  int bias_fixes = 0;
  const double dt = 0.1;
  for (int k = 0; k <= 3000; ++k) {
    const std::int64_t t_ns = k * kSecond / 10;
    if (k > 0) {
      const double time = k * dt;
      Eigen::Isometry3d step = Eigen::Isometry3d::Identity();
      step.linear() = odometry::expSo3(
          Eigen::Vector3d(0, 0.001 * std::sin(0.1 * time), 0.06 * std::sin(0.03 * time) * dt));
      step.translation() = Eigen::Vector3d(10.0 * dt, 0, 0);
      T = T * step;
      Eigen::Isometry3d step_vio = step;
      step_vio.translation() *= 1.002;
      step_vio.linear() =
          odometry::expSo3(Eigen::Vector3d(0, 0, 0.01 * M_PI / 180 * dt)) * step_vio.linear();
      T_vio = T_vio * step_vio;
    }
    d.truth.t_ns.push_back(t_ns);
    d.truth.poses.push_back(T);
    d.vio.t_ns.push_back(t_ns);
    d.vio.poses.push_back(T_vio);
    const double t_s = k * dt;
    if (k % 10 != 0 || (t_s >= outage_t0_s && t_s <= outage_t1_s)) continue;
    // Draws are sequenced (unsequenced arguments made the drive depend on the compiler), in the
    // order GCC evaluated them, so the drive, and the bounds tuned on it, stay as they were.
    const double noise_u = 3.0 * n01(rng), noise_n = 1.5 * n01(rng), noise_e = 1.5 * n01(rng);
    Eigen::Vector3d p = T * d.lever + Eigen::Vector3d(noise_e, noise_n, noise_u);
    // b_{k+1} = phi b_k + w, var(w) = sigma^2 (1 - phi^2) (fixes 1 s apart).
    const double phi = std::exp(-1.0 / bias_tau_s);
    const double w_u = n_bias(rng_bias), w_n = n_bias(rng_bias), w_e = n_bias(rng_bias);
    bias = (bias_fixes == 0 ? 0.0 : phi) * bias +
           bias_m * std::sqrt(bias_fixes == 0 ? 1.0 : 1.0 - phi * phi) *
               Eigen::Vector3d(w_e, w_n, w_u);
    ++bias_fixes;
    p += bias;
    const bool bad = u01(rng) < 0.02;
    if (bad) {
      const double size_m = 15.0 + 15.0 * u01(rng);
      const double dn = n01(rng), de = n01(rng);
      p += Eigen::Vector3d(de, dn, 0.2).normalized() * size_m;
    }
    d.fixes.push_back(fixAt(d.enu, t_ns, p, 1.5, 3.0));
    d.outlier.push_back(bad);
  }
  return d;
}

// The drive of makeGnssDrive with white fix errors drawn from thin ellipses (major_m x minor_m
// 1-sigma semi-axes, vertical 3 m) whose orientation turns through 180 degrees every 150 fixes,
// as a receiver's geometry turns; each fix states that ellipse with its horizontal sigma times
// stated_factor (1: right; 0.5: optimistic by 2). No outliers.
inline GnssDrive makeEllipseGnssDrive(std::uint64_t seed, double major_m = 3.0,
                                      double minor_m = 0.5, double stated_factor = 1.0) {
  GnssDrive d = makeGnssDrive();
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  for (std::size_t k = 0; k < d.fixes.size(); ++k) {
    GnssFix& fix = d.fixes[k];
    const double orientation_deg = 180.0 * static_cast<double>(k) / 150.0;
    const Eigen::Matrix2d cov_en = fusion::ellipseCovariance(major_m, minor_m, orientation_deg);
    // Draws sequenced: the order of a call's arguments is the compiler's choice.
    const double w_e = n01(rng), w_n = n01(rng), w_u = n01(rng);
    const Eigen::Vector2d e_en = cov_en.llt().matrixL() * Eigen::Vector2d(w_e, w_n);
    const std::size_t pose = static_cast<std::size_t>(fix.t_ns / (kSecond / 10));
    const Eigen::Vector3d p =
        d.truth.poses[pose] * d.lever + Eigen::Vector3d(e_en.x(), e_en.y(), 3.0 * w_u);
    fix = fixAt(d.enu, fix.t_ns, p, stated_factor * std::sqrt(cov_en.trace() / 2.0),
                stated_factor * 3.0);
    fix.shape_en = fusion::horizontalShape(cov_en);
    d.outlier[k] = false;
  }
  return d;
}

// Feeds the drive to the fusion in time order (each fix before the VIO poses after it), as a run
// does, and finishes it.
inline void replay(fusion::GnssFusion& fusion, const GnssDrive& d) {
  std::size_t f = 0;
  for (std::size_t k = 0; k < d.vio.size(); ++k) {
    while (f < d.fixes.size() && d.fixes[f].t_ns <= d.vio.t_ns[k]) fusion.addFix(d.fixes[f++]);
    fusion.addVioPose(d.vio.t_ns[k], d.vio.poses[k]);
  }
  fusion.finish();
}

// Position RMSE of `est` against the truth pose with the same index, from index `from` on.
inline double rmse(const Trajectory& truth, const Trajectory& est, std::size_t from = 0) {
  double sum = 0.0;
  std::size_t n = 0;
  for (std::size_t k = from; k < est.size(); ++k) {
    sum += (est.poses[k].translation() - truth.poses[k].translation()).squaredNorm();
    ++n;
  }
  return std::sqrt(sum / static_cast<double>(n));
}

}  // namespace gvio::test
