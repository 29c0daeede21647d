#include "fusion/ins_alignment.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>

namespace gvio::fusion {
namespace {

// A chunk's own position and speed-heading need fixes over some time to be separable.
constexpr int kMinChunkFixes = 4;
constexpr double kMinChunkSpanS = 2.0;
// Chunks whose heading is this uncertain add nothing worth the risk of a wrapped angle.
constexpr double kMaxChunkSigmaRad = 0.5;
constexpr double kOutlierSigmas = 3.0;
constexpr std::int64_t kShortNs = 500'000'000;  // the quiet test's short window
constexpr double kSteadySpeed = 0.2;            // relative speed change of a steady chunk
constexpr int kMinSteadyChunks = 4;             // turn sums before the mount yaw is believed

double seconds(std::int64_t dt_ns) {
  return static_cast<double>(dt_ns) * 1e-9;
}

double wrap(double a) {
  return std::remainder(a, 2.0 * std::numbers::pi);
}

double yawOf(const Eigen::Matrix3d& R) {
  return std::atan2(R(1, 0), R(0, 0));
}

}  // namespace

TrackAlignment::TrackAlignment(const AlignmentConfig& config, const std::vector<ImuSample>& window,
                               const Eigen::Vector3d& lever_b)
    : config_(config), lever_b_(lever_b), last_(window.back()) {
  for (const ImuSample& s : window) {
    f_sum_ += s.acc_b_mps2;
    w_sum_ += s.gyr_b_radps;
  }
  n_sum_ = static_cast<double>(window.size());
  const Eigen::Vector3d w_mean = w_sum_ / n_sum_;
  Eigen::Vector3d w_var = Eigen::Vector3d::Zero();
  for (const ImuSample& s : window) w_var += (s.gyr_b_radps - w_mean).cwiseAbs2();
  const double w_std = std::sqrt(w_var.maxCoeff() / n_sum_);
  quiet_ = w_std <= config_.quiet_gyro_std_radps && w_mean.norm() <= config_.quiet_gyro_mean_radps;
  if (!quiet_) moving_since_ns_ = last_.t_ns;
  level();
  startChunk(last_);
}

void TrackAlignment::level() {
  const Eigen::Vector3d f_mean = f_sum_ / n_sum_;
  // At rest or moving steadily straight the gyro reads its bias; otherwise it is left at 0.
  bg_ = quiet_ ? Eigen::Vector3d(w_sum_ / n_sum_) : Eigen::Vector3d::Zero();
  st_.R_enu_b = rotationFromUpAndYaw(f_mean.normalized(), 0.0);
  st_.bg_b_radps = bg_;
  // The levelling makes R f_mean vertical; what its length lacks of gravity is held as a
  // body-fixed accelerometer bias so that the window integrates to no acceleration.
  st_.ba_b_mps2 = (f_mean.norm() - kGravity_mps2) * f_mean.normalized();
}

bool TrackAlignment::stillQuiet(const ImuSample& s) {
  recent_.push_back(s);
  while (recent_.front().t_ns < s.t_ns - kShortNs) recent_.erase(recent_.begin());
  Eigen::Vector3d f_short = Eigen::Vector3d::Zero(), w_short = Eigen::Vector3d::Zero();
  for (const ImuSample& r : recent_) {
    f_short += r.acc_b_mps2;
    w_short += r.gyr_b_radps;
  }
  const auto n = static_cast<double>(recent_.size());
  return (f_short / n - f_sum_ / n_sum_).norm() <= config_.quiet_acc_mps2 &&
         (w_short / n - bg_).norm() <= config_.quiet_gyro_std_radps;
}

void TrackAlignment::startChunk(const ImuSample& at) {
  Chunk c;
  c.start = at;
  c.R0 = st_.R_enu_b;
  chunks_.push_back(c);
  H_.setZero();
}

void TrackAlignment::integrate(const ImuSample& held, double dt) {
  // The turn sum of the sample held over dt: the gravity-free specific force in the body's yaw
  // frame times the levelled yaw rate; the track's heading integral; then the attitude.
  const Eigen::Matrix3d& R = st_.R_enu_b;
  const Eigen::Vector3d a_w =
      R * (held.acc_b_mps2 - st_.ba_b_mps2) + Eigen::Vector3d(0.0, 0.0, -kGravity_mps2);
  const double yaw = yawOf(R);
  const Eigen::Vector2d a_yaw = Eigen::Rotation2Dd(-yaw) * a_w.head<2>();
  const double w = (R * (held.gyr_b_radps - bg_)).z();
  chunks_.back().S += a_yaw * w * dt;
  H_ += Eigen::Vector2d(std::cos(yaw), std::sin(yaw)) * dt;
  st_ = propagateNominal(st_, held.acc_b_mps2, held.gyr_b_radps, dt);
}

void TrackAlignment::addImu(const ImuSample& s) {
  if (s.t_ns <= last_.t_ns) return;
  if (moving_since_ns_) {
    integrate(last_, seconds(s.t_ns - last_.t_ns));
  } else if (stillQuiet(s)) {
    // Still at rest (or steady): refine the levelling and the bias; a quiet IMU keeps the
    // levelled attitude.
    f_sum_ += s.acc_b_mps2;
    w_sum_ += s.gyr_b_radps;
    n_sum_ += 1.0;
    level();
    for (Chunk& c : chunks_) c.R0 = st_.R_enu_b;
  } else {
    // The quiet run ended within the short window: its samples leave the levelling and are
    // integrated as motion instead.
    moving_since_ns_ = recent_.front().t_ns;
    for (std::size_t k = 0; k + 1 < recent_.size(); ++k) {
      f_sum_ -= recent_[k].acc_b_mps2;
      w_sum_ -= recent_[k].gyr_b_radps;
      n_sum_ -= 1.0;
    }
    level();
    for (Chunk& c : chunks_) c.R0 = st_.R_enu_b;
    for (std::size_t k = 0; k + 1 < recent_.size(); ++k) {
      integrate(recent_[k], seconds(recent_[k + 1].t_ns - recent_[k].t_ns));
    }
    recent_.clear();
  }
  last_ = s;
  if (seconds(s.t_ns - chunks_.back().start.t_ns) >= config_.chunk_s) startChunk(s);
}

void TrackAlignment::addFix(std::int64_t t_ns, const Eigen::Vector3d& p_ant_enu, double sigma_h_m) {
  if (t_ns < chunks_.front().start.t_ns || !(sigma_h_m > 0.0)) return;
  Chunk& c = chunks_.back();
  // p = p_j + Rz(phi) s H: rows [1 0 H_x -H_y; 0 1 H_y H_x] in (p_e, p_n, c_re, c_im).
  Eigen::Matrix<double, 2, 4> A;
  A << 1, 0, H_.x(), -H_.y(),  //
      0, 1, H_.y(), H_.x();
  const Eigen::Vector2d b = p_ant_enu.head<2>();
  const double w = 1.0 / (sigma_h_m * sigma_h_m);
  c.N += w * A.transpose() * A;
  c.g += w * A.transpose() * b;
  c.bWb += w * b.squaredNorm();
  ++c.fixes;
  c.t_last_ns = t_ns;
}

std::optional<TrackAlignment::ChunkHeading> TrackAlignment::chunkHeading(const Chunk& c) const {
  if (c.fixes < kMinChunkFixes || seconds(c.t_last_ns - c.start.t_ns) < kMinChunkSpanS) {
    return std::nullopt;
  }
  const Eigen::LDLT<Eigen::Matrix4d> ldlt(c.N);
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive() ||
      ldlt.vectorD().minCoeff() <= 1e-9 * ldlt.vectorD().maxCoeff()) {
    return std::nullopt;
  }
  const Eigen::Vector4d x = ldlt.solve(c.g);
  const Eigen::Vector2d cs = x.tail<2>();
  const double speed = cs.norm();
  if (!(speed >= config_.min_speed_mps)) return std::nullopt;
  const int dof = 2 * c.fixes - 4;
  const double chi2 = std::max(0.0, c.bWb - x.dot(c.g));
  const double variance_factor = std::max(1.0, dof > 0 ? chi2 / dof : 1.0);
  const Eigen::Matrix4d cov = variance_factor * ldlt.solve(Eigen::Matrix4d::Identity());
  const double phi = std::atan2(cs.y(), cs.x());
  const Eigen::Vector2d across(-std::sin(phi), std::cos(phi));
  const double sigma = std::sqrt(across.dot(cov.bottomRightCorner<2, 2>() * across)) / speed;
  if (!(sigma <= kMaxChunkSigmaRad)) return std::nullopt;
  const Eigen::Vector2d along = cs / speed;
  const double speed_sigma = std::sqrt(along.dot(cov.bottomRightCorner<2, 2>() * along));
  return ChunkHeading{phi, sigma, x.head<2>(), cs, c.fixes, speed_sigma};
}

std::optional<AlignmentSolution> TrackAlignment::solve() const {
  std::vector<std::optional<ChunkHeading>> per_chunk;
  for (const Chunk& c : chunks_) per_chunk.push_back(chunkHeading(c));
  // The mount yaw from the steady chunks' turn sums: S points along the vehicle's lateral axis,
  // at 90 deg - m in the body's yaw frame.
  Eigen::Vector2d S = Eigen::Vector2d::Zero();
  std::vector<Eigen::Vector2d> steady;
  for (std::size_t j = 1; j + 1 < chunks_.size(); ++j) {
    const auto& a = per_chunk[j - 1];
    const auto& b = per_chunk[j];
    const auto& c = per_chunk[j + 1];
    if (!a || !b || !c) continue;
    // Steady: within 20 % of both neighbours, or within what the fixes' noise lets one tell.
    const double v = b->c.norm();
    const auto differs = [&](const ChunkHeading& o) {
      return std::abs(o.c.norm() - v) >
             kSteadySpeed * v + 2.0 * std::hypot(o.speed_sigma, b->speed_sigma);
    };
    if (differs(*a) || differs(*c)) continue;
    S += chunks_[j].S;
    steady.push_back(chunks_[j].S);
  }
  if (static_cast<int>(steady.size()) < kMinSteadyChunks || !(S.norm() > 0.0)) return std::nullopt;
  const double mount = wrap(std::numbers::pi / 2.0 - std::atan2(S.y(), S.x()));
  // Its 1-sigma from the chunks' own scatter across S (their turn sums' components
  // perpendicular to it): the accelerometer's noise is the least of what moves them (tilt, speed
  // changes, lever arm), so the spread is measured, not modelled.
  const Eigen::Vector2d across = Eigen::Vector2d(-S.y(), S.x()) / S.norm();
  double perp2 = 0.0;
  for (const Eigen::Vector2d& sj : steady) perp2 += std::pow(sj.dot(across), 2);
  const auto n = static_cast<double>(steady.size());
  const double mount_sigma = std::sqrt(perp2 * n / (n - 1.0)) / S.norm();
  const double max_sigma = config_.max_heading_sigma_deg * std::numbers::pi / 180.0;
  if (!(mount_sigma <= max_sigma)) return std::nullopt;
  // The vehicle heading offset phi from the chunks: weighted mean, outliers left out once.
  std::vector<std::pair<const Chunk*, ChunkHeading>> headings;
  for (std::size_t j = 0; j < chunks_.size(); ++j) {
    if (per_chunk[j]) headings.emplace_back(&chunks_[j], *per_chunk[j]);
  }
  const auto combine = [&](std::optional<double> centre, double gate) {
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();
    double info = 0.0;
    for (const auto& [chunk, h] : headings) {
      if (centre && std::abs(wrap(h.phi - *centre)) > gate * h.sigma) continue;
      const double w = 1.0 / (h.sigma * h.sigma);
      sum += w * Eigen::Vector2d(std::cos(h.phi), std::sin(h.phi));
      info += w;
    }
    return std::make_pair(std::atan2(sum.y(), sum.x()), info);
  };
  auto [phi, info] = combine(std::nullopt, 0.0);
  if (!(info > 0.0)) return std::nullopt;
  std::tie(phi, info) = combine(phi, kOutlierSigmas);
  if (!(info > 0.0)) return std::nullopt;
  const double sigma = std::hypot(1.0 / std::sqrt(info), mount_sigma);
  if (!(sigma <= max_sigma)) return std::nullopt;
  const double psi = wrap(phi + mount);
  // The state at the start of the first chunk that agrees with the combined heading.
  const Chunk* anchor = nullptr;
  ChunkHeading first;
  int fixes = 0, chunks = 0;
  for (const auto& [chunk, h] : headings) {
    if (std::abs(wrap(h.phi - phi)) > kOutlierSigmas * h.sigma) continue;
    fixes += h.fixes;
    ++chunks;
    if (anchor == nullptr) {
      anchor = chunk;
      first = h;
    }
  }
  AlignmentSolution out;
  const Chunk& front = chunks_.front();
  const Eigen::Matrix3d Rz_psi =
      Eigen::AngleAxisd(psi, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  if (moving_since_ns_ && front.start.t_ns < *moving_since_ns_ && front.fixes > 0 &&
      anchor->start.t_ns <= *moving_since_ns_ + static_cast<std::int64_t>(config_.chunk_s * 1e9)) {
    // A quiet start: the filter starts at the anchor, at rest where the quiet fixes say.
    out.anchor = front.start;
    out.R_enu_b = Rz_psi * front.R0;
    out.p_en = front.g.head<2>() / front.N(0, 0) - (out.R_enu_b * lever_b_).head<2>();
    out.v_en.setZero();
  } else {
    out.anchor = anchor->start;
    out.R_enu_b = Rz_psi * anchor->R0;
    out.p_en = first.p - (out.R_enu_b * lever_b_).head<2>();
    // v(t) = c e^{i yaw_b(t)} at the chunk's start (its speed along the vehicle's heading).
    out.v_en = Eigen::Rotation2Dd(yawOf(anchor->R0)) * first.c;
  }
  out.ba_b_mps2 = st_.ba_b_mps2;
  out.bg_b_radps = bg_;
  out.heading_sigma_rad = sigma;
  out.mount_yaw_rad = mount;
  out.mount_yaw_sigma_rad = mount_sigma;
  out.fixes = fixes;
  out.chunks = chunks;
  out.quiet_start = quiet_;
  return out;
}

std::optional<AlignmentSolution> TrackAlignment::solutionWithHeading(double psi,
                                                                     double sigma) const {
  const Chunk& front = chunks_.front();
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(psi, Eigen::Vector3d::UnitZ()).toRotationMatrix() * front.R0;
  AlignmentSolution out;
  out.anchor = front.start;
  out.R_enu_b = R;
  if (const std::optional<ChunkHeading> h = chunkHeading(front)) {
    out.p_en = h->p - (R * lever_b_).head<2>();
    out.v_en = Eigen::Rotation2Dd(yawOf(front.R0)) * h->c;
  } else if (front.fixes > 0) {
    out.p_en = front.g.head<2>() / front.N(0, 0) - (R * lever_b_).head<2>();
  } else {
    return std::nullopt;
  }
  out.ba_b_mps2 = st_.ba_b_mps2;
  out.bg_b_radps = bg_;
  out.heading_sigma_rad = sigma;
  out.quiet_start = quiet_;
  return out;
}

}  // namespace gvio::fusion
