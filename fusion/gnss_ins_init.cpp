// GnssIns's initialisation (fusion/gnss_ins.hpp): the track alignment with its replay, and the
// course of a fast-moving vehicle.
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>

#include "fusion/gnss_covariance.hpp"
#include "fusion/gnss_ins.hpp"
#include "fusion/ins_heading_bank.hpp"

namespace gvio::fusion {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;
// A fix's horizontal velocity differenced from the previous fix is used for the course only over
// at least this long, and only when its speed exceeds init_min_speed by 3 sigma of the
// differencing noise (sqrt 2 sigma_h / dt): SPP noise must not pass for motion.
constexpr double kMinDifferencingS = 0.5, kMaxDifferencingS = 2.0;

double seconds(std::int64_t dt_ns) {
  return static_cast<double>(dt_ns) * 1e-9;
}

}  // namespace

void GnssIns::recordBeforeInit(const GnssFix& fix) {
  ++stats_.fixes_before_init;
  stats_.fixes.push_back({fix.t_ns, enu_.toEnu({fix.lat_deg, fix.lon_deg, fix.h_ellipsoid_m}),
                          InsFixStatus::kBeforeInit});
}

void GnssIns::flushPendingBeforeInit() {
  for (const Event& e : pending_) {
    if (const auto* fix = std::get_if<GnssFix>(&e)) recordBeforeInit(*fix);
  }
  pending_.clear();
}

void GnssIns::startAlignment() {
  flushPendingBeforeInit();
  bank_.reset();
  align_.emplace(config_.align, std::vector<ImuSample>(init_imu_.begin(), init_imu_.end()),
                 config_.lever_arm_b);
  pending_.emplace_back(init_imu_.back());  // the anchor: where a replay would start
}

void GnssIns::bufferImu(const ImuSample& s) {
  ++stats_.imu_before_init;
  init_imu_.push_back(s);
  const auto window_ns = static_cast<std::int64_t>(config_.init_window_s * 1e9);
  while (init_imu_.front().t_ns < s.t_ns - window_ns) init_imu_.pop_front();
  last_imu_ = s;
  const bool window_ready =
      init_imu_.size() >= 5 && init_imu_.back().t_ns - init_imu_.front().t_ns >= window_ns / 2;
  if (!align_) {
    if (window_ready) startAlignment();
    return;
  }
  align_->addImu(s);
  pending_.emplace_back(s);
  if (bank_) bank_->addImu(s);
  // The window counts from the end of a quiet start: waiting at rest costs no window.
  const std::optional<std::int64_t> moving = align_->movingSinceNs();
  if (moving && seconds(s.t_ns - *moving) > config_.align.max_window_s && window_ready) {
    ++stats_.alignment_restarts;  // no heading in this window: anchor again, here
    startAlignment();
  }
}

void GnssIns::tryInitialize(const GnssFix& fix, const Eigen::Vector3d& p_ant) {
  if (align_) {
    pending_.emplace_back(fix);
    align_->addFix(fix.t_ns, p_ant, fix.sigma_h_m);
    if (bank_) {
      bank_->addFix(fix);
    } else if (config_.align.hypotheses > 0) {
      startBank();
    }
    if (const std::optional<AlignmentSolution> solution = align_->solve()) {
      initializeFromAlignment(*solution, "track");
      return;
    }
    if (tryAttitudeHeading()) return;
    const double max_sigma = config_.align.bank_max_heading_sigma_deg * kDegToRad;
    const std::optional<HeadingChoice> choice = bank_ ? bank_->choose(max_sigma) : std::nullopt;
    if (choice && initializeFromAttitudeNow(choice->R_enu_b, choice->sigma_rad, "heading bank")) {
      return;
    }
  }
  if (tryCourseInitialize(fix, p_ant)) return;
  if (!align_) recordBeforeInit(fix);  // else it waits in pending_
}

void GnssIns::addAttitude(const ImuAttitude& attitude) {
  if (!initialized_) attitude_ = attitude;
}

bool GnssIns::tryAttitudeHeading() {
  const double max_sigma = config_.align.imu_orientation_max_sigma_deg * kDegToRad;
  // The attitude must be of now (within 50 ms of the last sample): it is compared with the
  // levelled frame's attitude now.
  constexpr std::int64_t kMaxAgeNs = 50'000'000;
  if (!attitude_ || !last_imu_ || max_sigma <= 0.0 || attitude_->yaw_sigma_rad > max_sigma ||
      std::abs(attitude_->t_ns - last_imu_->t_ns) > kMaxAgeNs) {
    return false;
  }
  return initializeFromAttitudeNow(attitude_->R_enu_b, attitude_->yaw_sigma_rad, "imu orientation");
}

bool GnssIns::initializeFromAttitudeNow(const Eigen::Matrix3d& R_enu_b, double heading_sigma_rad,
                                        const std::string& method) {
  // The levelled frame's yaw: the attitude now against the gyros' integrated from the anchor.
  const Eigen::Matrix3d R = R_enu_b * align_->attitudeNow().transpose();
  const double psi = std::atan2(R(1, 0), R(0, 0));
  const auto solution = align_->solutionWithHeading(psi, heading_sigma_rad);
  if (!solution) return false;
  initializeFromAlignment(*solution, method);
  return true;
}

void GnssIns::startBank() {
  const auto& anchor = std::get<ImuSample>(pending_.front());
  const GnssFix& fix = std::get<GnssFix>(pending_.back());
  InsState start;
  start.R_enu_b = align_->anchorAttitude();
  start.p_enu = enu_.toEnu({fix.lat_deg, fix.lon_deg, fix.h_ellipsoid_m}) -
                Eigen::Vector3d(0.0, 0.0, (start.R_enu_b * config_.lever_arm_b).z());
  start.ba_b_mps2 = align_->accBias();
  start.bg_b_radps = align_->gyrBias();
  start.time_offset_s = config_.receiver_time_offset_s;
  bank_ = std::make_unique<HeadingBank>(config_, enu_, anchor, start,
                                        initialCovariance(fix, start.R_enu_b, 0.0));
  for (std::size_t k = 1; k < pending_.size(); ++k) {
    if (const auto* s = std::get_if<ImuSample>(&pending_[k])) {
      bank_->addImu(*s);
    } else {
      bank_->addFix(std::get<GnssFix>(pending_[k]));
    }
  }
}

InsMatrix GnssIns::initialCovariance(const GnssFix& fix, const Eigen::Matrix3d& R,
                                     double heading_sigma_rad) const {
  InsMatrix P = InsMatrix::Zero();
  P.block<3, 3>(kInsP, kInsP) = gnssCovariance(fix.sigma_h_m, fix.sigma_v_m, fix.shape_en);
  P.block<3, 3>(kInsV, kInsV).diagonal().setConstant(std::pow(config_.init_velocity_sigma_mps, 2));
  // Tilt and heading sigmas are about ENU axes; the error angle is in the body (local) frame.
  const double tilt = config_.init_tilt_sigma_deg * kDegToRad;
  const Eigen::Vector3d att_var(tilt * tilt, tilt * tilt, heading_sigma_rad * heading_sigma_rad);
  P.block<3, 3>(kInsTheta, kInsTheta) = R.transpose() * att_var.asDiagonal() * R;
  P.block<3, 3>(kInsBa, kInsBa)
      .diagonal()
      .setConstant(std::pow(config_.init_acc_bias_sigma_mps2, 2));
  P.block<3, 3>(kInsBg, kInsBg)
      .diagonal()
      .setConstant(std::pow(config_.init_gyr_bias_sigma_radps, 2));
  P(kInsTau, kInsTau) =
      config_.estimate_time_offset ? std::pow(config_.time_offset_sigma_s, 2) : 0.0;
  return P;
}

void GnssIns::setInitialCovariance(const GnssFix& fix, double heading_sigma_rad) {
  P_ = initialCovariance(fix, x_.R_enu_b, heading_sigma_rad);
}

void GnssIns::initializeFromAlignment(const AlignmentSolution& a, const std::string& method) {
  std::vector<Event> events;
  events.swap(pending_);
  align_.reset();
  bank_.reset();
  // Events up to the anchor sample are before initialisation; the rest are replayed.
  std::size_t k = 0;
  for (; k < events.size(); ++k) {
    if (const auto* s = std::get_if<ImuSample>(&events[k]); s && s->t_ns == a.anchor.t_ns) break;
    if (const auto* fix = std::get_if<GnssFix>(&events[k])) recordBeforeInit(*fix);
  }
  const GnssFix* first_fix = nullptr;
  for (std::size_t i = k; i < events.size() && first_fix == nullptr; ++i) {
    first_fix = std::get_if<GnssFix>(&events[i]);
  }
  if (first_fix == nullptr) first_fix = &std::get<GnssFix>(events.back());
  x_.R_enu_b = a.R_enu_b;
  const Eigen::Vector3d p_ant =
      enu_.toEnu({first_fix->lat_deg, first_fix->lon_deg, first_fix->h_ellipsoid_m});
  x_.p_enu =
      Eigen::Vector3d(a.p_en.x(), a.p_en.y(), p_ant.z() - (a.R_enu_b * config_.lever_arm_b).z());
  x_.v_enu_mps = Eigen::Vector3d(a.v_en.x(), a.v_en.y(), 0.0);
  x_.ba_b_mps2 = a.ba_b_mps2;
  x_.bg_b_radps = a.bg_b_radps;
  setInitialCovariance(*first_fix, std::max(a.heading_sigma_rad, 0.5 * kDegToRad));
  initialized_ = true;
  stats_.t_init_ns = a.anchor.t_ns;
  stats_.t_heading_ns = last_imu_->t_ns;
  stats_.init_method = method;
  stats_.init_heading_sigma_deg = a.heading_sigma_rad / kDegToRad;
  stats_.init_quiet_start = a.quiet_start;
  stats_.align_mount_yaw_deg = a.mount_yaw_rad / kDegToRad;
  stats_.align_mount_yaw_sigma_deg = a.mount_yaw_sigma_rad / kDegToRad;
  if (config_.estimatesMount() && method == "track") {
    // The turns' mount yaw until the direction of travel refines it (updateMount).
    R_v_b_ = Eigen::AngleAxisd(a.mount_yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
             R_v_b_config_;
    mount_known_ = true;
  }
  init_imu_.clear();
  init_fix_v_.clear();
  last_imu_ = a.anchor;
  last_accepted_ns_.reset();
  consecutive_rejections_ = 0;
  recordPose();
  for (std::size_t i = k + 1; i < events.size(); ++i) {
    if (const auto* s = std::get_if<ImuSample>(&events[i])) {
      --stats_.imu_before_init;
      propagate(*s);
    } else {
      const GnssFix& fix = std::get<GnssFix>(events[i]);
      processFix(fix, enu_.toEnu({fix.lat_deg, fix.lon_deg, fix.h_ellipsoid_m}));
    }
  }
  --stats_.imu_before_init;  // the anchor sample starts the trajectory
}

bool GnssIns::tryCourseInitialize(const GnssFix& fix, const Eigen::Vector3d& p_ant) {
  std::optional<Eigen::Vector2d> v_en = fixVelocityEn(fix);
  double min_speed = config_.init_min_speed_mps;
  if (!v_en && prev_fix_) {
    const double dt = seconds(fix.t_ns - prev_fix_->first);
    if (dt >= kMinDifferencingS && dt <= kMaxDifferencingS) {
      v_en = (p_ant - prev_fix_->second).head<2>() / dt;
      min_speed += 3.0 * std::sqrt(2.0) * fix.sigma_h_m / dt;
    }
  }
  const auto window_ns = static_cast<std::int64_t>(config_.init_window_s * 1e9);
  if (v_en) init_fix_v_.push_back({fix.t_ns, *v_en});
  while (!init_fix_v_.empty() && init_fix_v_.front().t_ns < fix.t_ns - window_ns) {
    init_fix_v_.pop_front();
  }
  const bool moving = v_en && v_en->norm() >= min_speed;
  const bool imu_ready = last_imu_ && init_imu_.size() >= 5 &&
                         init_imu_.back().t_ns - init_imu_.front().t_ns >= window_ns / 2;
  if (!moving || !imu_ready) return false;
  // The fixes the alignment held are before initialisation now.
  if (!pending_.empty() && std::holds_alternative<GnssFix>(pending_.back())) pending_.pop_back();
  flushPendingBeforeInit();
  align_.reset();
  bank_.reset();
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
  // The vehicle's forward axis along the course; the body turned from it by the configured mount.
  const double yaw = std::atan2(v_en->y(), v_en->x()) - config_.mount_rpy_deg.z() * kDegToRad;
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
  setInitialCovariance(fix, config_.init_heading_sigma_deg * kDegToRad);
  initialized_ = true;
  stats_.t_init_ns = last_imu_->t_ns;
  stats_.t_heading_ns = last_imu_->t_ns;
  stats_.init_method = "course";
  stats_.init_heading_sigma_deg = config_.init_heading_sigma_deg;
  last_accepted_ns_ = fix.t_ns;
  ++stats_.fixes_used;
  stats_.fixes.push_back({fix.t_ns, p_ant, InsFixStatus::kUsed});
  init_imu_.clear();
  init_fix_v_.clear();
  recordPose();
  return true;
}

}  // namespace gvio::fusion
