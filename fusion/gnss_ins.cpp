#include "fusion/gnss_ins.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <string>

#include "odometry/error.hpp"

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

// Body -> ENU rotation from the body's up direction (unit, body frame) and the heading of the
// body x axis (rad, counter-clockwise from east): R = Rz(yaw) Ry(pitch) Rx(roll), with
// R^T e_up = (-sin pitch, cos pitch sin roll, cos pitch cos roll).
Eigen::Matrix3d rotationFromUpAndYaw(const Eigen::Vector3d& up_b, double yaw_rad) {
  const double pitch = std::asin(std::clamp(-up_b.x(), -1.0, 1.0));
  const double roll = std::atan2(up_b.y(), up_b.z());
  return (Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
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
}

std::optional<Eigen::Vector2d> fixVelocityEn(const GnssFix& fix) {
  if (!std::isfinite(fix.speed_mps) || !std::isfinite(fix.course_deg) || fix.speed_mps < 0.0) {
    return std::nullopt;
  }
  const double course = fix.course_deg * kDegToRad;  // clockwise from north
  return Eigen::Vector2d(fix.speed_mps * std::sin(course), fix.speed_mps * std::cos(course));
}

GnssIns::GnssIns(const InsConfig& config, const EnuFrame& enu) : config_(config), enu_(enu) {
  config_.validate();
  const Eigen::Vector3d rpy = config_.mount_rpy_deg * kDegToRad;
  R_v_b_ = (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
            Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
            Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
               .toRotationMatrix();
  x_.time_offset_s = config_.receiver_time_offset_s;
}

double GnssIns::stampMinusFilter(std::int64_t t_ns) const {
  return last_imu_ ? seconds(t_ns - last_imu_->t_ns) : 0.0;
}

void GnssIns::recordPose() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = x_.R_enu_b;
  T.translation() = x_.p_enu;
  trajectory_.t_ns.push_back(last_imu_->t_ns);
  trajectory_.poses.push_back(T);
}

void GnssIns::addImu(const ImuSample& s) {
  ++stats_.imu_samples;
  if (last_imu_ && s.t_ns <= last_imu_->t_ns) return;  // readers guarantee increasing stamps
  if (!initialized_) {
    ++stats_.imu_before_init;
    init_imu_.push_back(s);
    const auto window_ns = static_cast<std::int64_t>(config_.init_window_s * 1e9);
    while (init_imu_.front().t_ns < s.t_ns - window_ns) init_imu_.pop_front();
    last_imu_ = s;
    return;
  }
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
    updatePosition(fix, p_ant);
    if (config_.use_velocity) updateVelocity(fix);
    if (config_.use_nhc) updateNonHolonomic();
  }
  prev_fix_ = std::make_pair(fix.t_ns, p_ant);
  stats_.ms_per_fix.push_back(
      std::chrono::duration<double, std::milli>(Clock::now() - start).count());
}

void GnssIns::tryInitialize(const GnssFix& fix, const Eigen::Vector3d& p_ant) {
  std::optional<Eigen::Vector2d> v_en = fixVelocityEn(fix);
  if (!v_en && prev_fix_) {
    const double dt = seconds(fix.t_ns - prev_fix_->first);
    if (dt > 0.0 && dt <= 2.0) v_en = (p_ant - prev_fix_->second).head<2>() / dt;
  }
  const auto window_ns = static_cast<std::int64_t>(config_.init_window_s * 1e9);
  if (v_en) init_fix_v_.push_back({fix.t_ns, *v_en});
  while (!init_fix_v_.empty() && init_fix_v_.front().t_ns < fix.t_ns - window_ns) {
    init_fix_v_.pop_front();
  }
  const bool moving = v_en && v_en->norm() >= config_.init_min_speed_mps;
  const bool imu_ready = last_imu_ && init_imu_.size() >= 5 &&
                         init_imu_.back().t_ns - init_imu_.front().t_ns >= window_ns / 2;
  if (!moving || !imu_ready) {
    ++stats_.fixes_before_init;
    stats_.fixes.push_back({fix.t_ns, p_ant, InsFixStatus::kBeforeInit});
    return;
  }
  // Coarse levelling (Groves section 5.6.2) from the mean specific force f = R^T (a - g), with the
  // acceleration a over the window taken from the GNSS velocities: up_b = normalise(f - R^T a),
  // iterated because R itself depends on the tilt.
  Eigen::Vector3d f_mean = Eigen::Vector3d::Zero();
  for (const ImuSample& s : init_imu_) f_mean += s.acc_b_mps2;
  f_mean /= static_cast<double>(init_imu_.size());
  Eigen::Vector3d a_enu = Eigen::Vector3d::Zero();
  const FixVelocity& oldest = init_fix_v_.front();
  const double span_s = seconds(fix.t_ns - oldest.t_ns);
  if (span_s >= 0.3 * config_.init_window_s) a_enu.head<2>() = (*v_en - oldest.v_en) / span_s;
  const double yaw = std::atan2(v_en->y(), v_en->x());  // the body x axis along the course
  Eigen::Vector3d up_b = f_mean.normalized();
  Eigen::Matrix3d R = rotationFromUpAndYaw(up_b, yaw);
  for (int i = 0; i < 3; ++i) {
    up_b = (f_mean - R.transpose() * a_enu).normalized();
    R = rotationFromUpAndYaw(up_b, yaw);
  }
  x_.R_enu_b = R;
  x_.v_enu_mps = Eigen::Vector3d(v_en->x(), v_en->y(), 0.0);
  x_.p_enu = p_ant - R * config_.lever_arm_b -
             x_.v_enu_mps * (stampMinusFilter(fix.t_ns) + x_.time_offset_s);
  P_.setZero();
  P_.block<3, 3>(kInsP, kInsP).diagonal() << fix.sigma_h_m * fix.sigma_h_m,
      fix.sigma_h_m * fix.sigma_h_m, fix.sigma_v_m * fix.sigma_v_m;
  P_.block<3, 3>(kInsV, kInsV).diagonal().setConstant(std::pow(config_.init_velocity_sigma_mps, 2));
  // Tilt and heading sigmas are about ENU axes; the error angle is in the body (local) frame.
  const double tilt = config_.init_tilt_sigma_deg * kDegToRad;
  const double heading = config_.init_heading_sigma_deg * kDegToRad;
  const Eigen::Vector3d att_var(tilt * tilt, tilt * tilt, heading * heading);
  P_.block<3, 3>(kInsTheta, kInsTheta) = R.transpose() * att_var.asDiagonal() * R;
  P_.block<3, 3>(kInsBa, kInsBa)
      .diagonal()
      .setConstant(std::pow(config_.init_acc_bias_sigma_mps2, 2));
  P_.block<3, 3>(kInsBg, kInsBg)
      .diagonal()
      .setConstant(std::pow(config_.init_gyr_bias_sigma_radps, 2));
  P_(kInsTau, kInsTau) =
      config_.estimate_time_offset ? std::pow(config_.time_offset_sigma_s, 2) : 0.0;
  initialized_ = true;
  stats_.t_init_ns = last_imu_->t_ns;
  last_accepted_ns_ = fix.t_ns;
  ++stats_.fixes_used;
  stats_.fixes.push_back({fix.t_ns, p_ant, InsFixStatus::kUsed});
  init_imu_.clear();
  init_fix_v_.clear();
  recordPose();
}

template <int Rows>
bool GnssIns::update(const InsMeasurement<Rows>& m, const Eigen::Matrix<double, Rows, 1>& z,
                     const Eigen::Matrix<double, Rows, Rows>& R, double gate_chi2, bool force) {
  using MatrixR = Eigen::Matrix<double, Rows, Rows>;
  const Eigen::Matrix<double, Rows, 1> y = z - m.h;
  const MatrixR S = m.H * P_ * m.H.transpose() + R;
  const Eigen::LDLT<MatrixR> ldlt(S);
  if (ldlt.info() != Eigen::Success) return false;
  const double d2 = y.dot(ldlt.solve(y));  // normalised innovation squared (Groves eq. 17.7)
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
  const Eigen::Vector3d var(fix.sigma_h_m * fix.sigma_h_m, fix.sigma_h_m * fix.sigma_h_m,
                            fix.sigma_v_m * fix.sigma_v_m);
  const Eigen::Matrix3d R = var.asDiagonal();
  const bool force = consecutive_rejections_ >= config_.max_consecutive_rejections;
  if (force) {
    // Re-convergence after a run of rejections: widen the position uncertainty to the innovation
    // so that the filter moves to the fixes instead of trusting its coasted solution.
    const Eigen::Vector3d y = p_ant - m.h;
    P_.block<3, 3>(kInsP, kInsP) += Eigen::Vector3d(y.cwiseAbs2()).asDiagonal();
  }
  if (!update<3>(m, p_ant, R, config_.gate_chi2, force)) {
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
  if (!initialized_ || !last_accepted_ns_ || !last_imu_) return;
  if (seconds(last_imu_->t_ns - *last_accepted_ns_) > config_.outage_s) {
    stats_.outages.emplace_back(*last_accepted_ns_, last_imu_->t_ns);
  }
}

}  // namespace gvio::fusion
