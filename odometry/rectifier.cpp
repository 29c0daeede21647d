#include "odometry/rectifier.hpp"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <string>

#include "odometry/error.hpp"
#include "odometry/lie.hpp"
#include "odometry/rectifier_fisheye.hpp"

namespace gvio::odometry {
namespace {

std::string nameOf(const CameraModel& cam) {
  return cam.name.empty() ? std::string("camera") : "camera " + cam.name;
}

void validateCamera(const CameraModel& cam) {
  const bool finite = std::isfinite(cam.fx) && std::isfinite(cam.fy) && std::isfinite(cam.cx) &&
                      std::isfinite(cam.cy) && cam.T_b_c.matrix().allFinite();
  if (cam.width_px <= 0 || cam.height_px <= 0 || !finite || cam.fx <= 0.0 || cam.fy <= 0.0) {
    throw InvalidInput(nameOf(cam) + ": image size and focal lengths must be positive and finite");
  }
  const std::size_t n = cam.distortion.size();
  if (cam.distortion_model == Distortion::kEquidistant) {
    if (n != 4) {
      throw InvalidInput(nameOf(cam) +
                         ": the equidistant (fisheye) model takes exactly 4 distortion "
                         "coefficients (k1 k2 k3 k4), got " +
                         std::to_string(n));
    }
  } else if (n != 0 && n != 4 && n != 5 && n != 8) {
    // 8: OpenCV's rational model (ROS's rational_polynomial), which cv::undistort takes as is.
    throw InvalidInput(nameOf(cam) + ": expected 0, 4, 5 or 8 distortion coefficients (k1 k2 p1 " +
                       "p2 [k3 [k4 k5 k6]]), got " + std::to_string(n));
  }
  for (const double d : cam.distortion) {
    if (!std::isfinite(d)) throw InvalidInput(nameOf(cam) + ": distortion is not finite");
  }
}

bool isFisheye(const CameraModel& cam) {
  return cam.distortion_model == Distortion::kEquidistant;
}

cv::Mat intrinsics(const CameraModel& cam) {
  return (cv::Mat_<double>(3, 3) << cam.fx, 0.0, cam.cx, 0.0, cam.fy, cam.cy, 0.0, 0.0, 1.0);
}

cv::Mat distortionOf(const CameraModel& cam) {
  cv::Mat d(1, static_cast<int>(cam.distortion.size()), CV_64F);
  for (std::size_t i = 0; i < cam.distortion.size(); ++i) {
    d.at<double>(0, static_cast<int>(i)) = cam.distortion[i];
  }
  return d;
}

Eigen::Matrix3d toEigen(const cv::Mat& m) {
  Eigen::Matrix3d out;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) out(r, c) = m.at<double>(r, c);
  }
  return out;
}

// The rectified pinhole camera: raw geometry, new intrinsics, no distortion, and T_b_c turned by
// the rectifying rotation (x_rect = R_rect x_raw, so the rectified camera is T_b_c * R_rect^T).
CameraModel rectifiedModel(const CameraModel& raw, const cv::Mat& K_new,
                           const Eigen::Matrix3d& R_rect_raw) {
  CameraModel cam = raw;
  cam.fx = K_new.at<double>(0, 0);
  cam.fy = K_new.at<double>(1, 1);
  cam.cx = K_new.at<double>(0, 2);
  cam.cy = K_new.at<double>(1, 2);
  cam.distortion_model = Distortion::kRadtan;  // with no coefficients: a pinhole
  cam.distortion.clear();
  cam.T_b_c.linear() = normalizeRotation(raw.T_b_c.linear() * R_rect_raw.transpose());
  return cam;
}

// Maps from the rectified camera (K_new, turned by R_rect: x_rect = R_rect x_raw; empty for none)
// into the raw image, through the raw camera's own distortion model.
void undistortRectifyMap(const CameraModel& raw, const cv::Mat& R_rect, const cv::Mat& K_new,
                         cv::Mat& map_xy, cv::Mat& map_frac) {
  const cv::Size size(raw.width_px, raw.height_px);
  if (isFisheye(raw)) {
    cv::fisheye::initUndistortRectifyMap(intrinsics(raw), distortionOf(raw), R_rect, K_new, size,
                                         CV_16SC2, map_xy, map_frac);
  } else {
    cv::initUndistortRectifyMap(intrinsics(raw), distortionOf(raw), R_rect, K_new, size, CV_16SC2,
                                map_xy, map_frac);
  }
}

// The camera as given, minus its (zero) distortion, with an exact rotation: calibration files
// print rotations to 6-7 digits, and the estimator inverts T_b_c as a rigid transform.
CameraModel passThrough(const CameraModel& raw) {
  return rectifiedModel(raw, intrinsics(raw), Eigen::Matrix3d::Identity());
}

InvalidInput notSideBySide(const CameraModel& raw_left, const CameraModel& raw_right) {
  return InvalidInput("stereo: cameras " + raw_left.name + " and " + raw_right.name +
                      " cannot be rectified side by side (the right camera must lie to the right "
                      "of the left one, mostly along its x axis)");
}

// Right camera = left camera moved by +baseline along its own x axis: the estimator's contract,
// built exactly rather than left to rounding in two separately rotated T_b_c.
CameraModel rightOf(const CameraModel& left, const CameraModel& raw_right, double baseline_m) {
  CameraModel cam = left;
  cam.name = raw_right.name;
  cam.T_b_c = left.T_b_c * Eigen::Translation3d(baseline_m, 0.0, 0.0);
  return cam;
}

}  // namespace

Rectifier::Rectifier(const CameraModel& left, const std::optional<CameraModel>& right)
    : raw_left_(left), raw_right_(right) {
  validateCamera(left);
  if (!right) {
    initMono(left);
    return;
  }
  validateCamera(*right);
  if (right->distortion_model != left.distortion_model) {
    // One rectification needs both cameras undistorted through one model; a radtan camera is no
    // equidistant one with some coefficients (nor the other way round).
    throw InvalidInput("stereo: " + nameOf(left) + " is " + toString(left.distortion_model) +
                       " and " + nameOf(*right) + " " + toString(right->distortion_model) +
                       ": cameras of different distortion models cannot be rectified together "
                       "(calibrate both with one model)");
  }
  if (right->width_px != left.width_px || right->height_px != left.height_px) {
    throw InvalidInput("stereo cameras of different image sizes (" + std::to_string(left.width_px) +
                       "x" + std::to_string(left.height_px) + " and " +
                       std::to_string(right->width_px) + "x" + std::to_string(right->height_px) +
                       ") cannot be rectified together");
  }
  initStereo(left, *right);
}

void Rectifier::initMono(const CameraModel& raw) {
  if (!hasLensDistortion(raw)) {
    identity_ = true;
    left_ = passThrough(raw);
    return;
  }
  const cv::Size size(raw.width_px, raw.height_px);
  const cv::Mat K = intrinsics(raw), D = distortionOf(raw);
  // alpha (balance) 0: every rectified pixel sees the scene (no black border for the tracker to
  // find; a wide fisheye's corners see more than any pinhole image could hold anyway).
  const cv::Mat K_new = isFisheye(raw) ? fisheye::monoIntrinsics(K, D, size)
                                       : cv::getOptimalNewCameraMatrix(K, D, size, 0.0, size);
  undistortRectifyMap(raw, cv::Mat(), K_new, map_left_xy_, map_left_frac_);
  left_ = rectifiedModel(raw, K_new, Eigen::Matrix3d::Identity());
}

void Rectifier::initStereo(const CameraModel& raw_left, const CameraModel& raw_right) {
  // Already rectified: equal rotations and the right camera on the left camera's x axis. Compared
  // in the body frame rather than through T_cl_cr: a rotation read from a calibration file is
  // orthonormal only to ~1e-7, so R_l^T R_r would differ from I by that much although both cameras
  // share the very same matrix (KITTI's rectified pair: one R_rect_00, one IMU chain).
  const Eigen::Matrix3d& R_b_cl = raw_left.T_b_c.linear();
  const Eigen::Vector3d x_b_cl = R_b_cl.col(0).normalized();
  const Eigen::Vector3d d_b = raw_right.T_b_c.translation() - raw_left.T_b_c.translation();
  const double along_x_m = d_b.dot(x_b_cl);
  const bool same_intrinsics = std::abs(raw_left.fx - raw_right.fx) <= kIdentityTolerance &&
                               std::abs(raw_left.fy - raw_right.fy) <= kIdentityTolerance &&
                               std::abs(raw_left.cx - raw_right.cx) <= kIdentityTolerance &&
                               std::abs(raw_left.cy - raw_right.cy) <= kIdentityTolerance;
  if (!hasLensDistortion(raw_left) && !hasLensDistortion(raw_right) && same_intrinsics &&
      (raw_right.T_b_c.linear() - R_b_cl).cwiseAbs().maxCoeff() <= kIdentityTolerance &&
      (d_b - along_x_m * x_b_cl).norm() <= kIdentityTolerance) {
    if (along_x_m <= 0.0) {
      throw InvalidInput("stereo: the right camera (" + raw_right.name +
                         ") must lie to the right of the left one (+x); got x offset " +
                         std::to_string(along_x_m) + " m");
    }
    identity_ = true;
    baseline_m_ = along_x_m;
    left_ = passThrough(raw_left);
    right_ = rightOf(left_, raw_right, baseline_m_);
    return;
  }

  const Eigen::Isometry3d T_cl_cr = raw_left.T_b_c.inverse() * raw_right.T_b_c;
  const Eigen::Vector3d p_cl_cr = T_cl_cr.translation();
  const cv::Size size(raw_left.width_px, raw_left.height_px);
  const cv::Mat K_l = intrinsics(raw_left), D_l = distortionOf(raw_left);
  const cv::Mat K_r = intrinsics(raw_right), D_r = distortionOf(raw_right);
  // OpenCV's R, T map left-camera points into the right camera: x_r = R x_l + T.
  const Eigen::Isometry3d T_cr_cl = T_cl_cr.inverse();
  cv::Mat R(3, 3, CV_64F), T(3, 1, CV_64F);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) R.at<double>(r, c) = T_cr_cl.linear()(r, c);
    T.at<double>(r, 0) = T_cr_cl.translation()(r);
  }
  cv::Mat R_l, R_r, K_new;
  // Zero disparity: both rectified cameras share one principal point (the estimator's contract);
  // alpha (balance) 0: no invalid (black) pixels in either rectified image.
  if (isFisheye(raw_left)) {
    // cv::fisheye::stereoRectify always turns the baseline onto x, even a vertical one; refuse
    // what cv::stereoRectify would rectify vertically: |t_y| >= |t_x| once each camera is turned
    // by half the relative rotation.
    const Eigen::AngleAxisd aa_cr_cl(T_cr_cl.linear());
    const Eigen::Vector3d t_half =
        Eigen::AngleAxisd(-0.5 * aa_cr_cl.angle(), aa_cr_cl.axis()) * T_cr_cl.translation();
    if (std::abs(t_half.y()) >= std::abs(t_half.x())) throw notSideBySide(raw_left, raw_right);
    const fisheye::StereoRectification rect =
        fisheye::stereoRectification(K_l, D_l, K_r, D_r, size, R, T);
    R_l = rect.R_left;
    R_r = rect.R_right;
    K_new = rect.K_new;
  } else {
    cv::Mat P_l, P_r, Q;
    cv::stereoRectify(K_l, D_l, K_r, D_r, size, R, T, R_l, R_r, P_l, P_r, Q,
                      cv::CALIB_ZERO_DISPARITY, 0.0, size);
    K_new = P_l.colRange(0, 3).clone();
  }
  const Eigen::Matrix3d R_rl_l = toEigen(R_l);
  // The right camera centre seen from the rectified left camera: (baseline, 0, 0) for a
  // horizontal rig; stereoRectify rectifies vertically when the offset is mostly along y.
  const Eigen::Vector3d p_rl_cr = R_rl_l * p_cl_cr;
  if (!cv::checkRange(K_new) || p_rl_cr.x() <= 0.0 ||
      std::abs(p_rl_cr.y()) > 1e-6 * p_rl_cr.norm() ||
      std::abs(p_rl_cr.z()) > 1e-6 * p_rl_cr.norm()) {
    throw notSideBySide(raw_left, raw_right);
  }
  undistortRectifyMap(raw_left, R_l, K_new, map_left_xy_, map_left_frac_);
  undistortRectifyMap(raw_right, R_r, K_new, map_right_xy_, map_right_frac_);
  baseline_m_ = p_rl_cr.x();
  left_ = rectifiedModel(raw_left, K_new, R_rl_l);
  right_ = rightOf(left_, raw_right, baseline_m_);
}

cv::Mat Rectifier::remapped(const cv::Mat& image, const CameraModel& raw, const cv::Mat& map_xy,
                            const cv::Mat& map_frac) const {
  if (image.cols != raw.width_px || image.rows != raw.height_px) {
    throw InvalidInput("rectify: " + nameOf(raw) + " image is " + std::to_string(image.cols) + "x" +
                       std::to_string(image.rows) + ", calibrated for " +
                       std::to_string(raw.width_px) + "x" + std::to_string(raw.height_px));
  }
  if (identity_) return image;
  cv::Mat out;
  // alpha 0 fits the valid region from a sparse grid of edge points, so edge pixels may sample up
  // to ~1 px outside the image; replicating the edge there avoids a dark seam, which the corner
  // detector would take for structure.
  cv::remap(image, out, map_xy, map_frac, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  return out;
}

RectifiedImages Rectifier::rectify(const cv::Mat& left, const cv::Mat& right) const {
  RectifiedImages out;
  out.left = remapped(left, raw_left_, map_left_xy_, map_left_frac_);
  if (raw_right_) {
    if (right.empty()) throw InvalidInput("rectify: stereo rig but no right image");
    out.right = remapped(right, *raw_right_, map_right_xy_, map_right_frac_);
  }
  return out;
}

}  // namespace gvio::odometry
