// GnssFusion's first registration of the VIO world to ENU: the pairs it rests on, its rotation
// and how well its fixes fix the heading and the tilt (the window's first node keeps them).
#include <algorithm>
#include <cmath>

#include "fusion/alignment_consensus.hpp"
#include "fusion/gnss_fusion_impl.hpp"
#include "fusion/vio_enu_alignment.hpp"

namespace gvio::fusion {

// The registration explains the fixes when the median squared residual, normalised by each fix's
// sigma, stays within the gate (the median ignores the rare outlier). A chi-square(3) variable
// has median 2.37; the gate (99.9 %) leaves room for the receiver's unmodelled bias.
bool GnssFusion::Impl::residualsConsistent(const Eigen::Isometry3d& T,
                                           const std::vector<bool>& use) const {
  std::vector<double> chi2;
  for (std::size_t i = 0; i < alignment_pairs.size(); ++i) {
    if (!use[i]) continue;
    const Pair& p = alignment_pairs[i];
    const Eigen::Vector3d r = p.p_enu - T * (p.T_w_b * config.lever_arm_b);
    const double var_h = p.fix.sigma_h_m * p.fix.sigma_h_m;
    chi2.push_back(r.head<2>().squaredNorm() / var_h +
                   r.z() * r.z() / (p.fix.sigma_v_m * p.fix.sigma_v_m));
  }
  if (chi2.empty()) return false;
  const auto mid = chi2.begin() + static_cast<std::ptrdiff_t>(chi2.size() / 2);
  std::nth_element(chi2.begin(), mid, chi2.end());
  return *mid <= config.gate_chi2;
}

std::optional<Eigen::Isometry3d> GnssFusion::Impl::registration(
    const std::vector<bool>& use) const {
  std::vector<Eigen::Vector3d> p_w, p_enu;
  for (std::size_t i = 0; i < alignment_pairs.size(); ++i) {
    if (!use[i]) continue;
    p_w.push_back(alignment_pairs[i].T_w_b * config.lever_arm_b);
    p_enu.push_back(alignment_pairs[i].p_enu);
  }
  std::optional<Eigen::Isometry3d> T =
      alignVioToEnu(p_w, p_enu, config.alignment, config.alignment_min_extent_m,
                    config.alignment_min_cross_extent_m);
  if (T && config.alignment == AlignmentDof::kRotationTranslation &&
      !residualsConsistent(*T, use)) {
    T.reset();  // e.g. a tilted start under the yaw-only stand-in: wait for more spread
  }
  return T;
}

// The pairs the registration rests on: all of them while the least-squares registration leaves
// none outside the gate; else the largest consensus (fusion/alignment_consensus.hpp), and only
// when it is a clear majority (two thirds) of at least alignment_min_fixes pairs, so that a
// burst of outliers early in the drive cannot outvote the good fixes: then the registration
// waits for more fixes.
std::optional<std::vector<bool>> GnssFusion::Impl::registrationPairs(
    const Eigen::Isometry3d& T_ls) const {
  std::vector<AlignmentSample> samples;
  bool all_within_gate = true;
  for (const Pair& p : alignment_pairs) {
    samples.push_back({p.T_w_b * config.lever_arm_b, p.p_enu, p.fix.sigma_h_m, p.fix.sigma_v_m});
    all_within_gate = all_within_gate && registrationChi2(T_ls, samples.back(),
                                                          config.gate_floor_m) <= config.gate_chi2;
  }
  if (all_within_gate) return std::vector<bool>(alignment_pairs.size(), true);
  std::vector<bool> inliers = consensusInliers(samples, config.gate_chi2, config.gate_floor_m);
  const auto count = static_cast<std::size_t>(std::count(inliers.begin(), inliers.end(), true));
  if (count < static_cast<std::size_t>(config.alignment_min_fixes) ||
      3 * count < 2 * alignment_pairs.size()) {
    return std::nullopt;
  }
  return inliers;
}

// The heading's and the tilt's 1-sigma (rad) that a registration on the used pairs leaves: twice
// the fixes' mean horizontal (vertical) sigma across their horizontal span (a conservative bound:
// fixes at both ends of a span L, each off by sigma, turn it by at most about 2 sigma / L).
void GnssFusion::Impl::setRegistrationAngleSigmas(const std::vector<bool>& use) {
  double span = 0.0, sigma_h = 0.0, sigma_v = 0.0;
  int n = 0;
  for (std::size_t i = 0; i < alignment_pairs.size(); ++i) {
    if (!use[i]) continue;
    sigma_h += alignment_pairs[i].fix.sigma_h_m;
    sigma_v += alignment_pairs[i].fix.sigma_v_m;
    ++n;
    for (std::size_t j = 0; j < i; ++j) {
      if (!use[j]) continue;
      const Eigen::Vector3d d = alignment_pairs[i].p_enu - alignment_pairs[j].p_enu;
      span = std::max(span, std::hypot(d.x(), d.y()));
    }
  }
  const bool none = n == 0 || span <= 0.0;
  registration_yaw_sigma_rad = none ? kFreeRad : std::atan2(2.0 * sigma_h / n, span);
  registration_tilt_sigma_rad = none ? kFreeRad : std::atan2(2.0 * sigma_v / n, span);
}

void GnssFusion::Impl::align(const Pair& pair) {
  alignment_pairs.push_back(pair);
  if (static_cast<int>(alignment_pairs.size()) < config.alignment_min_fixes) return;
  std::vector<bool> use(alignment_pairs.size(), true);
  T_enu_w = registration(use);
  if (!T_enu_w) return;
  const std::optional<std::vector<bool>> kept = registrationPairs(*T_enu_w);
  if (!kept) {
    T_enu_w.reset();
    return;
  }
  if (*kept != use) {
    use = *kept;
    T_enu_w = registration(use);
    if (!T_enu_w) return;
  }
  setRegistrationAngleSigmas(use);
  // Back-fill the poses seen so far with the registration, then start the chosen filter; the
  // pairs outside the consensus are rejected.
  stats.poses_before_alignment = static_cast<int>(vio.size());
  fused.t_ns = vio.t_ns;
  fused.poses.clear();
  for (const auto& T : vio.poses) fused.poses.push_back(*T_enu_w * T);
  for (std::size_t i = 0; i < alignment_pairs.size(); ++i) {
    const Pair& p = alignment_pairs[i];
    noteOutcome(p, use[i] && (config.mode == FusionMode::kGraph ? fuseGraph(p) : fuseKf(p)));
  }
  alignment_pairs.clear();
}

}  // namespace gvio::fusion
