#include "viz/loop_layer.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>

namespace gvio::viz {
namespace {

// Deep pink: apart from the map's viridis, the trajectories' blue / orange, the fixes' cyan /
// orange / grey and the outages' magenta.
const render::Color kLoop(1.0F, 0.1F, 0.55F, 1);
constexpr float kLoopWidthPx = 4.0F, kKeyframeDiscPx = 9.0F;
constexpr std::int64_t kMaxStampGapNs = 200'000'000;  // a keyframe is a pose: 0.2 s is generous

}  // namespace

std::optional<std::size_t> nearestPoseIndex(const Trajectory& traj, std::int64_t t_ns,
                                            std::int64_t max_dt_ns) {
  if (!traj.hasTimestamps()) return std::nullopt;
  const auto& t = traj.t_ns;
  const auto after = std::lower_bound(t.begin(), t.end(), t_ns);
  std::optional<std::size_t> best;
  std::uint64_t best_gap = 0;
  // The poses either side of t_ns; unsigned differences cannot overflow across the int64 range.
  for (auto it = after == t.begin() ? after : after - 1; it != t.end() && it <= after; ++it) {
    const std::uint64_t gap =
        *it > t_ns ? static_cast<std::uint64_t>(*it) - static_cast<std::uint64_t>(t_ns)
                   : static_cast<std::uint64_t>(t_ns) - static_cast<std::uint64_t>(*it);
    if (gap <= static_cast<std::uint64_t>(max_dt_ns) && (!best || gap < best_gap)) {
      best_gap = gap;
      best = static_cast<std::size_t>(it - t.begin());
    }
  }
  return best;
}

LoopLayerCounts addLoopClosures(const std::vector<io::LoopCsvRow>& loops, const Trajectory& traj,
                                double z, std::vector<render::Polyline>& lines,
                                std::vector<render::PointCloud>& clouds,
                                std::vector<render::LegendEntry>& legend) {
  LoopLayerCounts counts;
  render::PointCloud discs;
  for (const io::LoopCsvRow& loop : loops) {
    if (!loop.accepted) continue;
    const auto query = nearestPoseIndex(traj, loop.query_t_ns, kMaxStampGapNs);
    const auto candidate = nearestPoseIndex(traj, loop.candidate_t_ns, kMaxStampGapNs);
    if (!query || !candidate) {
      ++counts.unplaced;
      continue;
    }
    render::Polyline segment;
    for (const std::size_t i : {*candidate, *query}) {
      Eigen::Vector3d p = traj.poses[i].translation();
      p.z() = z;
      segment.points.push_back(p);
      discs.points.push_back(p);
    }
    segment.colors = {kLoop};
    segment.widths_px = {kLoopWidthPx};
    lines.push_back(std::move(segment));
    ++counts.drawn;
  }
  if (counts.unplaced > 0) {
    spdlog::debug(
        "loops.csv: {} accepted loop(s) not drawn: a keyframe stamp is more than 0.2 s "
        "from every pose of the trajectory",
        counts.unplaced);
  }
  if (counts.drawn == 0) return counts;
  discs.colors = {kLoop};
  discs.sizes_px = {kKeyframeDiscPx};
  clouds.push_back(std::move(discs));
  legend.push_back({fmt::format("loop closures ({})", counts.drawn),
                    render::Rgb{kLoop[0], kLoop[1], kLoop[2]}, false});
  return counts;
}

}  // namespace gvio::viz
