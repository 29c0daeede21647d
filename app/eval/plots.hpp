#pragma once
// Evaluation plots drawn with cairo, each written as PNG and SVG:
//   PREFIX_trajectory: top-down view, estimate coloured by error (colour bar), reference dashed,
//                      start/end marked, metric scale bar;
//   PREFIX_error:      error vs time with rmse/mean/median lines, outage intervals shaded;
//   PREFIX_axes:       per-axis position error (est - ref) vs time, outages shaded.
#include <Eigen/Core>
#include <array>
#include <string>
#include <utility>
#include <vector>

#include "eval/metrics.hpp"

namespace gvio::eval {

struct PlotData {
  std::string title;                 // e.g. "APE translation part (m), SE(3) aligned"
  std::string error_label;           // axis / colour-bar label, e.g. "APE (m)"
  std::vector<double> t_s;           // time of each associated pose, seconds since the first one
  std::string time_label = "t (s)";  // "pose index" when the trajectories carry no stamps
  std::vector<Eigen::Vector3d> p_ref, p_est;  // associated positions, estimate aligned
  std::vector<double> error;                  // per-pose error (same length as t_s)
  Stats stats;
  std::vector<std::pair<double, double>> outages_s;  // [t0, t1] in the same time base as t_s
  std::array<int, 2> plane = {0, 1};                 // axes of the top-down view (0=x,1=y,2=z)
};

// The two axes with the largest extent of the reference, in increasing axis order.
std::array<int, 2> choosePlane(const std::vector<Eigen::Vector3d>& points);

// Writes PREFIX_trajectory.{png,svg}, PREFIX_error.{png,svg}, PREFIX_axes.{png,svg} atomically.
// Throws io::InputError naming the file when it cannot be written. Returns the written paths.
std::vector<std::string> writePlots(const PlotData& data, const std::string& prefix);

}  // namespace gvio::eval
