#pragma once
// The front-end tests' simulated drive, with its images loaded.
#include <opencv2/core/mat.hpp>

#include <cstdint>
#include <string>
#include <vector>

#include "io/dataset.hpp"

namespace gvio::test {

struct StereoDrive {
  io::Dataset dataset;
  std::vector<cv::Mat> left, right;  // every frame's grey images, in frame order
};

// 3 s of the embedded demo drive, seed 11 (31 stereo frames), simulated once (cachedSimulation),
// read back with every frame's left and right image.
StereoDrive trackerTestDrive();

struct StereoPair {
  std::int64_t t_ns = 0;
  cv::Mat left, right;  // rectified grey images
};

// Every other frame of the real EuRoC V1_01 clip (../shared/data/euroc_v101_micro), rectified as
// the pipeline does; empty when the shared data is absent.
std::vector<StereoPair> eurocClipRectified();

}  // namespace gvio::test
