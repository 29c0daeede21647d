#pragma once
// The front-end tests' simulated drive, with its images loaded.
#include <opencv2/core/mat.hpp>

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

}  // namespace gvio::test
