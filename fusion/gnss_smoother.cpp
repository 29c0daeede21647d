#include "fusion/gnss_smoother.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <memory>
#include <string>

#include <ceres/covariance.h>
#include <ceres/loss_function.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include "fusion/batch_solver.hpp"
#include "fusion/gnss_covariance.hpp"
#include "fusion/gnss_factors.hpp"
#include "odometry/error.hpp"
#include "odometry/pose_manifold.hpp"

namespace gvio::fusion {
namespace {

// Marginal covariances of the node poses, rotated from the manifold's body-frame tangent
// (dphi, dp_body) to ENU axes: dtheta = R dphi, dp = R dp_body.
std::vector<PoseCovariance> nodeCovariances(ceres::Problem& problem,
                                            const std::vector<double*>& poses) {
  ceres::Covariance::Options options;
  options.num_threads = 1;
  ceres::Covariance covariance(options);
  std::vector<std::pair<const double*, const double*>> blocks;
  for (const double* p : poses) blocks.emplace_back(p, p);
  if (!covariance.Compute(blocks, &problem)) return {};
  std::vector<PoseCovariance> out;
  out.reserve(poses.size());
  for (const double* p : poses) {
    Eigen::Matrix<double, 6, 6, Eigen::RowMajor> tangent;
    if (!covariance.GetCovarianceBlockInTangentSpace(p, p, tangent.data())) return {};
    const Eigen::Matrix3d R = odometry::poseFromBlock(p).rotation();
    Eigen::Matrix<double, 6, 6> J = Eigen::Matrix<double, 6, 6>::Zero();
    J.topLeftCorner<3, 3>() = R;
    J.bottomRightCorner<3, 3>() = R;
    out.push_back(J * tangent * J.transpose());
  }
  return out;
}

}  // namespace

void SmootherConfig::validate() const {
  if (!(std::isfinite(bias_ratio) && bias_ratio >= 0.0)) {
    throw InvalidInput("config: fusion.smoother.bias_ratio must be >= 0");
  }
  if (!(std::isfinite(bias_tau_s) && bias_tau_s > 0.0)) {
    throw InvalidInput("config: fusion.smoother.bias_tau_s must be > 0");
  }
  if (max_iterations < 1) throw InvalidInput("config: fusion.smoother.max_iterations must be >= 1");
  if (min_fixes_to_learn < 2) {
    throw InvalidInput("config: fusion.smoother.min_fixes_to_learn must be >= 2");
  }
  if (!(std::isfinite(outlier_chi2) && outlier_chi2 > 0.0)) {
    throw InvalidInput("config: fusion.smoother.outlier_chi2 must be > 0");
  }
  if (!(std::isfinite(min_learned_scale) && min_learned_scale > 0.0)) {
    throw InvalidInput("config: fusion.smoother.min_learned_scale must be > 0");
  }
  if (max_rounds < 1) throw InvalidInput("config: fusion.smoother.max_rounds must be >= 1");
}

namespace {

// What every solve of one smoothing pass shares.
struct SmootherProblem {
  const std::vector<SmootherFix>& fixes;
  const Eigen::Vector3d& lever_arm_b;
  const RelativeNoise& noise;
  double huber_sigmas;
  const SmootherConfig& config;
  double tilt_sigma_rad;
};

// One batch solve over the fixes with use[k], their sigmas scaled; the whitened residual of
// every fix (used or not) against the solution, in the scaled sigmas; the nodes' covariances
// only when asked (they cost more than the solve, and only the last solve's are reported).
struct SmootherSolve {
  SmoothedNodes nodes;
  std::vector<Eigen::Vector3d> residual;
  bool with_covariance = false;
};

SmootherSolve solveOnce(const SmootherProblem& in, const std::vector<bool>& use,
                        const std::vector<Eigen::Vector2d>& scale, bool with_covariance) {
  const std::vector<SmootherFix>& fixes = in.fixes;
  const Eigen::Vector3d& lever_arm_b = in.lever_arm_b;
  const SmootherConfig& config = in.config;
  const std::size_t n = fixes.size();
  // Every parameter block in one buffer, poses then biases: ceres::Covariance orders the blocks
  // by address, and two separate allocations came in either order from run to run (measured: the
  // sigmas' last digits differed in one run of a few).
  std::vector<double> storage(n * (odometry::kPoseAmbient + 3), 0.0);
  std::vector<double*> poses(n), biases(n);
  for (std::size_t k = 0; k < n; ++k) {
    poses[k] = storage.data() + k * odometry::kPoseAmbient;
    biases[k] = storage.data() + n * odometry::kPoseAmbient + 3 * k;
  }
  const bool with_bias = config.bias_ratio > 0.0;
  odometry::PoseManifold manifold;
  ceres::HuberLoss loss(in.huber_sigmas);
  ceres::Problem::Options popts;
  popts.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  popts.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(popts);
  // Each fix's factor: owned by the problem when used, else by `left_out` (its residual is still
  // evaluated against the solution).
  std::vector<ceres::CostFunction*> fix_factors(n, nullptr);
  std::vector<std::unique_ptr<ceres::CostFunction>> left_out;
  for (std::size_t k = 0; k < n; ++k) {
    const SmootherFix& f = fixes[k];
    const double sigma_h = f.sigma_h_m * scale[k].x(), sigma_v = f.sigma_v_m * scale[k].y();
    odometry::poseToBlock(f.T_enu_b, poses[k]);
    problem.AddParameterBlock(poses[k], odometry::kPoseAmbient, &manifold);
    if (with_bias) problem.AddParameterBlock(biases[k], 3);
    if (in.tilt_sigma_rad > 0.0) {
      const Eigen::Vector3d g_b = f.T_w_b.rotation().transpose() * Eigen::Vector3d::UnitZ();
      problem.AddResidualBlock(new TiltFactor(g_b, in.tilt_sigma_rad), nullptr, poses[k]);
    }
    const Eigen::Matrix3d W = gnssSqrtInformation(sigma_h, sigma_v, f.shape_en);
    if (with_bias) {
      fix_factors[k] = new GnssBiasedPositionFactor(lever_arm_b, f.p_enu, W);
    } else {
      fix_factors[k] = new GnssPositionFactor(lever_arm_b, f.p_enu, W);
    }
    if (use[k]) {
      std::vector<double*> blocks = {poses[k]};
      if (with_bias) blocks.push_back(biases[k]);
      problem.AddResidualBlock(fix_factors[k], &loss, blocks);
    } else {
      left_out.emplace_back(fix_factors[k]);
    }
    if (k == 0) continue;
    const Eigen::Isometry3d T_rel = fixes[k - 1].T_w_b.inverse() * f.T_w_b;
    const double dist = T_rel.translation().norm();
    problem.AddResidualBlock(new RelativePoseFactor(T_rel, in.noise.rotationSigmaRad(dist),
                                                    in.noise.positionSigmaM(dist)),
                             nullptr, poses[k - 1], poses[k]);
  }
  // The receiver's bias: one Gauss-Markov chain per fix quality (ReceiverBiasChains).
  ReceiverBiasChains chains(config.bias_tau_s);
  for (std::size_t k = 0; with_bias && k < n; ++k) {
    chains.add(problem, fixes[k].quality, fixes[k].t_ns,
               config.bias_ratio * fixes[k].sigma_h_m * scale[k].x(), fixes[k].shape_en, biases[k]);
  }
  const ceres::Solver::Options options = batchSolverOptions(config.max_iterations);
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  SmootherSolve out;
  out.nodes.T_enu_b.reserve(n);
  for (const double* p : poses) out.nodes.T_enu_b.push_back(odometry::poseFromBlock(p));
  if (with_covariance) out.nodes.covariance = nodeCovariances(problem, poses);
  out.with_covariance = with_covariance;
  out.residual.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    const double* blocks[2] = {poses[k], biases[k]};
    fix_factors[k]->Evaluate(blocks, out.residual[k].data(), nullptr);
  }
  return out;
}

double robustSpread(std::vector<double> values) {
  if (values.empty()) return 1.0;
  const auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), mid, values.end());
  return 1.4826 * *mid;
}

// The robust spread (1.4826 MAD about zero) of the used fixes' whitened residuals, horizontal
// (east and north) and vertical, over the fixes `in_group` selects.
template <typename InGroup>
Eigen::Vector2d residualSpread(const SmootherSolve& solve, const std::vector<bool>& use,
                               InGroup in_group) {
  std::vector<double> h, v;
  for (std::size_t k = 0; k < use.size(); ++k) {
    if (!use[k] || !in_group(k)) continue;
    h.push_back(std::abs(solve.residual[k].x()));
    h.push_back(std::abs(solve.residual[k].y()));
    v.push_back(std::abs(solve.residual[k].z()));
  }
  return {robustSpread(h), robustSpread(v)};
}

}  // namespace

SmoothedNodes smoothNodes(const std::vector<SmootherFix>& fixes, const Eigen::Vector3d& lever_arm_b,
                          const RelativeNoise& noise, double huber_sigmas,
                          const SmootherConfig& config, double tilt_sigma_rad) {
  const SmootherProblem problem{fixes, lever_arm_b, noise, huber_sigmas, config, tilt_sigma_rad};
  const std::size_t n = fixes.size();
  std::vector<bool> use(n, true);
  std::vector<Eigen::Vector2d> scale(n, Eigen::Vector2d::Ones());
  std::map<int, Eigen::Vector2d> quality_scale;
  for (const SmootherFix& f : fixes) quality_scale.emplace(f.quality, Eigen::Vector2d::Ones());
  SmootherSolve solve;
  for (int round = 0;; ++round) {
    const auto used = static_cast<int>(std::count(use.begin(), use.end(), true));
    const bool last =
        !config.learn_noise || round + 1 >= config.max_rounds || used < config.min_fixes_to_learn;
    solve = solveOnce(problem, use, scale, last);
    if (last) break;
    // Each quality's spread, or every fix's where a quality has too few to tell.
    const Eigen::Vector2d pooled = residualSpread(solve, use, [](std::size_t) { return true; });
    std::map<int, Eigen::Vector2d> spread;
    for (const auto& entry : quality_scale) {
      const int quality = entry.first;  // a variable, not a binding: lambdas capture it in C++17
      const auto of_quality = [&](std::size_t k) { return fixes[k].quality == quality; };
      int count = 0;
      for (std::size_t k = 0; k < n; ++k) count += use[k] && of_quality(k) ? 1 : 0;
      spread[quality] =
          count >= config.min_fixes_to_learn ? residualSpread(solve, use, of_quality) : pooled;
    }
    const std::vector<bool> solved_with = use;
    bool changed = false;
    for (std::size_t k = 0; k < n; ++k) {
      const Eigen::Vector2d detect = spread[fixes[k].quality].cwiseMax(config.min_learned_scale);
      const Eigen::Vector3d& r = solve.residual[k];
      const double d2 = (r.x() * r.x() + r.y() * r.y()) / (detect.x() * detect.x()) +
                        r.z() * r.z() / (detect.y() * detect.y());
      const bool inlier = d2 <= config.outlier_chi2;
      if (inlier != use[k]) changed = true;
      use[k] = inlier;
    }
    if (std::count(use.begin(), use.end(), true) < 2) {  // nothing left to smooth with
      use = solved_with;
      break;
    }
    bool rescaled = false;
    for (auto& [quality, s] : quality_scale) {
      const Eigen::Vector2d next = s.cwiseProduct(spread[quality].cwiseMax(1.0));
      rescaled = rescaled || next != s;
      s = next;
    }
    if (!changed && !rescaled) break;
    for (std::size_t k = 0; k < n; ++k) scale[k] = quality_scale[fixes[k].quality];
  }
  // Learning settled (or found too few fixes to go on) before the last round: the same solve
  // again, for its covariances.
  if (!solve.with_covariance) solve = solveOnce(problem, use, scale, true);
  SmoothedNodes out = std::move(solve.nodes);
  out.outlier.resize(n);
  for (std::size_t k = 0; k < n; ++k) out.outlier[k] = !use[k];
  out.sigma_scale = quality_scale;
  return out;
}

Trajectory spreadOverVio(const Trajectory& vio, const std::vector<SmootherFix>& nodes,
                         const SmoothedNodes& smoothed_nodes, const RelativeNoise& noise,
                         std::vector<PoseCovariance>* covariance_out) {
  Trajectory out;
  const std::vector<Eigen::Isometry3d>& smoothed = smoothed_nodes.T_enu_b;
  const std::size_t n = nodes.size();
  if (n == 0 || smoothed.size() != n) return out;
  const bool with_covariance = covariance_out != nullptr && smoothed_nodes.covariance.size() == n;
  if (covariance_out != nullptr) covariance_out->clear();
  // The VIO's drift between a node and the pose, as the relative factors model it.
  const auto drift = [&](std::size_t j, std::size_t k) {
    const double d = (nodes[j].T_w_b.translation() - vio.poses[k].translation()).norm();
    const double s_rot = noise.rotationSigmaRad(d);
    const double s_pos = noise.positionSigmaM(d);
    PoseCovariance q = PoseCovariance::Zero();
    q.diagonal() << s_rot * s_rot, s_rot * s_rot, s_rot * s_rot, s_pos * s_pos, s_pos * s_pos,
        s_pos * s_pos;
    return q;
  };
  out.t_ns = vio.t_ns;
  out.poses.reserve(vio.size());
  std::size_t i = 0;  // the last node at or before the pose (or the first node)
  for (std::size_t k = 0; k < vio.size(); ++k) {
    const std::int64_t t = vio.t_ns[k];
    while (i + 1 < n && nodes[i + 1].t_ns <= t) ++i;
    const auto carried = [&](std::size_t j) {
      return Eigen::Isometry3d(smoothed[j] * nodes[j].T_w_b.inverse() * vio.poses[k]);
    };
    if (t <= nodes[0].t_ns || i + 1 >= n) {
      const std::size_t j = t <= nodes[0].t_ns ? 0 : n - 1;
      out.poses.push_back(carried(j));
      if (with_covariance) covariance_out->push_back(smoothed_nodes.covariance[j] + drift(j, k));
      continue;
    }
    const Eigen::Isometry3d A = carried(i), B = carried(i + 1);
    const double alpha = static_cast<double>(t - nodes[i].t_ns) /
                         static_cast<double>(nodes[i + 1].t_ns - nodes[i].t_ns);
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::Quaterniond(A.rotation())
                     .slerp(alpha, Eigen::Quaterniond(B.rotation()))
                     .toRotationMatrix();
    T.translation() = (1.0 - alpha) * A.translation() + alpha * B.translation();
    out.poses.push_back(T);
    if (with_covariance) {
      const std::size_t nearer = alpha < 0.5 ? i : i + 1;
      covariance_out->push_back((1.0 - alpha) * smoothed_nodes.covariance[i] +
                                alpha * smoothed_nodes.covariance[i + 1] + drift(nearer, k));
    }
  }
  return out;
}

}  // namespace gvio::fusion
