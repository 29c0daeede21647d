// The corner candidates' 4-wide scans against a per-pixel scan: the same maximum and the same
// candidates in the same order, bit for bit, on responses built to hit the vector loop's edges
// (widths that are no multiple of 4, plateaus, masks cut at odd columns, values at the threshold).
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include "odometry/corner_candidates.hpp"

namespace gvio::test {
namespace {

float referenceMaximum(const cv::Mat& response, const cv::Mat& mask) {
  float best = 0.0F;
  for (int y = 0; y < response.rows; ++y) {
    for (int x = 0; x < response.cols; ++x) {
      if (mask.at<std::uint8_t>(y, x) != 0) best = std::max(best, response.at<float>(y, x));
    }
  }
  return best;
}

// 3 x 3 maxima as goodFeaturesToTrack finds them: the response equal to its dilation.
std::vector<std::pair<float, int>> referenceCandidates(const cv::Mat& response, const cv::Mat& mask,
                                                       float threshold) {
  cv::Mat dilated;
  cv::dilate(response, dilated, cv::Mat());
  std::vector<std::pair<float, int>> out;
  for (int y = 1; y + 1 < response.rows; ++y) {
    for (int x = 1; x + 1 < response.cols; ++x) {
      const float v = response.at<float>(y, x);
      if (v >= threshold && mask.at<std::uint8_t>(y, x) != 0 && v == dilated.at<float>(y, x)) {
        out.emplace_back(v, y * response.cols + x);
      }
    }
  }
  std::stable_sort(out.begin(), out.end(),
                   [](const auto& a, const auto& b) { return a.first > b.first; });
  return out;
}

// A smoothed random response with flat steps (plateaus: equal neighbours) and some negative
// values, and a mask of random discs cut out of it (as the tracker's mask of existing tracks).
std::pair<cv::Mat, cv::Mat> randomResponse(int rows, int cols, std::uint64_t seed) {
  cv::RNG rng(seed);
  cv::Mat noise(rows, cols, CV_32F);
  rng.fill(noise, cv::RNG::UNIFORM, -0.1, 1.0);
  cv::Mat response;
  cv::GaussianBlur(noise, response, cv::Size(5, 5), 1.0);
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < cols; ++x) {
      float& v = response.at<float>(y, x);
      v = std::round(v * 64.0F) / 64.0F;  // plateaus
    }
  }
  cv::Mat mask(rows, cols, CV_8U, cv::Scalar(255));
  for (int i = 0; i < rows * cols / 200; ++i) {
    cv::circle(mask, cv::Point(rng.uniform(0, cols), rng.uniform(0, rows)), rng.uniform(1, 9),
               cv::Scalar(0), cv::FILLED);
  }
  return {response, mask};
}

TEST(CornerCandidates, FourWideScansGiveThePerPixelResultsBitForBit) {
  int compared = 0;
  for (const int cols : {3, 4, 5, 7, 8, 9, 13, 64, 101, 1241}) {
    for (const int rows : {3, 4, 17, 60}) {
      const auto [response, mask] =
          randomResponse(rows, cols, static_cast<std::uint64_t>(rows * 10007 + cols));
      const float best = odometry::maskedMaximum(response, mask);
      ASSERT_EQ(best, referenceMaximum(response, mask)) << rows << " x " << cols;
      // Thresholds at, below and above the values present, the plateaus' steps included.
      for (const float threshold : {-1.0F, 0.25F, 0.5F, 35.0F / 64.0F, best, best + 1.0F}) {
        const auto got = odometry::localMaximumCandidates(response, mask, threshold);
        ASSERT_EQ(got, referenceCandidates(response, mask, threshold))
            << rows << " x " << cols << ", threshold " << threshold;
        compared += static_cast<int>(got.size());
      }
    }
  }
  EXPECT_GT(compared, 1000);  // the comparison covered real candidates, not only empty lists
}

TEST(CornerCandidates, AnAllMaskedImageHasNoMaximumAndNoCandidates) {
  cv::Mat response(20, 33, CV_32F, cv::Scalar(2.0F));
  const cv::Mat mask(20, 33, CV_8U, cv::Scalar(0));
  EXPECT_EQ(odometry::maskedMaximum(response, mask), 0.0F);
  EXPECT_TRUE(odometry::localMaximumCandidates(response, mask, 0.5F).empty());
}

TEST(CornerCandidates, ThePeakOfAnUnmaskedRowTailIsFound) {
  // The largest response in the last column of a width the 4-wide loop does not cover.
  cv::Mat response(5, 11, CV_32F, cv::Scalar(0.1F));
  response.at<float>(2, 9) = 3.0F;
  response.at<float>(4, 10) = 7.0F;  // border pixel: the maximum, never a candidate
  const cv::Mat mask(5, 11, CV_8U, cv::Scalar(255));
  EXPECT_EQ(odometry::maskedMaximum(response, mask), 7.0F);
  const auto got = odometry::localMaximumCandidates(response, mask, 1.0F);
  ASSERT_EQ(got.size(), 1U);
  EXPECT_EQ(got[0], std::make_pair(3.0F, 2 * 11 + 9));
}

}  // namespace
}  // namespace gvio::test
