#pragma once
// Trajectory files exactly as the `evo` evaluation tool reads them (evo.tools.file_interface), so
// results computed here and by evo start from identical poses:
//  - TUM:   "t tx ty tz qx qy qz qw" (seconds, quaternion w LAST), whitespace separated.
//  - KITTI: 12 values per line, the row-major 3x4 [R|t]; timestamps only from a separate times
//  file.
//  - EuRoC: "t_ns,px,py,pz,qw,qx,qy,qz,..." (quaternion w FIRST, extra columns ignored).
// '#' lines and blank lines are skipped. Every malformed input throws InputError("file:line: ...").
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "odometry/trajectory.hpp"

namespace gvio::io {

enum class TrajectoryFormat { kTum, kKitti, kEuroc };

// "tum", "kitti" or "euroc"; nullopt for anything else.
std::optional<TrajectoryFormat> parseTrajectoryFormat(std::string_view name);
std::string toString(TrajectoryFormat format);

// Guesses the format from the first data line: commas -> EuRoC, 8 fields -> TUM, 12 -> KITTI.
// Throws InputError naming file and line when none fits.
TrajectoryFormat detectTrajectoryFormat(const std::filesystem::path& file);

// kIncreasing: a stamp that repeats or steps back is an error naming the line (estimation and
// interpolation need a monotonic stream: simulate, export, datasets). kAsGiven: stamps in any
// order, as evo reads them (it checks nothing; gvio eval associates them as evo does).
enum class StampOrder { kIncreasing, kAsGiven };

Trajectory readTum(const std::filesystem::path& file, StampOrder order = StampOrder::kIncreasing);
// Without `times_file` the result has no timestamps. With it, the times file holds one seconds
// value per pose (the KITTI odometry times.txt layout) and the counts must match.
Trajectory readKitti(const std::filesystem::path& file,
                     const std::optional<std::filesystem::path>& times_file = std::nullopt,
                     StampOrder order = StampOrder::kIncreasing);
Trajectory readEurocCsv(const std::filesystem::path& file,
                        StampOrder order = StampOrder::kIncreasing);
// Throws InvalidInput when a times file is given for a format other than KITTI.
Trajectory readTrajectory(const std::filesystem::path& file, TrajectoryFormat format,
                          const std::optional<std::filesystem::path>& times_file = std::nullopt,
                          StampOrder order = StampOrder::kIncreasing);

// Stamps that are not strictly increasing: repeats (t == previous) and steps back (t < previous),
// with the index of the first such pose.
struct StampOrderSummary {
  std::size_t repeated = 0, steps_back = 0;
  std::size_t first_index = 0;  // meaningful when repeated + steps_back > 0
};
StampOrderSummary summarizeStampOrder(const std::vector<std::int64_t>& t_ns);

// Writers replace `file` atomically. TUM, EuRoC and KITTI times need timestamps (InvalidInput if
// the trajectory has none); KITTI poses ignore them.
void writeTum(const std::filesystem::path& file, const Trajectory& traj);
void writeKitti(const std::filesystem::path& file, const Trajectory& traj);
void writeKittiTimes(const std::filesystem::path& file, const Trajectory& traj);
void writeEurocCsv(const std::filesystem::path& file, const Trajectory& traj);
void writeTrajectory(const std::filesystem::path& file, const Trajectory& traj,
                     TrajectoryFormat format);

}  // namespace gvio::io
