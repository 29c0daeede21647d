#pragma once
// Accepted loop closures (loops.csv) in the top-down map: a segment between the two keyframes of
// each, on the trajectory the map is drawn with, so one sees which stretches of the drive the run
// tied together. Rejected candidates are not drawn.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "io/loops_csv.hpp"
#include "odometry/trajectory.hpp"
#include "render/annotate.hpp"
#include "render/scene.hpp"

namespace gvio::viz {

// Index of the pose nearest in time to `t_ns`, when it is within `max_dt_ns`; nullopt otherwise
// (or when the trajectory has no stamps). The stamps must increase, as readTum guarantees.
std::optional<std::size_t> nearestPoseIndex(const Trajectory& traj, std::int64_t t_ns,
                                            std::int64_t max_dt_ns);

struct LoopLayerCounts {
  std::size_t drawn = 0;     // accepted loops drawn
  std::size_t unplaced = 0;  // accepted loops with a keyframe stamp more than 0.2 s from any pose
};

// Each accepted loop as a segment (plus a disc at either keyframe: a loop's keyframes were close
// to each other, so the segment alone may be only a few pixels long) at height `z`, and the
// legend entry "loop closures (N)" when any is drawn.
LoopLayerCounts addLoopClosures(const std::vector<io::LoopCsvRow>& loops, const Trajectory& traj,
                                double z, std::vector<render::Polyline>& lines,
                                std::vector<render::PointCloud>& clouds,
                                std::vector<render::LegendEntry>& legend);

}  // namespace gvio::viz
