#pragma once
// Where the simulated body's orientation comes from. The simulator mounts its IMU and cameras on a
// vehicle body (x forward, y left, z up), but many ground-truth files give the orientation of an
// IMU or camera mounted any way: taken as-is, such a file points the simulated cameras sideways or
// at the sky. `kMotion` derives a vehicle orientation from the path itself; `checkForwardAxis`
// measures whether a file's orientation can be a vehicle's.
#include <optional>
#include <string>
#include <string_view>

#include "odometry/trajectory.hpp"
#include "sim/trajectory_fit.hpp"

namespace gvio::sim {

enum class OrientationSource {
  kFile,    // the file's orientations are the body's (TUM as given, KITTI via kitti_convention)
  kMotion,  // heading and pitch from the direction of travel (x along it), roll zero
};
inline constexpr std::string_view kOrientationSourceNames = "file or motion";
std::optional<OrientationSource> parseOrientationSource(std::string_view name);
const char* toString(OrientationSource source);

struct MotionOrientationOptions {
  // The direction of travel at a pose is that of the chord over this much path centred on it
  // (centred in distance along the path, not in time): the velocity's direction while moving
  // (exactly the tangent's on a circle), and unchanged through a standstill, which adds no path.
  // Noise in the velocity's direction at walking pace would otherwise swing the heading.
  double chord_m = 1.0;
  // Slower than this the path does not advance, so a standstill's position jitter does not slide
  // the chord.
  double min_speed_mps = 0.2;
  FitOptions fit;  // the spline whose positions give the path (the simulator's own)
};

// The same poses with each orientation replaced by a vehicle's that follows the path: x along the
// direction of travel (heading and climb angle), y horizontal (roll zero: a path alone has no
// cross slope). Within chord_m / 2 of either end the chord is the path's first or last chord_m.
// Where the path folds back on itself (reversing), the last orientation is held. Throws
// InvalidInput when the path is shorter than chord_m (no heading to take).
Trajectory orientationFromMotion(const Trajectory& T_w_b, const MotionOrientationOptions& options);

struct ForwardAxisCheck {
  std::size_t moving_poses = 0;     // poses with horizontal speed above the threshold
  double x_median_deg = 0.0;        // median angle between body x and the horizontal velocity
  std::string closest_axis = "+x";  // the body axis (+x, -x, +y, ..., -z) closest to travel
  double closest_median_deg = 0.0;  // its median angle
};
// Above this median angle the file's x axis is not the vehicle's forward.
inline constexpr double kForwardAxisWarnDeg = 30.0;

// How far the body x axis (the simulator's forward) is from the direction of travel, over the
// poses moving faster than min_speed_mps; nullopt when none does.
std::optional<ForwardAxisCheck> checkForwardAxis(const Trajectory& T_w_b, const FitOptions& fit,
                                                 double min_speed_mps = 1.0);

// One warning line for `file` when its x axis is more than kForwardAxisWarnDeg from the direction
// of travel (naming the axis that travel follows, when one does); nullopt otherwise.
std::optional<std::string> forwardAxisWarning(const std::optional<ForwardAxisCheck>& check,
                                              const std::string& file);

}  // namespace gvio::sim
