#pragma once
// The plot of `gvio consistency --images`: the two agreement scores of every checked keyframe
// along the drive (patch ZNCC above, depth agreement below), each with its flag threshold, the
// flagged keyframes in red and the flagged stretches shaded, so the worst places stand out.
#include <string>
#include <utility>
#include <vector>

namespace gvio::eval {

struct ImageCheckPlotData {
  std::string title;
  std::vector<double> t_s;    // seconds from the start of the drive, ascending
  std::vector<double> ncc;    // NaN: not scored
  std::vector<double> depth;  // share 0..1; NaN: not scored
  std::vector<bool> flagged;
  std::vector<std::pair<double, double>> stretches_s;  // flagged stretches (from, to)
  // Per keyframe: flagged below (-inf: none).
  std::vector<double> ncc_threshold, depth_threshold;
};

// Writes STEM.png and STEM.svg atomically; InvalidInput for inconsistent input, io::InputError
// naming the file when it cannot be written. Returns the written paths.
std::vector<std::string> writeImageCheckPlot(const ImageCheckPlotData& data,
                                             const std::string& stem);

}  // namespace gvio::eval
