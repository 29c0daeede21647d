#include "odometry/mono_sfm.hpp"

#include <ceres/autodiff_cost_function.h>
#include <ceres/loss_function.h>
#include <ceres/manifold.h>
#include <ceres/problem.h>
#include <ceres/solver.h>
#include <Eigen/SVD>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include <algorithm>
#include <array>
#include <cmath>

#include "odometry/pnp.hpp"

namespace gvio::odometry {
namespace {

// Reprojection error (in pixels at the nominal focal length) beyond which a triangulated point
// or an adjusted observation is not trusted.
constexpr double kMaxPointErrorPx = 4.0;
constexpr int kBundleIterations = 20;

const Eigen::Vector2d* observationIn(const SfmTrack& t, int frame) {
  for (const auto& [k, uv] : t.observations) {
    if (k == frame) return &uv;
  }
  return nullptr;
}

Eigen::Vector2d project(const Eigen::Isometry3d& T_c_v, const Eigen::Vector3d& p_v) {
  const Eigen::Vector3d p_c = T_c_v * p_v;
  return p_c.head<2>() / p_c.z();
}

// Bundle-adjustment residual in pixels: camera pose T_c_v (quaternion x y z w, translation) and a
// point in the visual frame against a normalised observation.
struct ReprojectionCost {
  ReprojectionCost(Eigen::Vector2d uv, double focal) : uv_(std::move(uv)), focal_(focal) {}
  template <typename T>
  bool operator()(const T* q, const T* t, const T* p, T* r) const {
    const Eigen::Map<const Eigen::Quaternion<T>> Q(q);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> tt(t), P(p);
    const Eigen::Matrix<T, 3, 1> pc = Q * P + tt;
    r[0] = T(focal_) * (pc.x() / pc.z() - T(uv_.x()));
    r[1] = T(focal_) * (pc.y() / pc.z() - T(uv_.y()));
    return true;
  }
  Eigen::Vector2d uv_;
  double focal_;
};

class Solver {
 public:
  Solver(const std::vector<SfmTrack>& tracks, int n, const SfmOptions& o)
      : tracks_(tracks),
        n_(n),
        o_(o),
        poses_(static_cast<std::size_t>(n)),
        points_(tracks.size()) {}

  std::optional<SfmResult> run() {
    const int newest = n_ - 1;
    int ref = -1;
    for (int i = 0; i < newest && ref < 0; ++i) {
      if (relativePose(i, newest)) ref = i;
    }
    if (ref < 0) return std::nullopt;
    triangulatePair(ref, newest);
    // Frames between the pair: PnP from the previous one, then more points with the newest.
    for (int j = ref + 1; j < newest; ++j) {
      if (!locate(j, *poses_[static_cast<std::size_t>(j - 1)])) return std::nullopt;
      triangulatePair(j, newest);
      triangulatePair(ref, j);
    }
    // Frames before the reference, walking back.
    for (int j = ref - 1; j >= 0; --j) {
      if (!locate(j, *poses_[static_cast<std::size_t>(j + 1)])) return std::nullopt;
      triangulatePair(j, ref);
    }
    // Every other track seen from two located frames: its first and last observation.
    for (std::size_t k = 0; k < tracks_.size(); ++k) {
      const auto& obs = tracks_[k].observations;
      if (points_[k] || obs.size() < 2) continue;
      triangulate(k, obs.front().first, obs.back().first);
    }
    if (o_.bundle_adjust) bundleAdjust(ref);
    if (translationalParallaxPx(ref, newest) < 0.5 * o_.min_parallax_px) return std::nullopt;
    return finish(ref);
  }

 private:
  const Eigen::Isometry3d& pose(int k) const { return *poses_[static_cast<std::size_t>(k)]; }

  // Mean image motion (px) between frames a and b that the relative rotation does not explain:
  // near zero for a pure rotation, which passes the raw parallax test and fits an essential
  // matrix with any translation.
  [[nodiscard]] double translationalParallaxPx(int a, int b) const {
    const Eigen::Matrix3d R_b_a = pose(b).linear() * pose(a).linear().transpose();
    double sum = 0.0;
    int count = 0;
    for (const SfmTrack& t : tracks_) {
      const Eigen::Vector2d* ua = observationIn(t, a);
      const Eigen::Vector2d* ub = observationIn(t, b);
      if (ua == nullptr || ub == nullptr) continue;
      const Eigen::Vector3d r = R_b_a * ua->homogeneous();
      if (r.z() <= 0.0) continue;
      sum += (r.head<2>() / r.z() - *ub).norm();
      ++count;
    }
    return count == 0 ? 0.0 : sum / count * o_.focal_px;
  }

  // Essential matrix (5-point, RANSAC) and relative pose of the pair; the first camera is the
  // visual frame and the baseline has unit length (VINS-Mono's relativePose).
  bool relativePose(int a, int b) {
    std::vector<cv::Point2d> pa, pb;
    double parallax = 0.0;
    for (const SfmTrack& t : tracks_) {
      const Eigen::Vector2d* ua = observationIn(t, a);
      const Eigen::Vector2d* ub = observationIn(t, b);
      if (ua == nullptr || ub == nullptr) continue;
      pa.emplace_back(ua->x(), ua->y());
      pb.emplace_back(ub->x(), ub->y());
      parallax += (*ua - *ub).norm();
    }
    const auto common = static_cast<int>(pa.size());
    if (common < std::max(o_.min_common_features, 8)) return false;
    if (parallax / common * o_.focal_px < o_.min_parallax_px) return false;
    cv::Mat mask;
    const cv::Mat E = cv::findEssentialMat(pa, pb, 1.0, cv::Point2d(0, 0), cv::RANSAC, 0.999,
                                           o_.ransac_threshold_px / o_.focal_px, mask);
    if (E.rows != 3 || E.cols != 3) return false;
    cv::Mat R_cv, t_cv;
    const int inliers = cv::recoverPose(E, pa, pb, R_cv, t_cv, 1.0, cv::Point2d(0, 0), mask);
    if (inliers < o_.min_common_features / 2) return false;
    Eigen::Isometry3d T_b_a = Eigen::Isometry3d::Identity();
    for (int r = 0; r < 3; ++r) {
      T_b_a.translation()(r) = t_cv.at<double>(r);
      for (int c = 0; c < 3; ++c) T_b_a.linear()(r, c) = R_cv.at<double>(r, c);
    }
    if (!T_b_a.matrix().allFinite()) return false;
    poses_.assign(poses_.size(), std::nullopt);
    points_.assign(points_.size(), std::nullopt);
    poses_[static_cast<std::size_t>(a)] = Eigen::Isometry3d::Identity();
    poses_[static_cast<std::size_t>(b)] = T_b_a;
    return true;
  }

  // Linear (DLT) triangulation of track k from frames a and b (Hartley & Zisserman, sec. 12.2).
  void triangulate(std::size_t k, int a, int b) {
    if (a == b || !poses_[static_cast<std::size_t>(a)] || !poses_[static_cast<std::size_t>(b)]) {
      return;
    }
    const Eigen::Vector2d* ua = observationIn(tracks_[k], a);
    const Eigen::Vector2d* ub = observationIn(tracks_[k], b);
    if (ua == nullptr || ub == nullptr) return;
    const Eigen::Matrix<double, 3, 4> Pa = pose(a).matrix().topRows<3>();
    const Eigen::Matrix<double, 3, 4> Pb = pose(b).matrix().topRows<3>();
    Eigen::Matrix4d A;
    A.row(0) = ua->x() * Pa.row(2) - Pa.row(0);
    A.row(1) = ua->y() * Pa.row(2) - Pa.row(1);
    A.row(2) = ub->x() * Pb.row(2) - Pb.row(0);
    A.row(3) = ub->y() * Pb.row(2) - Pb.row(1);
    const Eigen::Vector4d X =
        Eigen::JacobiSVD<Eigen::Matrix4d>(A, Eigen::ComputeFullV).matrixV().col(3);
    if (std::abs(X.w()) < 1e-12) return;
    const Eigen::Vector3d p = X.head<3>() / X.w();
    if ((pose(a) * p).z() <= 0.0 || (pose(b) * p).z() <= 0.0) return;
    const Eigen::Vector3d ray_a = p - pose(a).inverse().translation();
    const Eigen::Vector3d ray_b = p - pose(b).inverse().translation();
    const double angle =
        std::acos(std::clamp(ray_a.normalized().dot(ray_b.normalized()), -1.0, 1.0));
    if (angle < o_.min_triangulation_deg * M_PI / 180.0) return;
    const double limit = kMaxPointErrorPx / o_.focal_px;
    if ((project(pose(a), p) - *ua).norm() > limit || (project(pose(b), p) - *ub).norm() > limit) {
      return;
    }
    points_[k] = p;
  }

  void triangulatePair(int a, int b) {
    for (std::size_t k = 0; k < tracks_.size(); ++k) {
      if (!points_[k]) triangulate(k, a, b);
    }
  }

  // PnP (RANSAC, then iterative refinement on the inliers) on normalised coordinates (K = I).
  bool locate(int j, const Eigen::Isometry3d& guess) {
    std::vector<cv::Point3d> object;
    std::vector<cv::Point2d> image;
    for (std::size_t k = 0; k < tracks_.size(); ++k) {
      const Eigen::Vector2d* u = observationIn(tracks_[k], j);
      if (!points_[k] || u == nullptr) continue;
      object.emplace_back(points_[k]->x(), points_[k]->y(), points_[k]->z());
      image.emplace_back(u->x(), u->y());
    }
    if (static_cast<int>(object.size()) < std::max(o_.min_pnp_points, 6)) return false;
    const auto solved = pnpRansac(object, image, cv::Matx33d::eye(), guess,
                                  static_cast<float>(2.0 * o_.ransac_threshold_px / o_.focal_px));
    if (!solved || solved->inliers < std::max(o_.min_pnp_points, 6)) return false;
    poses_[static_cast<std::size_t>(j)] = solved->T_c_w;
    return true;
  }

  // Bundle adjustment of all poses and points; the reference pose is the gauge (the scale stays
  // free and only drifts slightly under the damping).
  void bundleAdjust(int ref) {
    std::vector<std::array<double, 7>> blocks(poses_.size());
    for (std::size_t f = 0; f < poses_.size(); ++f) {
      const Eigen::Quaterniond q(pose(static_cast<int>(f)).linear());
      blocks[f] = {q.x(),
                   q.y(),
                   q.z(),
                   q.w(),
                   pose(static_cast<int>(f)).translation().x(),
                   pose(static_cast<int>(f)).translation().y(),
                   pose(static_cast<int>(f)).translation().z()};
    }
    std::vector<std::array<double, 3>> pts(points_.size());
    ceres::Problem::Options popts;
    popts.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    popts.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    ceres::Problem problem(popts);
    ceres::HuberLoss loss(1.0);
    ceres::EigenQuaternionManifold quaternion;
    for (std::size_t k = 0; k < tracks_.size(); ++k) {
      if (!points_[k]) continue;
      pts[k] = {points_[k]->x(), points_[k]->y(), points_[k]->z()};
      for (const auto& [f, uv] : tracks_[k].observations) {
        auto& b = blocks[static_cast<std::size_t>(f)];
        problem.AddResidualBlock(new ceres::AutoDiffCostFunction<ReprojectionCost, 2, 4, 3, 3>(
                                     new ReprojectionCost(uv, o_.focal_px)),
                                 &loss, b.data(), b.data() + 4, pts[k].data());
        problem.SetManifold(b.data(), &quaternion);
      }
    }
    auto& gauge = blocks[static_cast<std::size_t>(ref)];
    if (!problem.HasParameterBlock(gauge.data())) return;
    problem.SetParameterBlockConstant(gauge.data());
    problem.SetParameterBlockConstant(gauge.data() + 4);
    ceres::Solver::Options options;
    options.linear_solver_type = ceres::DENSE_SCHUR;
    options.max_num_iterations = kBundleIterations;
    options.num_threads = 1;
    options.logging_type = ceres::SILENT;
    ceres::Solver::Summary summary;
    ceres::Solve(options, &problem, &summary);
    if (summary.termination_type == ceres::FAILURE) return;
    for (std::size_t f = 0; f < poses_.size(); ++f) {
      const auto& b = blocks[f];
      if (!problem.HasParameterBlock(b.data())) continue;
      Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
      T.linear() = Eigen::Quaterniond(b[3], b[0], b[1], b[2]).normalized().toRotationMatrix();
      T.translation() = Eigen::Vector3d(b[4], b[5], b[6]);
      if (T.matrix().allFinite()) poses_[f] = T;
    }
    for (std::size_t k = 0; k < points_.size(); ++k) {
      if (points_[k]) points_[k] = Eigen::Vector3d(pts[k][0], pts[k][1], pts[k][2]);
    }
    // The scale is free in the adjustment: back to a unit distance from reference to newest.
    const double baseline = pose(n_ - 1).inverse().translation().norm();
    if (!(baseline > 1e-9)) return;
    for (auto& T : poses_) T->translation() /= baseline;
    for (auto& p : points_) {
      if (p) *p /= baseline;
    }
  }

  std::optional<SfmResult> finish(int ref) {
    SfmResult result;
    result.reference = ref;
    double sum_sq = 0.0;
    int count = 0;
    const double limit = kMaxPointErrorPx / o_.focal_px;
    for (std::size_t k = 0; k < tracks_.size(); ++k) {
      if (!points_[k] || !points_[k]->allFinite()) continue;
      double sq = 0.0;
      bool good = true;
      for (const auto& [f, uv] : tracks_[k].observations) {
        if ((pose(f) * *points_[k]).z() <= 0.0) good = false;
        const double e = (project(pose(f), *points_[k]) - uv).norm();
        good = good && e <= limit;
        sq += e * e;
      }
      if (!good) continue;
      sum_sq += sq;
      count += static_cast<int>(tracks_[k].observations.size());
      result.points_v[tracks_[k].id] = *points_[k];
    }
    if (static_cast<int>(result.points_v.size()) < o_.min_common_features / 2) return std::nullopt;
    result.rms_px = std::sqrt(sum_sq / count) * o_.focal_px;
    if (!(result.rms_px <= o_.max_rms_px)) return std::nullopt;
    for (const auto& T : poses_) {
      if (!T || !T->matrix().allFinite()) return std::nullopt;
      result.T_v_c.push_back(T->inverse());
    }
    return result;
  }

  const std::vector<SfmTrack>& tracks_;
  int n_;
  SfmOptions o_;
  std::vector<std::optional<Eigen::Isometry3d>> poses_;  // T_c_v of each frame once located
  std::vector<std::optional<Eigen::Vector3d>> points_;   // per track, visual frame
};

}  // namespace

std::optional<SfmResult> solveMonoSfm(const std::vector<SfmTrack>& tracks, int num_frames,
                                      const SfmOptions& options) {
  if (num_frames < 2 || !(options.focal_px > 0.0)) return std::nullopt;
  for (const SfmTrack& t : tracks) {
    for (const auto& [f, uv] : t.observations) {
      if (f < 0 || f >= num_frames || !uv.allFinite()) return std::nullopt;
    }
  }
  try {
    return Solver(tracks, num_frames, options).run();
  } catch (const cv::Exception&) {
    return std::nullopt;  // OpenCV refuses degenerate input by throwing
  }
}

}  // namespace gvio::odometry
