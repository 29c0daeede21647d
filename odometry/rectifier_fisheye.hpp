#pragma once
// The equidistant (fisheye, Kannala-Brandt 2006) part of odometry::Rectifier: new intrinsics and
// rectifying rotations from OpenCV's fisheye module (balance 0, CALIB_ZERO_DISPARITY), zoomed in
// just enough that every rectified pixel samples inside the raw image. Balance 0 alone fits the
// view to the raw image's four edge midpoints only, and for stereo cv::fisheye::stereoRectify then
// takes the smaller of the two focal lengths and the mean principal point: on the TUM VI rig that
// leaves bands up to ~4.6 raw px outside the image, which cv::stereoRectify's alpha 0 (radtan)
// does not. Internal to odometry/; no file I/O.
#include <opencv2/core/mat.hpp>

namespace gvio::odometry::fisheye {

// The rectified camera's K (3x3 CV_64F) for one raw fisheye camera (K, D: k1 k2 k3 k4) seen
// without rotation, of the same image size.
cv::Mat monoIntrinsics(const cv::Mat& K, const cv::Mat& D, const cv::Size& size);

struct StereoRectification {
  cv::Mat K_new;            // 3x3, shared by both rectified cameras
  cv::Mat R_left, R_right;  // x_rect = R x_raw, for each camera
};

// R, T as cv::fisheye::stereoRectify takes them: x_right = R x_left + T.
StereoRectification stereoRectification(const cv::Mat& K_l, const cv::Mat& D_l, const cv::Mat& K_r,
                                        const cv::Mat& D_r, const cv::Size& size, const cv::Mat& R,
                                        const cv::Mat& T);

}  // namespace gvio::odometry::fisheye
