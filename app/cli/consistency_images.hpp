#pragma once
// `gvio consistency --run DIR --images`: the run's map checked against its recorded images, no
// ground truth needed (viz/image_check.hpp). Writes, into --out (default RUN/consistency_images):
// keyframes.csv (one row per checked keyframe), summary.json, scores.png/.svg (the scores along
// the drive, flagged stretches shaded) and worst_N_T.png (recorded | rendered | difference) for
// the worst keyframes.
#include <cstddef>
#include <filesystem>
#include <optional>

#include "cli/progress.hpp"
#include "viz/image_check.hpp"

namespace gvio::cli {

struct ImageConsistencyRequest {
  std::filesystem::path run;
  std::optional<std::filesystem::path> out;      // default: RUN/consistency_images
  std::optional<std::filesystem::path> dataset;  // instead of report.json's sources
  std::optional<std::filesystem::path> json;     // a copy of summary.json
  std::size_t every = 1;                         // every n-th map keyframe
  std::optional<double> at_s;                    // only the keyframe nearest this time
  std::optional<double> from_s, to_s;            // only keyframes in [from, to] s into the drive
  std::size_t worst_images = 3;
  bool no_revisits = false;  // --no-revisits: check.revisits off
  viz::ImageCheckOptions check;
  ProgressStyle progress = ProgressStyle::kOff;
};

int runImageConsistency(const ImageConsistencyRequest& request);

}  // namespace gvio::cli
