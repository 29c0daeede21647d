#include "io/image_loader.hpp"

#include <fmt/format.h>

#include <opencv2/imgcodecs.hpp>

#include "io/input_error.hpp"

namespace gvio::io {

cv::Mat loadGrayImage(const std::filesystem::path& file, const CameraModel& camera) {
  if (!std::filesystem::is_regular_file(file)) throw InputError(file, 0, "image file not found");
  cv::Mat image = cv::imread(file.string(), cv::IMREAD_GRAYSCALE);
  if (image.empty()) throw InputError(file, 0, "unreadable image (corrupt or not a PNG/JPEG)");
  if (image.cols != camera.width_px || image.rows != camera.height_px) {
    throw InputError(file, 0,
                     fmt::format("image is {}x{} but the calibration of {} says {}x{}", image.cols,
                                 image.rows, camera.name, camera.width_px, camera.height_px));
  }
  return image;
}

}  // namespace gvio::io
