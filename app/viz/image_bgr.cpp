#include "viz/image_bgr.hpp"

#include <opencv2/imgproc.hpp>

namespace gvio::viz {

cv::Mat toBgr(const render::ImageRgba& image) {
  const cv::Mat rgba(image.height, image.width, CV_8UC4,
                     const_cast<std::uint8_t*>(image.rgba.data()));
  cv::Mat bgr;
  cv::cvtColor(rgba, bgr, cv::COLOR_RGBA2BGR);
  return bgr;
}

}  // namespace gvio::viz
