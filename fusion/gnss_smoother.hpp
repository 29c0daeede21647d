#pragma once
// Offline smoothing pass of the global fusion ("graph" mode): after the drive, one batch solve
// over every accepted fix (nodes at the fix times, VIO relative-pose factors between consecutive
// nodes, robust GNSS position factors) gives each node the estimate that uses the fixes after it as
// well as those before (a fixed-interval smoother; the online window only sees the past). The VIO
// poses between two nodes take the blend of the two nodes carried by the VIO motion, so the VIO's
// own shape is kept between fixes.
//
// Optionally the receiver's slowly varying error (multipath, atmosphere: SPP errors are strongly
// correlated over tens of seconds) is modelled as a first-order Gauss-Markov bias per axis,
//   b_{k+1} = phi b_k + w_k, phi = exp(-dt / tau), var(w_k) = sigma_b^2 (1 - phi^2)
// (Groves 2013, "Principles of GNSS, Inertial, and Multisensor Integrated Navigation Systems",
// 2nd ed., eq. 14.74 / App. I), with the fix p_fix = p_antenna + b + white noise. Without it a
// correlated error is taken for truth by every fix it touches. One chain per fix quality: an RTK
// fixed, a float and a single-point solution are different error processes.
#include <Eigen/Geometry>
#include <cstdint>
#include <map>
#include <vector>

#include "odometry/trajectory.hpp"

namespace gvio::fusion {

struct SmootherConfig {
  bool enabled = true;
  // Gauss-Markov receiver bias per axis: its steady-state sigma as a fraction of the fix's reported
  // horizontal sigma (receivers report their white noise; the correlated part scales with it:
  // SPP ~1 m, RTK ~1 cm); 0 leaves the bias out of the model.
  double bias_ratio = 0.5;
  double bias_tau_s = 60.0;
  int max_iterations = 50;
  // What the fixes say of themselves, learned after a first solve from their residuals against
  // the smoothed trajectory (the VIO shape plus the slow bias), per fix quality (an RTK fixed and
  // a float solution state their sigmas differently well): with at least min_fixes_to_learn
  // fixes of a quality (fewer: those of every quality together), the robust spread of the whitened
  // residuals (1.4826 MAD, horizontal and vertical apart) scales the sigmas up where they were
  // optimistic (never down: a correlated error hides in small residuals), and a fix whose residual
  // lies beyond outlier_chi2 (3 degrees of freedom, 99.9 %) of that spread is left out (a multipath
  // burst, a wrong RTK fix), then the solve is repeated, up to max_rounds. The spread used to find
  // outliers is at least min_learned_scale of the stated sigmas: stated sigmas far too pessimistic
  // still leave a margin.
  bool learn_noise = true;
  int min_fixes_to_learn = 10;
  double outlier_chi2 = 16.27;
  double min_learned_scale = 0.25;
  int max_rounds = 3;
  void validate() const;  // throws InvalidInput naming the field
};

// One accepted fix with what the online fusion knew of it.
struct SmootherFix {
  std::int64_t t_ns = 0;
  Eigen::Isometry3d T_w_b = Eigen::Isometry3d::Identity();    // VIO pose at the fix time
  Eigen::Isometry3d T_enu_b = Eigen::Isometry3d::Identity();  // online estimate (initial guess)
  Eigen::Vector3d p_enu = Eigen::Vector3d::Zero();            // antenna position of the fix
  double sigma_h_m = 1.0, sigma_v_m = 1.0;
  int quality = 1;  // NMEA GGA fix quality: the noise is learned per quality
  Eigen::Matrix2d shape_en = Eigen::Matrix2d::Identity();  // the stated ellipse's shape
};

// The VIO relative-motion noise between nodes: sigma = fraction * distance + floor (rotation:
// rad per metre + floor), as the online window uses.
struct RelativeNoise {
  double drift_fraction = 0.004;
  double sigma_floor_m = 0.02;
  double rot_drift_rad_per_m = 1e-5;
  double rot_floor_rad = 5e-4;

  [[nodiscard]] double positionSigmaM(double distance_m) const {
    return drift_fraction * distance_m + sigma_floor_m;
  }
  [[nodiscard]] double rotationSigmaRad(double distance_m) const {
    return rot_drift_rad_per_m * distance_m + rot_floor_rad;
  }
};

// Covariance of a pose in ENU-aligned axes: (rotation about E, N, U (rad); position E, N, U (m)),
// i.e. the perturbation T = (Exp(dtheta) R, p + dp).
using PoseCovariance = Eigen::Matrix<double, 6, 6>;

struct SmoothedNodes {
  std::vector<Eigen::Isometry3d> T_enu_b;  // at each fix, same order
  std::vector<bool> outlier;               // per fix: left out by the learned noise
  // Per fix quality: the factors applied to the stated sigmas (horizontal, vertical).
  std::map<int, Eigen::Vector2d> sigma_scale;
  // Marginal covariance of each node (ceres::Covariance, sparse QR); empty when the solve's
  // Jacobian was too ill-conditioned to invert (then no covariance is reported, never a guess).
  std::vector<PoseCovariance> covariance;
};

// The smoothed body pose T_enu_b at each fix. `lever_arm_b`: antenna in the body.
// `tilt_sigma_rad` > 0 (the VIO has an IMU): a TiltFactor per node keeps the VIO's roll and pitch.
SmoothedNodes smoothNodes(const std::vector<SmootherFix>& fixes, const Eigen::Vector3d& lever_arm_b,
                          const RelativeNoise& noise, double huber_sigmas,
                          const SmootherConfig& config, double tilt_sigma_rad = 0.0);

// Every VIO pose in ENU: between nodes i and i+1 the two nodes carried by the VIO motion, blended
// linearly in time (slerp for the rotation); before the first / after the last node, that node
// carried by the VIO. `nodes` must be in time order with `smoothed` of the same size (>= 1).
// With `covariance_out` and node covariances: each pose's covariance is the blend of its nodes'
// plus the VIO drift (noise model) over the distance to the nearer node.
Trajectory spreadOverVio(const Trajectory& vio, const std::vector<SmootherFix>& nodes,
                         const SmoothedNodes& smoothed, const RelativeNoise& noise = {},
                         std::vector<PoseCovariance>* covariance_out = nullptr);

}  // namespace gvio::fusion
