#include "mapping/loop_verification.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include <Eigen/Cholesky>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/features2d.hpp>

#include "odometry/error.hpp"
#include "odometry/lie.hpp"

namespace gvio::mapping {
namespace {

// RANSAC confidence (the iterations bound it anyway) and the floor of the pixel noise used for
// the covariance: a perfect fit on few points must not claim millimetres.
constexpr double kRansacConfidence = 0.999;
constexpr double kMinPixelSigma = 0.5;

struct Correspondences {
  std::vector<cv::Point3d> object;  // candidate camera frame
  std::vector<cv::Point2d> image;   // query image
};

// Candidate points (rows [0, points)) to query keypoints: best match within max_hamming, passing
// the ratio test; a query keypoint keeps only its best candidate point.
Correspondences matchDescriptors(const LoopKeyframe& query, const LoopKeyframe& candidate,
                                 const LoopMatchConfig& c) {
  Correspondences out;
  if (candidate.points == 0 || query.descriptors.rows < 2) return out;
  const cv::Mat cand = candidate.descriptors.rowRange(0, static_cast<int>(candidate.points));
  cv::BFMatcher matcher(cv::NORM_HAMMING);
  std::vector<std::vector<cv::DMatch>> knn;
  matcher.knnMatch(cand, query.descriptors, knn, 2);
  std::map<int, cv::DMatch> best_per_query;  // ordered: deterministic output
  for (const auto& m : knn) {
    if (m.size() < 2 || m[0].distance > static_cast<float>(c.max_hamming)) continue;
    if (m[0].distance >= static_cast<float>(c.ratio) * m[1].distance) continue;
    auto [it, inserted] = best_per_query.emplace(m[0].trainIdx, m[0]);
    if (!inserted && m[0].distance < it->second.distance) it->second = m[0];
  }
  for (const auto& [q, m] : best_per_query) {
    const Eigen::Vector3f& p = candidate.p_c[static_cast<std::size_t>(m.queryIdx)];
    out.object.emplace_back(p.x(), p.y(), p.z());
    const Eigen::Vector2f& u = query.px[static_cast<std::size_t>(q)];
    out.image.emplace_back(u.x(), u.y());
  }
  return out;
}

cv::Matx33d intrinsics(const CameraModel& cam) {
  return {cam.fx, 0.0, cam.cx, 0.0, cam.fy, cam.cy, 0.0, 0.0, 1.0};
}

Eigen::Isometry3d toIsometry(const cv::Mat& rvec, const cv::Mat& tvec) {
  cv::Mat R_cv;
  cv::Rodrigues(rvec, R_cv);
  Eigen::Matrix3d R;
  Eigen::Vector3d t;
  cv::cv2eigen(R_cv, R);
  cv::cv2eigen(tvec, t);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R;
  T.translation() = t;
  return T;
}

// Reprojection error (px) of each correspondence under T_q_c (candidate camera -> query camera).
std::vector<double> reprojectionErrors(const Correspondences& c, const Eigen::Isometry3d& T_q_c,
                                       const CameraModel& cam) {
  std::vector<double> err(c.object.size());
  for (std::size_t i = 0; i < err.size(); ++i) {
    const Eigen::Vector3d p = T_q_c * Eigen::Vector3d(c.object[i].x, c.object[i].y, c.object[i].z);
    if (p.z() <= 1e-6) {
      err[i] = std::numeric_limits<double>::infinity();
      continue;
    }
    const Eigen::Vector2d u(cam.fx * p.x() / p.z() + cam.cx, cam.fy * p.y() / p.z() + cam.cy);
    err[i] = (u - Eigen::Vector2d(c.image[i].x, c.image[i].y)).norm();
  }
  return err;
}

// Covariance of T_q_c's perturbation (R Exp(dphi), t + dt) from the inliers' projections:
// sigma^2 (J^T J)^-1 with sigma^2 the residual variance (2n - 6 degrees of freedom).
Matrix6d pnpCovariance(const Correspondences& c, const std::vector<int>& inliers,
                       const Eigen::Isometry3d& T_q_c, const CameraModel& cam,
                       const std::vector<double>& err) {
  Matrix6d H = Matrix6d::Zero();
  double sse = 0.0;
  const Eigen::Matrix3d R = T_q_c.rotation();
  for (int i : inliers) {
    const auto k = static_cast<std::size_t>(i);
    const Eigen::Vector3d x(c.object[k].x, c.object[k].y, c.object[k].z);
    const Eigen::Vector3d p = T_q_c * x;
    Eigen::Matrix<double, 2, 3> P;
    P << cam.fx / p.z(), 0.0, -cam.fx * p.x() / (p.z() * p.z()), 0.0, cam.fy / p.z(),
        -cam.fy * p.y() / (p.z() * p.z());
    Eigen::Matrix<double, 2, 6> J;
    J << P * (-R * odometry::hat(x)), P;
    H += J.transpose() * J;
    sse += err[k] * err[k];
  }
  const double dof = std::max(1.0, 2.0 * static_cast<double>(inliers.size()) - 6.0);
  const double sigma = std::max(kMinPixelSigma, std::sqrt(sse / dof));
  return sigma * sigma * H.inverse();
}

// T_bc_bq and its covariance in RelativePoseFactor's convention, from T_q_c and its covariance,
// through T_bc_bq = T_b_c T_q_c^-1 T_c_b (numeric Jacobian of that map: 6x6, exact enough).
void toBodyFrames(const Eigen::Isometry3d& T_q_c, const Matrix6d& cov_q_c, const CameraModel& cam,
                  LoopMeasurement& m) {
  const auto body = [&](const Eigen::Isometry3d& T) {
    return Eigen::Isometry3d(cam.T_b_c * T.inverse() * cam.T_b_c.inverse());
  };
  const Eigen::Isometry3d T0 = body(T_q_c);
  const auto error = [&](const Eigen::Matrix<double, 6, 1>& d) {
    Eigen::Isometry3d T = T_q_c;
    T.linear() = T_q_c.rotation() * odometry::expSo3(d.head<3>());
    T.translation() += d.tail<3>();
    const Eigen::Isometry3d B = body(T);
    Eigen::Matrix<double, 6, 1> e;
    e << odometry::logSo3(T0.rotation().transpose() * B.rotation()),
        B.translation() - T0.translation();
    return e;
  };
  Matrix6d G;
  const double h = 1e-6;
  for (int k = 0; k < 6; ++k) {
    Eigen::Matrix<double, 6, 1> d = Eigen::Matrix<double, 6, 1>::Zero();
    d(k) = h;
    G.col(k) = (error(d) - error(-d)) / (2.0 * h);
  }
  m.T_cand_query = T0;
  m.covariance = G * cov_q_c * G.transpose();
}

}  // namespace

void LoopMatchConfig::validate() const {
  if (max_hamming < 1 || max_hamming > 256) {
    throw InvalidInput("config: loops.max_hamming must be in 1..256");
  }
  if (!(ratio > 0.0 && ratio <= 1.0)) throw InvalidInput("config: loops.ratio must be in (0, 1]");
  if (min_inliers < 6) throw InvalidInput("config: loops.min_inliers must be >= 6");
  if (!(std::isfinite(ransac_threshold_px) && ransac_threshold_px > 0.0)) {
    throw InvalidInput("config: loops.ransac_threshold_px must be > 0");
  }
  if (ransac_iterations < 1) throw InvalidInput("config: loops.ransac_iterations must be >= 1");
  if (!(std::isfinite(max_reprojection_px) && max_reprojection_px > 0.0)) {
    throw InvalidInput("config: loops.max_reprojection_px must be > 0");
  }
}

std::string toString(LoopCheck check) {
  switch (check) {
    case LoopCheck::kOk:
      return "ok";
    case LoopCheck::kNoPoints:
      return "no_points";
    case LoopCheck::kFewMatches:
      return "few_matches";
    case LoopCheck::kPnpFailed:
      return "pnp_failed";
    case LoopCheck::kFewInliers:
      return "few_inliers";
    case LoopCheck::kReprojection:
      return "reprojection";
  }
  return "unknown";
}

LoopMeasurement verifyLoop(const LoopKeyframe& query, const LoopKeyframe& candidate,
                           const CameraModel& camera, const LoopMatchConfig& config) {
  LoopMeasurement m;
  if (candidate.points < 4) return m;  // kNoPoints
  const Correspondences c = matchDescriptors(query, candidate, config);
  m.matches = static_cast<int>(c.object.size());
  if (m.matches < config.min_inliers) {
    m.check = LoopCheck::kFewMatches;
    return m;
  }
  cv::Mat rvec, tvec;
  std::vector<int> inliers;
  const cv::Matx33d K = intrinsics(camera);
  const bool found =
      cv::solvePnPRansac(c.object, c.image, K, cv::noArray(), rvec, tvec, false,
                         config.ransac_iterations, static_cast<float>(config.ransac_threshold_px),
                         kRansacConfidence, inliers, cv::SOLVEPNP_AP3P);
  if (!found || static_cast<int>(inliers.size()) < 4) {
    m.check = LoopCheck::kPnpFailed;
    return m;
  }
  // Refine on the inliers, then take the inliers again under the refined pose (twice: the set
  // and the pose settle together).
  for (int round = 0; round < 2; ++round) {
    std::vector<cv::Point3d> obj;
    std::vector<cv::Point2d> img;
    for (int i : inliers) {
      obj.push_back(c.object[static_cast<std::size_t>(i)]);
      img.push_back(c.image[static_cast<std::size_t>(i)]);
    }
    cv::solvePnPRefineLM(obj, img, K, cv::noArray(), rvec, tvec);
    const std::vector<double> err = reprojectionErrors(c, toIsometry(rvec, tvec), camera);
    inliers.clear();
    for (std::size_t i = 0; i < err.size(); ++i) {
      if (err[i] <= config.ransac_threshold_px) inliers.push_back(static_cast<int>(i));
    }
    if (static_cast<int>(inliers.size()) < 4) break;
  }
  const Eigen::Isometry3d T_q_c = toIsometry(rvec, tvec);
  if (!T_q_c.matrix().allFinite()) {
    m.check = LoopCheck::kPnpFailed;
    return m;
  }
  const std::vector<double> err = reprojectionErrors(c, T_q_c, camera);
  m.inliers = static_cast<int>(inliers.size());
  if (m.inliers < config.min_inliers) {
    m.check = LoopCheck::kFewInliers;
    return m;
  }
  double sum = 0.0;
  for (int i : inliers) sum += err[static_cast<std::size_t>(i)];
  m.reprojection_px = sum / static_cast<double>(m.inliers);
  if (m.reprojection_px > config.max_reprojection_px) {
    m.check = LoopCheck::kReprojection;
    return m;
  }
  toBodyFrames(T_q_c, pnpCovariance(c, inliers, T_q_c, camera, err), camera, m);
  // Degenerate geometry (inliers on a line, all at one depth far away) leaves the pose
  // unconstrained in some direction: no usable loop, whatever the inlier count.
  const Eigen::LLT<Matrix6d> llt(m.covariance);
  if (!m.covariance.allFinite() || llt.info() != Eigen::Success) {
    m.check = LoopCheck::kPnpFailed;
    return m;
  }
  m.check = LoopCheck::kOk;
  return m;
}

}  // namespace gvio::mapping
