#pragma once
// A render (RGBA, rows top to bottom) as the BGR image OpenCV writes (PNG, video).
#include <opencv2/core/mat.hpp>

#include "render/image.hpp"

namespace gvio::viz {

cv::Mat toBgr(const render::ImageRgba& image);

}  // namespace gvio::viz
