#include "odometry/rectifier_fisheye.hpp"

#include <opencv2/calib3d.hpp>

#include <algorithm>
#include <limits>
#include <vector>

namespace gvio::odometry::fisheye {
namespace {

// How far (px) the worst border pixel of the rectified camera (K_new, x_rect = R_rect x_raw)
// samples outside the raw image [0, w-1] x [0, h-1]: <= 0 when every one samples inside, and then
// every pixel does (the raw image's outline encloses the rectified border, so its inside too).
double borderOvershoot(const cv::Mat& K, const cv::Mat& D, const cv::Mat& R_rect,
                       const cv::Mat& K_new, const cv::Size& size) {
  const cv::Matx33d raw_from_pixel = cv::Matx33d(R_rect).t() * cv::Matx33d(K_new).inv();
  std::vector<cv::Point3d> rays;
  const auto add = [&](int u, int v) {
    const cv::Vec3d ray = raw_from_pixel * cv::Vec3d(u, v, 1.0);
    rays.emplace_back(ray[0], ray[1], ray[2]);
  };
  for (int u = 0; u < size.width; ++u) {
    add(u, 0);
    add(u, size.height - 1);
  }
  for (int v = 1; v + 1 < size.height; ++v) {
    add(0, v);
    add(size.width - 1, v);
  }
  // Behind the raw camera: no pinhole view reaches that far round.
  for (const cv::Point3d& ray : rays) {
    if (!(ray.z > 0.0)) return std::numeric_limits<double>::infinity();
  }
  std::vector<cv::Point2d> px;
  cv::fisheye::projectPoints(rays, px, cv::Vec3d::all(0.0), cv::Vec3d::all(0.0), K, D);
  double worst = -std::numeric_limits<double>::infinity();
  for (const cv::Point2d& p : px) {
    worst = std::max({worst, -p.x, -p.y, p.x - (size.width - 1), p.y - (size.height - 1)});
  }
  return worst;
}

// OpenCV's fov_scale divides the new focal length (< 1 zooms in). The largest fov_scale in
// [0.5, 1] whose view has no border pixel outside the raw image (bisection to ~1e-6; the view
// shrinks about the same image point as the scale falls).
template <typename Overshoot>
double fittingFovScale(const Overshoot& overshoot) {
  if (overshoot(1.0) <= 0.0) return 1.0;
  double inside = 0.5, outside = 1.0;
  for (int i = 0; i < 20; ++i) {
    const double mid = 0.5 * (inside + outside);
    (overshoot(mid) <= 0.0 ? inside : outside) = mid;
  }
  return inside;
}

}  // namespace

cv::Mat monoIntrinsics(const cv::Mat& K, const cv::Mat& D, const cv::Size& size) {
  const auto fitted = [&](double fov_scale) {
    cv::Mat K_new;
    cv::fisheye::estimateNewCameraMatrixForUndistortRectify(K, D, size, cv::Mat(), K_new, 0.0, size,
                                                            fov_scale);
    return K_new;
  };
  const cv::Mat I = cv::Mat::eye(3, 3, CV_64F);
  return fitted(fittingFovScale(
      [&](double fov_scale) { return borderOvershoot(K, D, I, fitted(fov_scale), size); }));
}

StereoRectification stereoRectification(const cv::Mat& K_l, const cv::Mat& D_l, const cv::Mat& K_r,
                                        const cv::Mat& D_r, const cv::Size& size, const cv::Mat& R,
                                        const cv::Mat& T) {
  const auto rectified = [&](double fov_scale) {
    StereoRectification out;
    cv::Mat P_l, P_r, Q;
    cv::fisheye::stereoRectify(K_l, D_l, K_r, D_r, size, R, T, out.R_left, out.R_right, P_l, P_r, Q,
                               cv::fisheye::CALIB_ZERO_DISPARITY, size, 0.0, fov_scale);
    out.K_new = P_l.colRange(0, 3).clone();
    return out;
  };
  return rectified(fittingFovScale([&](double fov_scale) {
    const StereoRectification r = rectified(fov_scale);
    return std::max(borderOvershoot(K_l, D_l, r.R_left, r.K_new, size),
                    borderOvershoot(K_r, D_r, r.R_right, r.K_new, size));
  }));
}

}  // namespace gvio::odometry::fisheye
