#pragma once
// GNSS-assisted VIO, loosely coupled and online: VIO poses and GNSS fixes stream in time order and
// every VIO pose gets a fused body pose in local ENU as soon as it arrives (causal). Two modes:
//  - kf: the reference method's 6-state Kalman filter on the VIO position/velocity error after a
//    rigid VIO-world -> ENU registration (fusion/kf_baseline.hpp);
//  - graph (ours): VIO relative-pose factors + robust GNSS position factors with chi-square gating,
//    per-fix sigma, lever arm, over a bounded window with a marginalisation prior
//    (fusion/graph_window.hpp).
// During outages both coast on the VIO motion; the intervals are reported.
#include <Eigen/Geometry>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "fusion/geodesy.hpp"
#include "fusion/gnss_smoother.hpp"
#include "fusion/kf_baseline.hpp"
#include "fusion/vio_enu_alignment.hpp"
#include "odometry/measurements.hpp"
#include "odometry/trajectory.hpp"

namespace gvio::fusion {

enum class FusionMode { kKf, kGraph };
std::string toString(FusionMode mode);
FusionMode parseFusionMode(const std::string& name);  // "kf" | "graph"; throws InvalidInput

struct FusionConfig {
  FusionMode mode = FusionMode::kGraph;
  Eigen::Vector3d lever_arm_b = Eigen::Vector3d::Zero();  // antenna in the body frame (m)
  double receiver_time_offset_s = 0.0;  // added to every fix stamp (receiver clock latency)
  AlignmentDof alignment = AlignmentDof::kYawTranslation;  // full rotation without an IMU
  int alignment_min_fixes = 5;
  double alignment_min_extent_m = 20.0;
  // Full-rotation registration (no IMU) waits for this spread across the path (m, standard
  // deviation); before it the yaw + translation registration stands in (vio_enu_alignment.hpp).
  double alignment_min_cross_extent_m = 10.0;
  // VIO relative-motion noise between consecutive nodes: drift per metre travelled plus a floor.
  double vio_drift_fraction = 0.004;
  double vio_sigma_floor_m = 0.02;
  double vio_rot_drift_rad_per_m = 1e-5;
  double vio_rot_floor_rad = 5e-4;
  // With an IMU (alignment kYawTranslation): the nodes of the online window and of the smoother
  // keep the roll and pitch the VIO observed, within this 1 sigma (TiltFactor). Fixes and relative
  // poses alone leave the roll about a straight path free: a 12 s straight drive came out rolled
  // 42 deg. With the tilt held, the first node's heading shows in its fix only through the lever
  // arm's horizontal part (none for an antenna above the body), so it keeps the registration's
  // heading (a yaw prior).
  double tilt_sigma_deg = 1.0;
  int window_nodes = 20;
  double huber_sigmas = 2.0;
  double gate_chi2 = 16.27;  // chi-square, 3 degrees of freedom, 99.9 %
  // Added (in quadrature, per axis) to the gate's predicted sigma: the VIO's motion between fixes
  // is less accurate than vio_drift_fraction says just after initialisation, and the newest node
  // is itself uncertain. Without it accurate (RTK-grade) fixes fail the gate and are dropped.
  double gate_floor_m = 0.5;
  int max_consecutive_rejections = 5;  // then the next fix is accepted (re-convergence)
  double outage_s = 3.0;               // no accepted fix for longer than this is an outage
  KfConfig kf;
  SmootherConfig smoother;  // graph mode: the offline pass after the drive
  void validate() const;    // throws InvalidInput naming the field
  // The vio_* fields as the VIO relative-motion noise model of the graph and the smoother.
  // TiltFactor's sigma (rad) when the VIO observes gravity (an IMU), else 0 (no tilt factor).
  [[nodiscard]] double tiltSigmaRad() const;
  [[nodiscard]] RelativeNoise relativeNoise() const {
    return {vio_drift_fraction, vio_sigma_floor_m, vio_rot_drift_rad_per_m, vio_rot_floor_rad};
  }
};

// What became of one screened fix.
enum class FixStatus {
  kUsed,       // fused
  kRejected,   // failed the chi-square gate
  kUnmatched,  // outside the VIO trajectory (no pose to compare with)
  kUnaligned,  // the VIO never registered to ENU, so the fix was never fused
};
std::string toString(FixStatus status);  // used | rejected | unmatched | unaligned

struct FixOutcome {
  std::int64_t t_ns = 0;                            // after the receiver time offset
  Eigen::Vector3d p_enu = Eigen::Vector3d::Zero();  // the antenna position the fix reports
  FixStatus status = FixStatus::kUsed;
  double sigma_h_m = 0.0, sigma_v_m = 0.0;  // as the fix reports them
  int quality = 1;                          // NMEA GGA fix quality (RTK fixed 4, float 5, ...)
  Eigen::Matrix2d shape_en = Eigen::Matrix2d::Identity();  // its ellipse (GnssFix::shape_en)
};

struct FusionStats {
  int fixes_used = 0;
  int fixes_rejected = 0;   // chi-square gate
  int fixes_unmatched = 0;  // outside the VIO trajectory (before it starts, after it ends, gaps)
  int poses_before_alignment = 0;  // fused with the first registration, back-filled
  std::vector<std::pair<std::int64_t, std::int64_t>> outages;  // [t0, t1] without accepted fixes
  std::vector<double> ms_per_fix;  // fusion cost of each processed fix (informational)
  std::vector<FixOutcome> fixes;   // every screened fix in time order (maps, plots)
  double ms_smoothing = 0.0;       // the offline smoothing pass (graph mode), 0 when not run
  int smoother_outliers = 0;       // fixes the smoother left out (SmootherConfig::learn_noise)
  // Per fix quality: the factors the smoother learned for the stated sigmas (horizontal, vertical).
  std::map<int, Eigen::Vector2d> smoother_sigma_scale;
  // kf mode with fusion.kf.learn_noise: the factors learned online at the end of the drive.
  std::map<int, Eigen::Vector2d> kf_sigma_scale;
};

class GnssFusion {
 public:
  GnssFusion(const FusionConfig& config, const EnuFrame& enu);
  ~GnssFusion();
  GnssFusion(const GnssFusion&) = delete;
  GnssFusion& operator=(const GnssFusion&) = delete;

  // VIO body pose in the VIO world, in time order.
  void addVioPose(std::int64_t t_ns, const Eigen::Isometry3d& T_w_b);
  // A screened fix (fusion/gnss_screening.hpp), in time order; used once VIO poses bracket it.
  void addFix(const GnssFix& fix);
  // Processes the fixes still waiting and closes the last outage.
  void finish();

  // T_enu_b of every VIO pose added, as known when it was added (causal; empty until the first
  // registration succeeds).
  [[nodiscard]] Trajectory fusedTrajectory() const;
  // After finish(), graph mode with the smoother enabled and >= 2 fixes used: T_enu_b of every VIO
  // pose from the batch smoothing pass over all fixes (fusion/gnss_smoother.hpp); else empty.
  [[nodiscard]] Trajectory smoothedTrajectory() const;
  // The covariance of each smoothed pose (fusion/gnss_smoother.hpp PoseCovariance), empty when
  // there is no smoothed trajectory or the covariance could not be computed.
  [[nodiscard]] const std::vector<PoseCovariance>& smoothedCovariance() const;
  [[nodiscard]] const FusionStats& stats() const;
  [[nodiscard]] std::optional<Eigen::Isometry3d> T_enu_w() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace gvio::fusion
