// The frames the visual-inertial alignment of a moving stereo window runs on: the window's own
// and, while it waits for a certain gravity direction, those it has marginalised meanwhile
// (vio.init_alignment_span_s). Over a longer span the same visual position noise pins the gravity
// direction better: its leak into the positions grows as the span squared (VINS-Mono's alignment,
// Qin et al. 2018 sec. V-B, over more than the window).
#include <algorithm>
#include <memory>
#include <vector>

#include "odometry/vio_estimator_impl.hpp"

namespace gvio::odometry {

std::vector<AlignmentFrame> VioEstimator::Impl::windowAlignmentFrames() const {
  std::vector<AlignmentFrame> af;
  const auto& frames = window.frames();
  for (std::size_t k = 0; k < frames.size(); ++k) {
    if (k > 0 && !frames[k]->preintegration) return {};
    AlignmentFrame a;
    const Eigen::Isometry3d T = frames[k]->T_w_b();
    a.R_v_b = T.rotation();
    a.p_v_b = T.translation();
    if (k > 0) a.preintegration = frames[k]->preintegration;
    af.push_back(a);
  }
  return af;
}

bool VioEstimator::Impl::keepsAlignmentHistory() const {
  return usesImu(config.mode) && geometry.stereo && !imu_aligned &&
         config.init_alignment_span_s > 0.0;
}

void VioEstimator::Impl::keepForAlignment(const WindowFrame& f) {
  alignment_history.push_back({f.t_ns, f.T_w_b()});
  const auto span_ns = static_cast<std::int64_t>(config.init_alignment_span_s * 1e9);
  const std::int64_t newest_ns = window.frames().back()->t_ns;
  while (!alignment_history.empty() && newest_ns - alignment_history.front().t_ns > span_ns) {
    alignment_history.pop_front();
  }
}

std::size_t VioEstimator::Impl::prependHistory(std::vector<AlignmentFrame>& af) const {
  const auto& frames = window.frames();
  if (alignment_history.empty() || af.empty() || frames.empty()) return 0;
  const std::int64_t retime = frames.front()->retime_ns;
  const ImuBias bias = frames.front()->bias();
  const auto max_hold = static_cast<std::int64_t>(config.max_imu_gap_s * 1e9);
  // Back from the window's oldest frame, as far as the IMU runs without a gap: past[0] is the
  // frame next to the window, and each entry carries the IMU to its successor.
  std::vector<AlignmentFrame> past;
  std::vector<std::shared_ptr<ImuPreintegration>> to_next;
  std::int64_t next_ns = frames.front()->t_ns;
  for (auto it = alignment_history.rbegin(); it != alignment_history.rend(); ++it) {
    const std::int64_t a = it->t_ns - retime;
    const std::int64_t b = next_ns - retime;
    if (a >= b || !imu.covers(a, b, max_hold)) break;
    AlignmentFrame f;
    f.R_v_b = it->T_v_b.rotation();
    f.p_v_b = it->T_v_b.translation();
    past.push_back(f);
    to_next.push_back(imu.preintegrate(a, b, bias, config.imu_noise));
    next_ns = it->t_ns;
  }
  if (past.empty()) return 0;
  // In time order, each frame's preintegration from its predecessor.
  std::reverse(past.begin(), past.end());
  std::reverse(to_next.begin(), to_next.end());
  for (std::size_t k = 1; k < past.size(); ++k) past[k].preintegration = to_next[k - 1];
  af.front().preintegration = to_next.back();
  af.insert(af.begin(), past.begin(), past.end());
  return past.size();
}

}  // namespace gvio::odometry
