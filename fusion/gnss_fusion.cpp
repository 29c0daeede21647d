#include "fusion/gnss_fusion.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>

#include "fusion/gnss_covariance.hpp"
#include "fusion/gnss_factors.hpp"
#include "fusion/gnss_fusion_impl.hpp"
#include "odometry/error.hpp"
#include "odometry/prior_factor.hpp"

namespace gvio::fusion {
namespace {

using Clock = std::chrono::steady_clock;
// Chi-square, 6 degrees of freedom, 99.9 %: the KF's position + velocity innovation gate.
constexpr double kKfGateChi2 = 22.46;
// A fix without a usable previous one gets no velocity information (variance in (m/s)^2).
constexpr double kNoVelocityVariance = 1e8;
// Consecutive fixes further apart than this say little about the receiver's white noise (the VIO
// drifts, the receiver's slow error decorrelates).
constexpr double kMaxNoiseDifferencingS = 2.0;

// The fix's whitening, its stated ellipse kept.
Eigen::Matrix3d sqrtInformation(const GnssFix& fix) {
  return gnssSqrtInformation(fix.sigma_h_m, fix.sigma_v_m, fix.shape_en);
}

}  // namespace

std::string toString(FixStatus status) {
  switch (status) {
    case FixStatus::kUsed:
      return "used";
    case FixStatus::kRejected:
      return "rejected";
    case FixStatus::kUnmatched:
      return "unmatched";
    case FixStatus::kUnaligned:
      return "unaligned";
  }
  return "";
}

std::string toString(FusionMode mode) {
  return mode == FusionMode::kKf ? "kf" : "graph";
}

FusionMode parseFusionMode(const std::string& name) {
  if (name == "kf") return FusionMode::kKf;
  if (name == "graph") return FusionMode::kGraph;
  throw InvalidInput("fusion mode must be kf or graph (got '" + name + "')");
}

double FusionConfig::tiltSigmaRad() const {
  return alignment == AlignmentDof::kYawTranslation ? tilt_sigma_deg * std::numbers::pi / 180.0
                                                    : 0.0;
}

void FusionConfig::validate() const {
  const auto positive = [](double v, const char* name) {
    if (!(std::isfinite(v) && v > 0.0)) {
      throw InvalidInput(std::string("config: fusion.") + name + " must be > 0");
    }
  };
  if (!lever_arm_b.allFinite()) throw InvalidInput("config: fusion.lever_arm_b must be finite");
  if (!std::isfinite(receiver_time_offset_s)) {
    throw InvalidInput("config: fusion.receiver_time_offset_s must be finite");
  }
  if (alignment_min_fixes < 3)
    throw InvalidInput("config: fusion.alignment_min_fixes must be >= 3");
  if (window_nodes < 2) throw InvalidInput("config: fusion.window_nodes must be >= 2");
  if (max_consecutive_rejections < 1) {
    throw InvalidInput("config: fusion.max_consecutive_rejections must be >= 1");
  }
  positive(alignment_min_extent_m, "alignment_min_extent_m");
  positive(alignment_min_cross_extent_m, "alignment_min_cross_extent_m");
  positive(vio_drift_fraction, "vio_drift_fraction");
  positive(vio_sigma_floor_m, "vio_sigma_floor_m");
  positive(vio_rot_drift_rad_per_m, "vio_rot_drift_rad_per_m");
  positive(vio_rot_floor_rad, "vio_rot_floor_rad");
  positive(tilt_sigma_deg, "tilt_sigma_deg");
  positive(huber_sigmas, "huber_sigmas");
  positive(gate_chi2, "gate_chi2");
  if (!(std::isfinite(gate_floor_m) && gate_floor_m >= 0.0)) {
    throw InvalidInput("config: fusion.gate_floor_m must be >= 0");
  }
  positive(outage_s, "outage_s");
  kf.validate();
  smoother.validate();
}

Eigen::Isometry3d GnssFusion::Impl::fusedPose(std::int64_t t_ns,
                                              const Eigen::Isometry3d& T_w_b) const {
  if (config.mode == FusionMode::kGraph && !graph.empty()) {
    const GraphNode& n = graph.newest();
    return n.T_enu_b() * n.T_w_b.inverse() * T_w_b;  // the newest node carried by the VIO motion
  }
  Eigen::Isometry3d T = *T_enu_w * T_w_b;
  if (config.mode == FusionMode::kKf) {
    const double dt = static_cast<double>(t_ns - kf_t_ns) * 1e-9;
    T.translation() += kf.state().head<3>() + kf.state().tail<3>() * std::max(dt, 0.0);
  }
  return T;
}

void GnssFusion::Impl::noteAccepted(std::int64_t t_ns) {
  if (last_accepted_ns && static_cast<double>(t_ns - *last_accepted_ns) * 1e-9 > config.outage_s) {
    stats.outages.emplace_back(*last_accepted_ns, t_ns);
  }
  last_accepted_ns = t_ns;
  ++stats.fixes_used;
  consecutive_rejections = 0;
}

void GnssFusion::Impl::noteOutcome(const Pair& pair, bool used) {
  stats.fixes.push_back({pair.t_ns, pair.p_enu, used ? FixStatus::kUsed : FixStatus::kRejected,
                         pair.fix.sigma_h_m, pair.fix.sigma_v_m, pair.fix.quality,
                         pair.fix.shape_en});
  if (used) {
    noteAccepted(pair.t_ns);
  } else {
    ++stats.fixes_rejected;
  }
}

bool GnssFusion::Impl::fuseGraph(const Pair& pair) {
  const Eigen::Vector3d& lever = config.lever_arm_b;
  if (graph.empty()) {
    GraphNode& n = graph.addNode(pair.t_ns, *T_enu_w * pair.T_w_b, pair.T_w_b, nullptr);
    addNodePriors(n, true);
    graph.addGnssFactor(
        n, std::make_shared<GnssPositionFactor>(lever, pair.p_enu, sqrtInformation(pair.fix)));
    graph.solve();
    noteGraphNode(pair);
    return true;
  }
  const GraphNode& last = graph.newest();
  const Eigen::Isometry3d T_rel = last.T_w_b.inverse() * pair.T_w_b;
  const Eigen::Isometry3d T_pred = last.T_enu_b() * T_rel;
  const double dist = T_rel.translation().norm();
  // Gate: the fix against the antenna predicted by the VIO motion since the newest node. The node
  // is itself uncertain by up to about one fix's sigma (it rests on a few fixes seen through the
  // VIO), hence twice the fix variance plus the VIO drift since the node.
  const RelativeNoise noise = config.relativeNoise();
  const double sigma_motion = noise.positionSigmaM(dist);
  const double var_pred = sigma_motion * sigma_motion + config.gate_floor_m * config.gate_floor_m;
  const Eigen::Vector3d innovation = pair.p_enu - T_pred * lever;
  const Eigen::Matrix3d covariance =
      2.0 * gnssCovariance(pair.fix.sigma_h_m, pair.fix.sigma_v_m, pair.fix.shape_en) +
      var_pred * Eigen::Matrix3d::Identity();
  const double chi2 = innovation.dot(covariance.ldlt().solve(innovation));
  if (chi2 > config.gate_chi2 && consecutive_rejections < config.max_consecutive_rejections) {
    return false;
  }
  auto relative = std::make_shared<RelativePoseFactor>(T_rel, noise.rotationSigmaRad(dist),
                                                       noise.positionSigmaM(dist));
  GraphNode& n = graph.addNode(pair.t_ns, T_pred, pair.T_w_b, relative);
  addNodePriors(n, false);
  graph.addGnssFactor(
      n, std::make_shared<GnssPositionFactor>(lever, pair.p_enu, sqrtInformation(pair.fix)));
  graph.solve();
  noteGraphNode(pair);
  return true;
}

// With an IMU the VIO observes roll and pitch at every pose, and the window keeps them (TiltFactor,
// as the smoother does): fixes alone leave the roll about a straight stretch free, and with the
// antenna above the body the fixes' lateral noise then rolls the online poses by tens of degrees
// (31.7 deg at worst, 2.9 deg median, on 60 s of simulated KITTI-00 with SPP fixes). Held at its
// tilt, a lone node's heading moves its antenna only through the lever arm's horizontal part (not
// at all for an antenna above the body), so the first node also keeps the registration's heading,
// within what the registration's fixes say of it; later nodes get their heading through the VIO's
// relative poses and the track of the fixes, as before.
// Without an IMU nothing observes the tilt but the fixes, so the first node keeps the whole
// rotation of the registration, which rests on all its fixes: left free, the window's first two
// nodes tilt to fit two fixes' height noise over ~10 m (a 35 deg pitch and 52 m of online height
// error on a simulated 60 s street drive, stereo alone, before the gate's reset).
void GnssFusion::Impl::addNodePriors(GraphNode& node, bool first) {
  const double tilt_sigma = config.tiltSigmaRad();
  if (tilt_sigma > 0.0) {
    const Eigen::Vector3d g_b = node.T_w_b.rotation().transpose() * Eigen::Vector3d::UnitZ();
    graph.addPrior(node, std::make_shared<TiltFactor>(g_b, tilt_sigma));
  }
  if (!first) return;
  odometry::PoseSigmas sigmas;
  // With an IMU the tilt is the tilt factor's; without one, the registration's.
  sigmas.tilt_rad = tilt_sigma > 0.0 ? kFreeRad : registration_tilt_sigma_rad;
  sigmas.yaw_rad = registration_yaw_sigma_rad;
  sigmas.position_m = kFreePositionM;  // the fix's
  graph.addPrior(node, std::make_shared<odometry::PosePriorFactor>(node.pose.data(), sigmas));
}

void GnssFusion::Impl::noteGraphNode(const Pair& pair) {
  graph_fixes.push_back({pair.t_ns, pair.T_w_b, graph.newest().T_enu_b(), pair.p_enu,
                         pair.fix.sigma_h_m, pair.fix.sigma_v_m, pair.fix.quality,
                         pair.fix.shape_en});
}

void GnssFusion::Impl::smooth() {
  if (config.mode != FusionMode::kGraph || !config.smoother.enabled || graph_fixes.size() < 2) {
    return;
  }
  const auto start = Clock::now();
  const RelativeNoise noise = config.relativeNoise();
  const SmoothedNodes nodes =
      smoothNodes(graph_fixes, config.lever_arm_b, noise, config.huber_sigmas, config.smoother,
                  config.tiltSigmaRad());
  smoothed = spreadOverVio(vio, graph_fixes, nodes, noise, &smoothed_covariance);
  stats.smoother_outliers =
      static_cast<int>(std::count(nodes.outlier.begin(), nodes.outlier.end(), true));
  stats.smoother_sigma_scale = nodes.sigma_scale;
  stats.ms_smoothing = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

bool GnssFusion::Impl::fuseKf(const Pair& pair) {
  const Eigen::Vector3d& lever = config.lever_arm_b;
  const Eigen::Vector3d p_vio = *T_enu_w * (pair.T_w_b * lever);
  kf.predict(pair.t_ns);
  // The stated sigmas, scaled by what the earlier fixes of this quality showed.
  const Eigen::Vector2d scale =
      config.kf.learn_noise ? kf_noise.scale(pair.fix.quality) : Eigen::Vector2d::Ones();
  const auto covariance = [&](const GnssFix& fix) -> Eigen::Matrix3d {
    return gnssCovariance(fix.sigma_h_m * scale.x(), fix.sigma_v_m * scale.y(), fix.shape_en);
  };
  KfBaseline::Vector6d z;
  KfBaseline::Matrix6d R = KfBaseline::Matrix6d::Zero();
  const Eigen::Matrix3d cov_p = covariance(pair.fix);
  double dt_prev = 0.0;
  GnssFix prev_fix;
  Eigen::Vector2d vio_step_en = Eigen::Vector2d::Zero();
  z.head<3>() = pair.p_enu - p_vio;
  R.topLeftCorner<3, 3>() = cov_p;
  // No Doppler in the input: GNSS velocity by finite differences of consecutive fixes, against the
  // VIO's over the same interval (the reference method's fallback).
  z.tail<3>().setZero();
  R.diagonal().tail<3>().setConstant(kNoVelocityVariance);
  if (previous_fix) {
    const double dt = static_cast<double>(pair.t_ns - previous_fix->t_ns) * 1e-9;
    if (dt > 0.0) {
      const Eigen::Vector3d p_vio_prev = *T_enu_w * (previous_fix->T_w_b * lever);
      z.tail<3>() = (pair.p_enu - previous_fix->p_enu) / dt - (p_vio - p_vio_prev) / dt;
      R.bottomRightCorner<3, 3>() = (cov_p + covariance(previous_fix->fix)) / (dt * dt);
      dt_prev = dt;
      prev_fix = previous_fix->fix;
      vio_step_en = (p_vio - p_vio_prev).head<2>();
    }
  }
  previous_fix = pair;
  // What the receiver's noise is, from consecutive fixes: their displacement against the VIO's
  // over at most kMaxNoiseDifferencingS, whitened by the stated covariances of both
  // (differencedNoiseSample), is free of the slow bias the differencing cancels and, taken along
  // the track, of the filter's own error (which would feed back: larger sigmas, a looser filter,
  // larger innovations).
  if (config.kf.learn_noise && dt_prev > 0.0 && dt_prev <= kMaxNoiseDifferencingS) {
    const Eigen::Matrix3d both =
        gnssCovariance(pair.fix.sigma_h_m, pair.fix.sigma_v_m, pair.fix.shape_en) +
        gnssCovariance(prev_fix.sigma_h_m, prev_fix.sigma_v_m, prev_fix.shape_en);
    const DifferencedNoiseSample sample =
        differencedNoiseSample(z.tail<3>() * dt_prev, vio_step_en, both);
    kf_noise.add(pair.fix.quality, sample.z2_horizontal, sample.z2_vertical);
  }
  KfBaseline candidate = kf;
  const double nis = candidate.update(z, R);
  if (nis > kKfGateChi2 && consecutive_rejections < config.max_consecutive_rejections &&
      stats.fixes_used > 0) {
    return false;
  }
  kf = candidate;
  kf_t_ns = pair.t_ns;
  return true;
}

void GnssFusion::Impl::processFix(const GnssFix& fix) {
  const auto start = Clock::now();
  const auto T_w_b = interpolatePose(vio, fix.t_ns);
  if (!T_w_b) {
    ++stats.fixes_unmatched;
    stats.fixes.push_back({fix.t_ns, enu.toEnu({fix.lat_deg, fix.lon_deg, fix.h_ellipsoid_m}),
                           FixStatus::kUnmatched, fix.sigma_h_m, fix.sigma_v_m, fix.quality,
                           fix.shape_en});
    return;
  }
  Pair pair{fix.t_ns, *T_w_b, enu.toEnu({fix.lat_deg, fix.lon_deg, fix.h_ellipsoid_m}), fix};
  if (!T_enu_w) {
    align(pair);
  } else {
    const bool used = config.mode == FusionMode::kGraph ? fuseGraph(pair) : fuseKf(pair);
    noteOutcome(pair, used);
    if (!used) ++consecutive_rejections;
  }
  stats.ms_per_fix.push_back(
      std::chrono::duration<double, std::milli>(Clock::now() - start).count());
}

GnssFusion::GnssFusion(const FusionConfig& config, const EnuFrame& enu) {
  config.validate();
  impl_ = std::make_unique<Impl>(config, enu);
}
GnssFusion::~GnssFusion() = default;

void GnssFusion::addVioPose(std::int64_t t_ns, const Eigen::Isometry3d& T_w_b) {
  Impl& s = *impl_;
  if (!s.vio.t_ns.empty() && t_ns <= s.vio.t_ns.back()) return;
  s.vio.t_ns.push_back(t_ns);
  s.vio.poses.push_back(T_w_b);
  while (!s.pending.empty() && s.pending.front().t_ns <= t_ns) {
    const GnssFix fix = s.pending.front();
    s.pending.pop_front();
    s.processFix(fix);
  }
  if (s.T_enu_w && s.fused.size() < s.vio.size()) {
    s.fused.t_ns.push_back(t_ns);
    s.fused.poses.push_back(s.fusedPose(t_ns, T_w_b));
  }
}

void GnssFusion::addFix(const GnssFix& fix) {
  GnssFix shifted = fix;
  shifted.t_ns +=
      static_cast<std::int64_t>(std::llround(impl_->config.receiver_time_offset_s * 1e9));
  impl_->pending.push_back(shifted);
}

void GnssFusion::finish() {
  Impl& s = *impl_;
  while (!s.pending.empty()) {
    s.processFix(s.pending.front());
    s.pending.pop_front();
  }
  for (const Impl::Pair& p : s.alignment_pairs) {
    s.stats.fixes.push_back({p.t_ns, p.p_enu, FixStatus::kUnaligned, p.fix.sigma_h_m,
                             p.fix.sigma_v_m, p.fix.quality, p.fix.shape_en});
  }
  s.alignment_pairs.clear();
  if (s.config.mode == FusionMode::kKf && s.config.kf.learn_noise) {
    s.stats.kf_sigma_scale = s.kf_noise.scales();
  }
  std::sort(s.stats.fixes.begin(), s.stats.fixes.end(),
            [](const FixOutcome& a, const FixOutcome& b) { return a.t_ns < b.t_ns; });
  if (s.last_accepted_ns && !s.vio.empty() &&
      static_cast<double>(s.vio.t_ns.back() - *s.last_accepted_ns) * 1e-9 > s.config.outage_s) {
    s.stats.outages.emplace_back(*s.last_accepted_ns, s.vio.t_ns.back());
  }
  s.smooth();
}

Trajectory GnssFusion::fusedTrajectory() const {
  return impl_->fused;
}
Trajectory GnssFusion::smoothedTrajectory() const {
  return impl_->smoothed;
}
const std::vector<PoseCovariance>& GnssFusion::smoothedCovariance() const {
  return impl_->smoothed_covariance;
}
const FusionStats& GnssFusion::stats() const {
  return impl_->stats;
}
std::optional<Eigen::Isometry3d> GnssFusion::T_enu_w() const {
  return impl_->T_enu_w;
}

}  // namespace gvio::fusion
