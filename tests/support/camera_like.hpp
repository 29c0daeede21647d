#pragma once
// A KITTI-sized (1241x376) mono8 image with camera-like content for the bag reading benchmarks:
// smooth structure plus sensor noise (noise alone would not compress at all, a flat image far too
// well).
#include <cmath>
#include <opencv2/core.hpp>
#include <random>

namespace gvio::test {

inline cv::Mat cameraLike(int k, std::mt19937& rng) {
  cv::Mat image(376, 1241, CV_8UC1);
  std::normal_distribution<double> noise(0.0, 2.0);
  for (int r = 0; r < image.rows; ++r) {
    auto* row = image.ptr<std::uint8_t>(r);
    for (int c = 0; c < image.cols; ++c) {
      const double v = 128 + 60 * std::sin(0.05 * (c + 7 * k)) * std::cos(0.07 * r) + noise(rng);
      row[c] = cv::saturate_cast<std::uint8_t>(v);
    }
  }
  return image;
}

}  // namespace gvio::test
