#pragma once
// The revisit-consistency plot: a top-down view of the reference path with every revisit pair
// drawn as a segment between its two estimated positions, coloured by the pair's error (colour
// bar), so the places where the estimate puts two passes apart stand out.
#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "eval/revisits.hpp"

namespace gvio::eval {

struct RevisitPlotData {
  std::string title;
  std::vector<Eigen::Vector3d> p_ref, p_est;  // associated positions (estimate aligned)
  std::array<int, 2> plane = {0, 1};          // axes of the top-down view (0=x,1=y,2=z)
};

// Writes PREFIX_revisits.{png,svg} atomically (a plot without pairs says so on it). Throws
// InvalidInput for inconsistent input and io::InputError naming the file when it cannot be
// written. Returns the written paths.
std::vector<std::string> writeRevisitsPlot(const RevisitPlotData& data,
                                           const RevisitResult& revisits,
                                           const std::string& prefix);

}  // namespace gvio::eval
