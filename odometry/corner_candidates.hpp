#pragma once
// The candidate step of Shi-Tomasi detection (cv::goodFeaturesToTrack's): over a corner response
// image, the largest response inside a mask, and the 3x3 local maxima at least a threshold inside
// it, strongest first. Both scan the whole image every frame, so both test 4 responses at a time
// and look at single pixels only where one of the 4 passes (a few per cent of them); the results
// are the same as those of a pixel-by-pixel scan, bit for bit.

#include <opencv2/core.hpp>

#include <utility>
#include <vector>

namespace gvio::odometry {

// The largest response (CV_32F) where the mask (CV_8U, same size) is non-zero; 0 when none is
// larger. What cv::minMaxLoc with the mask gives whenever the maximum is positive.
float maskedMaximum(const cv::Mat& response, const cv::Mat& mask);

// The pixels inside the border of one, where the mask is non-zero, whose response is at least
// threshold and no smaller than any of its 8 neighbours: (response, raster index y * cols + x),
// the largest response first, ties in raster order.
std::vector<std::pair<float, int>> localMaximumCandidates(const cv::Mat& response,
                                                          const cv::Mat& mask, float threshold);

}  // namespace gvio::odometry
