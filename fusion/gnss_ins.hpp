#pragma once
// GNSS/INS without a camera: a loosely coupled error-state Kalman filter in local ENU (Groves,
// "Principles of GNSS, Inertial, and Multisensor Integrated Navigation Systems", 2nd ed., ch. 14;
// Sola 2017, "Quaternion kinematics for the error-state Kalman filter"). The IMU propagates the
// nominal state (fusion/ins_error_model.hpp); GNSS fixes correct it with their antenna position
// (lever arm, per-fix sigma, first-order receiver time offset, optionally estimated) and, when the
// receiver reports it, the horizontal velocity from speed and course. Innovations are chi-square
// gated with a bounded number of consecutive rejections; periods without accepted fixes are coasted
// on the IMU and reported as outages.
//
// Initialisation, whichever comes first:
// - track alignment (fusion/ins_alignment.hpp): levelled and gyro-bias-corrected at an anchor
//   (at rest or quiet), the heading found from the IMU's accelerations and turns against the GNSS
//   track, whatever the IMU's yaw in the vehicle; the filter then starts at the anchor and
//   replays every IMU sample and fix since, so fixes before the heading was known are used;
// - the GNSS course of a vehicle moving faster than init_min_speed_mps (a car): roll and pitch
//   from the mean specific force of the last init_window_s, corrected by the GNSS-measured
//   acceleration; heading from the course turned by the configured mount yaw.
// The IMU's mounting in the vehicle (the non-holonomic constraint's frame) is estimated from the
// direction the filter moves in, in the body frame (fusion/ins_mount.hpp), unless configured.
#include <Eigen/Core>
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include <string>
#include <variant>

#include "fusion/geodesy.hpp"
#include "fusion/imu_attitude.hpp"
#include "fusion/ins_alignment.hpp"
#include "fusion/ins_error_model.hpp"
#include "fusion/ins_mount.hpp"
#include "odometry/measurements.hpp"
#include "odometry/trajectory.hpp"

namespace gvio::fusion {

struct InsConfig {
  // Shared with the camera fusion (the app copies fusion.lever_arm_b, receiver_time_offset_s,
  // gate_chi2, max_consecutive_rejections and outage_s into these).
  Eigen::Vector3d lever_arm_b = Eigen::Vector3d::Zero();  // GNSS antenna in the body frame (m)
  double receiver_time_offset_s = 0.0;  // a fix stamped t is the antenna position at t + this
  double gate_chi2 = 16.27;             // position innovation gate (3 dof, 99.9 %)
  int max_consecutive_rejections = 5;   // then the next fix is accepted (re-convergence)
  double outage_s = 3.0;                // no accepted fix for longer than this is an outage
  ImuNoise imu;                         // the app sets imu.* (or the dataset's own noise)

  // INS-only settings (fusion.ins.*).
  bool estimate_time_offset = true;       // the receiver time offset is a filter state
  double time_offset_sigma_s = 0.1;       // its initial 1-sigma around receiver_time_offset_s
  double time_offset_random_walk = 1e-4;  // s/sqrt(s)
  bool use_velocity = true;               // fuse speed + course when the receiver reports them
  double velocity_sigma_mps = 0.2;        // 1-sigma per horizontal axis of that velocity
  double velocity_min_speed_mps = 2.0;    // below this the course is not used
  double velocity_gate_chi2 = 13.82;      // velocity innovation gate (2 dof, 99.9 %)
  // Non-holonomic constraint (a car moves along its forward axis), applied at each fix: the
  // vehicle's lateral and vertical velocity 0 with this 1-sigma (it also absorbs the IMU's offset
  // from the rear axle in turns). Gated like the velocity. The vehicle frame (forward-left-up) is
  // the IMU body frame turned by the mounting angles: roll, pitch, yaw of the IMU in the vehicle,
  // R_v_b = Rz(yaw) Ry(pitch) Rx(roll); a tilt left unconfigured biases the constraint by
  // speed x tilt.
  bool use_nhc = true;
  double nhc_sigma_mps = 0.3;
  Eigen::Vector3d mount_rpy_deg = Eigen::Vector3d::Zero();
  // Estimate the mount's yaw and pitch from the direction of travel (the constraint waits for
  // it) when mount_rpy_deg is left at zero; a configured mount is used as it is (the filter's
  // attitude, from which the estimate comes, is less accurate than a measured mount: 0.4 deg on
  // the unit tests' drive, 0.53 m 3-D against 0.33 m with the configured mount).
  bool estimate_mount = true;
  MountConfig mount;
  AlignmentConfig align;                // fusion.ins.align_*
  double init_window_s = 1.0;           // IMU samples averaged for roll / pitch
  double init_min_speed_mps = 3.0;      // GNSS speed at which the heading is taken from the course
  double init_tilt_sigma_deg = 2.0;     // initial roll / pitch 1-sigma
  double init_heading_sigma_deg = 5.0;  // initial heading 1-sigma
  double init_velocity_sigma_mps = 0.5;
  double init_acc_bias_sigma_mps2 = 0.2;
  double init_gyr_bias_sigma_radps = 0.005;
  double max_imu_gap_s = 0.1;  // longer IMU periods are counted as gaps (still integrated)

  void validate() const;  // throws InvalidInput naming the key (fusion.ins.*)
  // The mount is estimated: estimate_mount with mount_rpy_deg left at zero.
  [[nodiscard]] bool estimatesMount() const { return estimate_mount && mount_rpy_deg.isZero(0.0); }
};

enum class InsFixStatus { kUsed, kRejected, kBeforeInit };

struct InsFixOutcome {
  std::int64_t t_ns = 0;                            // the fix's stamp
  Eigen::Vector3d p_enu = Eigen::Vector3d::Zero();  // the antenna position it reports
  InsFixStatus status = InsFixStatus::kUsed;
};

struct InsStats {
  int imu_samples = 0;
  int imu_gaps = 0;
  int imu_before_init = 0;
  int fixes_used = 0;
  int fixes_rejected = 0;     // chi-square gate
  int fixes_forced = 0;       // accepted after max_consecutive_rejections (among fixes_used)
  int fixes_before_init = 0;  // waiting for motion (heading) and the IMU window
  int velocity_used = 0;
  int velocity_rejected = 0;
  int nhc_used = 0;
  int nhc_rejected = 0;
  // Sum of the constraint's innovations (vehicle lateral, vertical velocity before each update):
  // a mean far from 0 says the vehicle frame is wrong (an unconfigured IMU tilt).
  Eigen::Vector2d nhc_innovation_sum_mps = Eigen::Vector2d::Zero();
  std::optional<std::int64_t> t_init_ns;     // where the trajectory starts
  std::optional<std::int64_t> t_heading_ns;  // when the heading became known
  // "track" (the alignment's sums), "heading bank", "course"; "" not initialised
  std::string init_method;
  double init_heading_sigma_deg = 0.0;
  bool init_quiet_start = false;     // the gyro bias came from a quiet anchor window
  double align_mount_yaw_deg = 0.0;  // the track alignment's mount yaw (from turns) and 1-sigma
  double align_mount_yaw_sigma_deg = 0.0;
  int alignment_restarts = 0;          // windows without a heading, started again later
  std::optional<MountEstimate> mount;  // the estimated mount, when estimate_mount
  // -2 log-likelihood of the position innovations, sum of d2 (capped at 4 x the gate: one
  // outlier is not a verdict) + log det S: what the heading bank ranks its scouts by.
  double position_nll = 0.0;
  std::vector<std::pair<std::int64_t, std::int64_t>> outages;  // [t0, t1] without accepted fixes
  std::vector<double> ms_per_fix;                              // update cost of each fix
  std::vector<InsFixOutcome> fixes;                            // every fix given, in time order
};

class HeadingBank;

class GnssIns {
 public:
  GnssIns(const InsConfig& config, const EnuFrame& enu);
  GnssIns(GnssIns&&) noexcept;
  GnssIns& operator=(GnssIns&&) noexcept;
  ~GnssIns();

  // IMU samples and fixes in one time-ordered stream: a fix is given before the first IMU sample
  // later than its stamp. Fixes are applied at the filter time of the last IMU sample (causal).
  void addImu(const ImuSample& sample);
  void addFix(const GnssFix& fix);
  // An attitude the IMU reports, given before the first IMU sample later than its stamp: until
  // the filter is initialised, the latest one can give the heading (fusion.ins.align_imu_*).
  void addAttitude(const ImuAttitude& attitude);
  // Closes the last outage at the last IMU sample.
  void finish();
  // Starts the filter at `anchor` with this state and covariance instead of initialising it
  // (the heading bank's scouts, fusion/ins_heading_bank.hpp, which keep no trajectory: twelve of
  // them at 200 Hz would hold 40 MB a minute).
  void startAt(const ImuSample& anchor, const InsState& x, const InsMatrix& P,
               bool record_poses = true);

  [[nodiscard]] bool initialized() const { return initialized_; }
  [[nodiscard]] const InsState& state() const { return x_; }
  [[nodiscard]] const InsMatrix& covariance() const { return P_; }
  // T_enu_b after every IMU sample from initialisation on.
  [[nodiscard]] const Trajectory& trajectory() const { return trajectory_; }
  [[nodiscard]] const InsStats& stats() const { return stats_; }

 private:
  struct FixVelocity {
    std::int64_t t_ns = 0;
    Eigen::Vector2d v_en = Eigen::Vector2d::Zero();
  };

  using Event = std::variant<ImuSample, GnssFix>;

  void bufferImu(const ImuSample& sample);
  void propagate(const ImuSample& sample);
  void processFix(const GnssFix& fix, const Eigen::Vector3d& p_ant_enu);
  void tryInitialize(const GnssFix& fix, const Eigen::Vector3d& p_ant_enu);
  [[nodiscard]] bool tryCourseInitialize(const GnssFix& fix, const Eigen::Vector3d& p_ant_enu);
  void initializeFromAlignment(const AlignmentSolution& solution, const std::string& method);
  void startBank();  // the scouts, from the anchor, fed what pending_ holds
  // The heading of the IMU's own attitude at the last sample, as the levelled frame's yaw.
  [[nodiscard]] bool tryAttitudeHeading();
  // Initialises from the alignment with the heading an attitude of now gives (the heading bank's
  // winner, the IMU's own); false when the alignment has no solution with it.
  [[nodiscard]] bool initializeFromAttitudeNow(const Eigen::Matrix3d& R_enu_b,
                                               double heading_sigma_rad, const std::string& method);
  // P at initialisation: the fix's position sigmas, the configured velocity, tilt and bias
  // sigmas, this heading sigma.
  void setInitialCovariance(const GnssFix& fix, double heading_sigma_rad);
  [[nodiscard]] InsMatrix initialCovariance(const GnssFix& fix, const Eigen::Matrix3d& R_enu_b,
                                            double heading_sigma_rad) const;
  void startAlignment();
  void recordBeforeInit(const GnssFix& fix);
  void flushPendingBeforeInit();
  void updateMount();
  void updatePosition(const GnssFix& fix, const Eigen::Vector3d& p_ant_enu);
  void updateVelocity(const GnssFix& fix);
  void updateNonHolonomic();
  // Kalman update with gating; returns true when applied.
  template <int Rows>
  bool update(const InsMeasurement<Rows>& m, const Eigen::Matrix<double, Rows, 1>& z,
              const Eigen::Matrix<double, Rows, Rows>& R, double gate_chi2, bool force,
              double* nll = nullptr);
  void recordPose();
  [[nodiscard]] double stampMinusFilter(std::int64_t t_ns) const;

  InsConfig config_;
  EnuFrame enu_;
  Eigen::Matrix3d R_v_b_config_ = Eigen::Matrix3d::Identity();  // from mount_rpy_deg
  Eigen::Matrix3d R_v_b_ = Eigen::Matrix3d::Identity();         // in use (estimated or config)
  bool record_poses_ = true;
  bool mount_known_ = false;  // the constraint may be applied
  MountEstimator mount_estimator_;
  std::optional<TrackAlignment> align_;
  std::unique_ptr<HeadingBank> bank_;    // scouts over headings, while the alignment has none
  std::optional<ImuAttitude> attitude_;  // the IMU's latest reported attitude, before init
  std::vector<Event> pending_;  // since the alignment's anchor, replayed once it has a heading
  bool initialized_ = false;
  InsState x_;
  InsMatrix P_ = InsMatrix::Zero();
  std::optional<ImuSample> last_imu_;
  std::deque<ImuSample> init_imu_;      // the last init_window_s of samples before initialisation
  std::deque<FixVelocity> init_fix_v_;  // GNSS velocities over the same window
  std::optional<std::pair<std::int64_t, Eigen::Vector3d>> prev_fix_;  // for differenced velocity
  std::optional<std::int64_t> last_accepted_ns_;
  int consecutive_rejections_ = 0;
  Trajectory trajectory_;
  InsStats stats_;
};

// The horizontal velocity a fix reports (east, north), from speed and course; nullopt without.
std::optional<Eigen::Vector2d> fixVelocityEn(const GnssFix& fix);

}  // namespace gvio::fusion
