#pragma once
// Turns raw calibrated cameras into the rectified pinhole cameras the estimator expects (no
// distortion; for stereo one shared K and the right camera offset only along the left x axis), and
// resamples images accordingly. Radtan cameras: cv::stereoRectify (alpha 0, CALIB_ZERO_DISPARITY)
// for stereo, cv::getOptimalNewCameraMatrix (alpha 0) for mono. Equidistant (fisheye,
// Kannala-Brandt 2006) cameras through OpenCV's fisheye module: cv::fisheye::stereoRectify (balance
// 0, CALIB_ZERO_DISPARITY) for stereo, cv::fisheye::estimateNewCameraMatrixForUndistortRectify
// (balance 0) for mono, each zoomed in (fov_scale) just enough that no rectified pixel samples
// outside the raw image (odometry/rectifier_fisheye.hpp); a stereo pair must share one model.
// Cameras that already are rectified (KITTI's rectified grey pair, the simulator's output) pass
// through untouched: remapping costs time and blurs. Pure image geometry: no file I/O.
#include <optional>

#include <opencv2/core/mat.hpp>

#include "odometry/measurements.hpp"

namespace gvio::odometry {

struct RectifiedImages {
  cv::Mat left;
  cv::Mat right;  // empty for a mono rig
};

class Rectifier {
 public:
  // Within this, cameras count as already rectified: rotation matrices of the two T_b_c (largest
  // entry difference), right camera off the left camera's x axis (m), intrinsics (px).
  static constexpr double kIdentityTolerance = 1e-9;

  // `left` always, `right` for a stereo rig. Throws InvalidInput for an invalid camera (size or
  // focal length not positive; radtan distortion not 0, 4 or 5 coefficients, equidistant not
  // exactly 4), stereo cameras of different sizes or different distortion models, and rigs that
  // cannot be rectified side by side (the right camera must lie to the right of the left one,
  // mostly along its x axis).
  explicit Rectifier(const CameraModel& left,
                     const std::optional<CameraModel>& right = std::nullopt);

  // True when the input cameras are already rectified: rectify() then returns its input as is.
  [[nodiscard]] bool isIdentity() const { return identity_; }
  [[nodiscard]] bool isStereo() const { return right_.has_value(); }

  // The rectified cameras (same image size, no distortion). Each T_b_c is the original T_b_c
  // turned by the rectifying rotation (made exactly orthonormal); the right one equals the left
  // one moved by +baseline along the left rectified x axis.
  [[nodiscard]] const CameraModel& left() const { return left_; }
  [[nodiscard]] const std::optional<CameraModel>& right() const { return right_; }
  [[nodiscard]] double baselineM() const { return baseline_m_; }  // 0 for mono

  // Bilinear resampling of original images into the rectified cameras. Any type cv::remap takes
  // (8-bit grey in the pipeline; float in tests, where an image of its own x coordinates shows
  // where each rectified pixel samples). `right` is required for stereo and ignored for mono.
  // Throws InvalidInput when an image does not have the calibrated size.
  [[nodiscard]] RectifiedImages rectify(const cv::Mat& left,
                                        const cv::Mat& right = cv::Mat()) const;

 private:
  void initMono(const CameraModel& raw);
  void initStereo(const CameraModel& raw_left, const CameraModel& raw_right);
  cv::Mat remapped(const cv::Mat& image, const CameraModel& raw, const cv::Mat& map_xy,
                   const cv::Mat& map_frac) const;

  CameraModel raw_left_;
  std::optional<CameraModel> raw_right_;
  CameraModel left_;
  std::optional<CameraModel> right_;
  double baseline_m_ = 0.0;
  bool identity_ = false;
  // Fixed-point maps (CV_16SC2 + CV_16UC1): what remap would convert float maps to on every call.
  cv::Mat map_left_xy_, map_left_frac_, map_right_xy_, map_right_frac_;
};

}  // namespace gvio::odometry
