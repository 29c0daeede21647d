#include "fusion/gnss_ins.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <string>

#include "fusion/gnss_covariance.hpp"
#include "fusion/ins_heading_bank.hpp"
#include "odometry/error.hpp"
#include "odometry/lie.hpp"

namespace gvio::fusion {
namespace {

using Clock = std::chrono::steady_clock;

constexpr double kDegToRad = std::numbers::pi / 180.0;

void requirePositive(double value, const char* key) {
  if (!(std::isfinite(value) && value > 0.0)) {
    throw InvalidInput(std::string("config: ") + key + " must be a positive number");
  }
}

double seconds(std::int64_t dt_ns) {
  return static_cast<double>(dt_ns) * 1e-9;
}

}  // namespace

void InsConfig::validate() const {
  if (!lever_arm_b.allFinite()) throw InvalidInput("config: fusion.lever_arm_b must be finite");
  if (!std::isfinite(receiver_time_offset_s) || std::abs(receiver_time_offset_s) > 10.0) {
    throw InvalidInput("config: fusion.receiver_time_offset_s must be within +-10 s");
  }
  requirePositive(gate_chi2, "fusion.gate_chi2");
  if (max_consecutive_rejections < 0) {
    throw InvalidInput("config: fusion.max_consecutive_rejections must be >= 0");
  }
  requirePositive(outage_s, "fusion.outage_s");
  imu.validate();
  requirePositive(time_offset_sigma_s, "fusion.ins.time_offset_sigma_s");
  requirePositive(time_offset_random_walk, "fusion.ins.time_offset_random_walk");
  requirePositive(velocity_sigma_mps, "fusion.ins.velocity_sigma_mps");
  if (!(std::isfinite(velocity_min_speed_mps) && velocity_min_speed_mps >= 0.0)) {
    throw InvalidInput("config: fusion.ins.velocity_min_speed_mps must be >= 0");
  }
  requirePositive(velocity_gate_chi2, "fusion.ins.velocity_gate_chi2");
  requirePositive(nhc_sigma_mps, "fusion.ins.nhc_sigma_mps");
  if (!mount_rpy_deg.allFinite() || mount_rpy_deg.cwiseAbs().maxCoeff() > 180.0) {
    throw InvalidInput("config: fusion.ins.mount_rpy_deg must be three angles within +-180 deg");
  }
  requirePositive(init_window_s, "fusion.ins.init_window_s");
  requirePositive(init_min_speed_mps, "fusion.ins.init_min_speed_mps");
  requirePositive(init_tilt_sigma_deg, "fusion.ins.init_tilt_sigma_deg");
  requirePositive(init_heading_sigma_deg, "fusion.ins.init_heading_sigma_deg");
  requirePositive(init_velocity_sigma_mps, "fusion.ins.init_velocity_sigma_mps");
  requirePositive(init_acc_bias_sigma_mps2, "fusion.ins.init_acc_bias_sigma_mps2");
  requirePositive(init_gyr_bias_sigma_radps, "fusion.ins.init_gyr_bias_sigma_radps");
  requirePositive(max_imu_gap_s, "fusion.ins.max_imu_gap_s");
  requirePositive(mount.min_speed_mps, "fusion.ins.mount_min_speed_mps");
  if (mount.min_samples < 3)
    throw InvalidInput("config: fusion.ins.mount_min_samples must be >= 3");
  if (!(mount.min_concentration > 0.0 && mount.min_concentration <= 1.0)) {
    throw InvalidInput("config: fusion.ins.mount_min_concentration must be in (0, 1]");
  }
  requirePositive(align.chunk_s, "fusion.ins.align_chunk_s");
  requirePositive(align.max_window_s, "fusion.ins.align_max_window_s");
  if (!(align.max_window_s > align.chunk_s)) {
    throw InvalidInput(
        "config: fusion.ins.align_max_window_s must exceed fusion.ins.align_chunk_s");
  }
  requirePositive(align.max_heading_sigma_deg, "fusion.ins.align_max_heading_sigma_deg");
  requirePositive(align.min_speed_mps, "fusion.ins.align_min_speed_mps");
  requirePositive(align.quiet_gyro_std_radps, "fusion.ins.align_quiet_gyro_std_radps");
  requirePositive(align.quiet_gyro_mean_radps, "fusion.ins.align_quiet_gyro_mean_radps");
  requirePositive(align.quiet_acc_mps2, "fusion.ins.align_quiet_acc_mps2");
  if (align.hypotheses != 0 && (align.hypotheses < 4 || align.hypotheses > 72)) {
    throw InvalidInput("config: fusion.ins.align_hypotheses must be 0 (off) or 4..72");
  }
  requirePositive(align.same_solution_deg, "fusion.ins.align_same_solution_deg");
  requirePositive(align.min_nll_gap, "fusion.ins.align_min_nll_gap");
  requirePositive(align.bank_max_heading_sigma_deg, "fusion.ins.align_bank_max_heading_sigma_deg");
  if (!(align.imu_orientation_max_sigma_deg >= 0.0 &&
        align.imu_orientation_max_sigma_deg <= 90.0)) {
    throw InvalidInput("config: fusion.ins.align_imu_orientation_max_sigma_deg must be in [0, 90]");
  }
}

std::optional<Eigen::Vector2d> fixVelocityEn(const GnssFix& fix) {
  if (!std::isfinite(fix.speed_mps) || !std::isfinite(fix.course_deg) || fix.speed_mps < 0.0) {
    return std::nullopt;
  }
  const double course = fix.course_deg * kDegToRad;  // clockwise from north
  return Eigen::Vector2d(fix.speed_mps * std::sin(course), fix.speed_mps * std::cos(course));
}

GnssIns::GnssIns(const InsConfig& config, const EnuFrame& enu)
    : config_(config), enu_(enu), mount_estimator_(config.mount) {
  config_.validate();
  R_v_b_config_ = odometry::rotationZyx(config_.mount_rpy_deg * kDegToRad);
  R_v_b_ = R_v_b_config_;
  mount_known_ = !config_.estimatesMount();
  x_.time_offset_s = config_.receiver_time_offset_s;
}

GnssIns::GnssIns(GnssIns&&) noexcept = default;
GnssIns& GnssIns::operator=(GnssIns&&) noexcept = default;
GnssIns::~GnssIns() = default;

void GnssIns::startAt(const ImuSample& anchor, const InsState& x, const InsMatrix& P,
                      bool record_poses) {
  record_poses_ = record_poses;
  x_ = x;
  P_ = P;
  last_imu_ = anchor;
  initialized_ = true;
  stats_.t_init_ns = anchor.t_ns;
  stats_.t_heading_ns = anchor.t_ns;
  stats_.init_method = "given";
  recordPose();
}

double GnssIns::stampMinusFilter(std::int64_t t_ns) const {
  return last_imu_ ? seconds(t_ns - last_imu_->t_ns) : 0.0;
}

void GnssIns::recordPose() {
  if (!record_poses_) return;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = x_.R_enu_b;
  T.translation() = x_.p_enu;
  trajectory_.t_ns.push_back(last_imu_->t_ns);
  trajectory_.poses.push_back(T);
}

void GnssIns::addImu(const ImuSample& s) {
  ++stats_.imu_samples;
  if (last_imu_ && s.t_ns <= last_imu_->t_ns) return;  // readers guarantee increasing stamps
  if (initialized_) {
    propagate(s);
  } else {
    bufferImu(s);
  }
}

void GnssIns::propagate(const ImuSample& s) {
  const double dt = seconds(s.t_ns - last_imu_->t_ns);
  if (dt > config_.max_imu_gap_s) ++stats_.imu_gaps;
  // The previous sample is held over [t_prev, t] (zero-order hold).
  const InsMatrix Phi = transitionMatrix(x_, last_imu_->acc_b_mps2, last_imu_->gyr_b_radps, dt);
  x_ = propagateNominal(x_, last_imu_->acc_b_mps2, last_imu_->gyr_b_radps, dt);
  P_ = Phi * P_ * Phi.transpose() +
       processNoise(config_.imu,
                    config_.estimate_time_offset ? config_.time_offset_random_walk : 0.0, dt);
  P_ = 0.5 * (P_ + P_.transpose()).eval();
  last_imu_ = s;
  recordPose();
}

void GnssIns::addFix(const GnssFix& fix) {
  const auto start = Clock::now();
  const Eigen::Vector3d p_ant = enu_.toEnu({fix.lat_deg, fix.lon_deg, fix.h_ellipsoid_m});
  if (!initialized_) {
    tryInitialize(fix, p_ant);
  } else {
    processFix(fix, p_ant);
  }
  prev_fix_ = std::make_pair(fix.t_ns, p_ant);
  stats_.ms_per_fix.push_back(
      std::chrono::duration<double, std::milli>(Clock::now() - start).count());
}

void GnssIns::processFix(const GnssFix& fix, const Eigen::Vector3d& p_ant) {
  updatePosition(fix, p_ant);
  if (config_.use_velocity) updateVelocity(fix);
  if (config_.use_nhc && mount_known_) updateNonHolonomic();
  if (config_.estimatesMount()) updateMount();
}

void GnssIns::updateMount() {
  mount_estimator_.add(x_.R_enu_b.transpose() * x_.v_enu_mps);
  stats_.mount = mount_estimator_.estimate(R_v_b_config_);
  if (stats_.mount) {
    R_v_b_ = stats_.mount->R_v_b;
    mount_known_ = true;
  }
}

template <int Rows>
bool GnssIns::update(const InsMeasurement<Rows>& m, const Eigen::Matrix<double, Rows, 1>& z,
                     const Eigen::Matrix<double, Rows, Rows>& R, double gate_chi2, bool force,
                     double* nll) {
  using MatrixR = Eigen::Matrix<double, Rows, Rows>;
  const Eigen::Matrix<double, Rows, 1> y = z - m.h;
  const MatrixR S = m.H * P_ * m.H.transpose() + R;
  const Eigen::LDLT<MatrixR> ldlt(S);
  if (ldlt.info() != Eigen::Success) return false;
  const double d2 = y.dot(ldlt.solve(y));  // normalised innovation squared (Groves eq. 17.7)
  if (nll != nullptr) {
    *nll = std::min(d2, 4.0 * gate_chi2) + ldlt.vectorD().array().log().sum();
  }
  if (!force && !(d2 <= gate_chi2)) return false;
  // K = P H^T S^-1; Joseph form (Groves eq. 3.88) keeps P symmetric positive definite.
  const Eigen::Matrix<double, kInsDim, Rows> K =
      ldlt.solve(m.H * P_).transpose();  // S symmetric: (S^-1 H P)^T = P H^T S^-1
  const InsVector dx = K * y;
  const InsMatrix I_KH = InsMatrix::Identity() - K * m.H;
  P_ = I_KH * P_ * I_KH.transpose() + K * R * K.transpose();
  x_ = injectError(x_, dx);
  const InsMatrix G = resetJacobian(dx);
  P_ = G * P_ * G.transpose();
  P_ = 0.5 * (P_ + P_.transpose()).eval();
  return true;
}

void GnssIns::updatePosition(const GnssFix& fix, const Eigen::Vector3d& p_ant) {
  const InsMeasurement<3> m =
      antennaPosition(x_, last_imu_->gyr_b_radps, config_.lever_arm_b, stampMinusFilter(fix.t_ns));
  const Eigen::Matrix3d R = gnssCovariance(fix.sigma_h_m, fix.sigma_v_m, fix.shape_en);
  const bool force = consecutive_rejections_ >= config_.max_consecutive_rejections;
  if (force) {
    // Re-convergence after a run of rejections: widen the position uncertainty to the innovation
    // so that the filter moves to the fixes instead of trusting its coasted solution.
    const Eigen::Vector3d y = p_ant - m.h;
    P_.block<3, 3>(kInsP, kInsP) += Eigen::Vector3d(y.cwiseAbs2()).asDiagonal();
  }
  double nll = 0.0;
  const bool applied = update<3>(m, p_ant, R, config_.gate_chi2, force, &nll);
  stats_.position_nll += nll;
  if (!applied) {
    ++stats_.fixes_rejected;
    ++consecutive_rejections_;
    stats_.fixes.push_back({fix.t_ns, p_ant, InsFixStatus::kRejected});
    return;
  }
  if (force) ++stats_.fixes_forced;
  consecutive_rejections_ = 0;
  ++stats_.fixes_used;
  stats_.fixes.push_back({fix.t_ns, p_ant, InsFixStatus::kUsed});
  if (last_accepted_ns_ && seconds(fix.t_ns - *last_accepted_ns_) > config_.outage_s) {
    stats_.outages.emplace_back(*last_accepted_ns_, fix.t_ns);
  }
  last_accepted_ns_ = fix.t_ns;
}

void GnssIns::updateVelocity(const GnssFix& fix) {
  const std::optional<Eigen::Vector2d> v_en = fixVelocityEn(fix);
  if (!v_en || fix.speed_mps < config_.velocity_min_speed_mps) return;
  const InsMeasurement<2> m = antennaVelocityEn(x_, last_imu_->acc_b_mps2, last_imu_->gyr_b_radps,
                                                config_.lever_arm_b, stampMinusFilter(fix.t_ns));
  const Eigen::Matrix2d R =
      config_.velocity_sigma_mps * config_.velocity_sigma_mps * Eigen::Matrix2d::Identity();
  if (update<2>(m, *v_en, R, config_.velocity_gate_chi2, false)) {
    ++stats_.velocity_used;
  } else {
    ++stats_.velocity_rejected;
  }
}

void GnssIns::updateNonHolonomic() {
  const Eigen::Matrix2d R =
      config_.nhc_sigma_mps * config_.nhc_sigma_mps * Eigen::Matrix2d::Identity();
  const InsMeasurement<2> m = vehicleLateralVerticalVelocity(x_, R_v_b_);
  stats_.nhc_innovation_sum_mps -= m.h;
  if (update<2>(m, Eigen::Vector2d::Zero(), R, config_.velocity_gate_chi2, false)) {
    ++stats_.nhc_used;
  } else {
    ++stats_.nhc_rejected;
  }
}

void GnssIns::finish() {
  if (!initialized_) flushPendingBeforeInit();
  if (!initialized_ || !last_accepted_ns_ || !last_imu_) return;
  if (seconds(last_imu_->t_ns - *last_accepted_ns_) > config_.outage_s) {
    stats_.outages.emplace_back(*last_accepted_ns_, last_imu_->t_ns);
  }
}

}  // namespace gvio::fusion
