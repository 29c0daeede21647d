#include "odometry/pnp.hpp"

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

namespace gvio::odometry {
namespace {

// RANSAC iterations and confidence (OpenCV's defaults, stated so the callers agree).
constexpr int kRansacIterations = 100;
constexpr double kRansacConfidence = 0.99;

}  // namespace

std::optional<PnpResult> pnpRansac(const std::vector<cv::Point3d>& object,
                                   const std::vector<cv::Point2d>& image, const cv::Matx33d& K,
                                   const Eigen::Isometry3d& T_c_w_guess, float threshold) {
  cv::Mat R_cv, rvec, tvec;
  const Eigen::Matrix3d R_guess = T_c_w_guess.linear();
  const Eigen::Vector3d t_guess = T_c_w_guess.translation();
  cv::eigen2cv(R_guess, R_cv);
  cv::eigen2cv(t_guess, tvec);
  cv::Rodrigues(R_cv, rvec);
  std::vector<int> inliers;
  if (!cv::solvePnPRansac(object, image, cv::Mat(K), cv::noArray(), rvec, tvec, true,
                          kRansacIterations, threshold, kRansacConfidence, inliers,
                          cv::SOLVEPNP_ITERATIVE)) {
    return std::nullopt;
  }
  cv::Rodrigues(rvec, R_cv);
  Eigen::Matrix3d R;
  Eigen::Vector3d t;
  cv::cv2eigen(R_cv, R);
  cv::cv2eigen(tvec, t);
  PnpResult result;
  result.T_c_w.linear() = R;
  result.T_c_w.translation() = t;
  result.inliers = static_cast<int>(inliers.size());
  if (!result.T_c_w.matrix().allFinite()) return std::nullopt;
  return result;
}

}  // namespace gvio::odometry
