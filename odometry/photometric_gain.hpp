#pragma once
// Exposure changes between two images, measured where a tracker matched them. KLT assumes that
// a patch keeps its brightness (Lucas and Kanade 1981); a camera's auto exposure breaks that
// between frames (and between the two cameras of a rig that expose independently), and KLT then
// fits part of the brightness change as motion. A global gain is what an exposure or sensor-gain
// step does to every pixel, so it is estimated from the matched patches themselves (robust to
// the scene changing at the image borders), and the image is scaled by its inverse before the
// patches are matched again.
#include <opencv2/core/mat.hpp>

#include <optional>
#include <vector>

namespace gvio::odometry {

// The median over the matched points (`matched[i]`) of mean(to patch) / mean(from patch), over
// (2 half_px + 1)^2 patches (bilinear, at the sub-pixel positions): the gain of `to` against
// `from`. Patches with a clipped pixel (below 3 or above 250 in either image) do not count: they
// do not scale with the gain. None when fewer than `min_points` patches count.
[[nodiscard]] std::optional<double> medianPatchGain(const cv::Mat& from, const cv::Mat& to,
                                                    const std::vector<cv::Point2f>& from_px,
                                                    const std::vector<cv::Point2f>& to_px,
                                                    const std::vector<bool>& matched, int half_px,
                                                    int min_points);

// mean(to) / mean(from) over the whole images, none for a black `from`: the gain where too few
// points were matched to measure it on patches (a large step can defeat KLT on weak texture).
[[nodiscard]] std::optional<double> meanImageGain(const cv::Mat& from, const cv::Mat& to);

// `image` (8-bit grey) divided by `gain`, rounded and saturated to [0, 255].
void removeGain(const cv::Mat& image, double gain, cv::Mat& out);

}  // namespace gvio::odometry
