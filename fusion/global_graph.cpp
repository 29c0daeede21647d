#include "fusion/global_graph.hpp"

#include <array>
#include <chrono>
#include <cmath>
#include <memory>

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

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using PoseBlock = std::array<double, odometry::kPoseAmbient>;

// S with S^T S = Sigma^-1: the inverse of Sigma's Cholesky factor L (Sigma = L L^T).
Matrix6d sqrtInformation(const Matrix6d& covariance) {
  const Eigen::LLT<Matrix6d> llt(covariance);
  if (llt.info() != Eigen::Success || !covariance.allFinite()) {
    throw InvalidInput("global graph: a loop covariance is not positive definite");
  }
  return Matrix6d(llt.matrixL()).inverse();
}

bool sameSegment(const std::vector<GraphNode>& nodes, const GraphFix& a, const GraphFix& b) {
  return nodes[a.node].segment == nodes[b.node].segment;
}

// The first node of each segment that nothing anchors: a segment is anchored by its own fixes,
// or by loops (any chain of them) to an anchored segment; without any fix, the first segment is
// the anchor. Union-find over the segments.
std::vector<std::size_t> gaugeNodes(const std::vector<GraphNode>& nodes,
                                    const std::vector<GraphFix>& fixes,
                                    const std::vector<GraphLoop>& loops) {
  const std::size_t n = nodes.back().segment + 1;
  std::vector<std::size_t> parent(n);
  for (std::size_t s = 0; s < n; ++s) parent[s] = s;
  const auto root = [&](std::size_t s) {
    while (parent[s] != s) s = parent[s] = parent[parent[s]];
    return s;
  };
  for (const GraphLoop& l : loops) parent[root(nodes[l.i].segment)] = root(nodes[l.j].segment);
  std::vector<bool> anchored(n, false);
  for (const GraphFix& f : fixes) anchored[root(nodes[f.node].segment)] = true;
  if (fixes.empty()) anchored[root(nodes.front().segment)] = true;
  std::vector<std::size_t> gauges;
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    const bool first = k == 0 || nodes[k].segment != nodes[k - 1].segment;
    if (!first || anchored[root(nodes[k].segment)]) continue;
    anchored[root(nodes[k].segment)] = true;  // this node anchors its whole component
    gauges.push_back(k);
  }
  if (fixes.empty()) gauges.insert(gauges.begin(), 0);
  return gauges;
}

void checkInputs(const std::vector<GraphNode>& nodes, const std::vector<GraphFix>& fixes,
                 const std::vector<GraphLoop>& loops) {
  if (nodes.empty()) throw InvalidInput("global graph: no nodes");
  for (std::size_t k = 1; k < nodes.size(); ++k) {
    if (nodes[k].segment < nodes[k - 1].segment) {
      throw InvalidInput("global graph: nodes must be grouped by segment in increasing order");
    }
    if (nodes[k].segment == nodes[k - 1].segment && nodes[k].t_ns <= nodes[k - 1].t_ns) {
      throw InvalidInput("global graph: node stamps must increase within a segment");
    }
  }
  for (std::size_t k = 0; k < fixes.size(); ++k) {
    if (fixes[k].node >= nodes.size()) throw InvalidInput("global graph: fix on a missing node");
    if (k > 0 && sameSegment(nodes, fixes[k], fixes[k - 1]) && fixes[k].t_ns < fixes[k - 1].t_ns) {
      throw InvalidInput("global graph: fixes must be in time order");
    }
    if (k > 0 && nodes[fixes[k].node].segment < nodes[fixes[k - 1].node].segment) {
      throw InvalidInput("global graph: fixes must be grouped by segment in increasing order");
    }
    if (!(fixes[k].sigma_h_m > 0.0 && fixes[k].sigma_v_m > 0.0)) {
      throw InvalidInput("global graph: fix sigmas must be > 0");
    }
  }
  for (const GraphLoop& l : loops) {
    if (l.i >= nodes.size() || l.j >= nodes.size() || l.i == l.j) {
      throw InvalidInput("global graph: a loop joins missing or identical nodes");
    }
  }
}

// One graph instance: the parameter blocks (restarted from the initial estimate for each solve,
// so that the final solution depends on the final set of loops alone) and the factors.
class Graph {
 public:
  Graph(const std::vector<GraphNode>& nodes, const std::vector<GraphFix>& fixes,
        const std::vector<GraphLoop>& loops, bool tilt, const GlobalGraphConfig& config)
      : nodes_(nodes), fixes_(fixes), loops_(loops), tilt_(tilt), config_(config) {
    sqrt_info_.reserve(loops.size());
    for (const GraphLoop& l : loops) sqrt_info_.push_back(sqrtInformation(l.covariance));
  }

  // Solves with the loops flagged in `active`, robustly (Cauchy) when `robust`; returns Ceres'
  // summary.
  ceres::Solver::Summary solve(const std::vector<bool>& active, bool robust) {
    poses_.assign(nodes_.size(), PoseBlock{});
    for (std::size_t k = 0; k < nodes_.size(); ++k) {
      odometry::poseToBlock(nodes_[k].T_init, poses_[k].data());
    }
    biases_.assign(fixes_.size(), Eigen::Vector3d::Zero());
    ceres::Problem::Options popts;
    popts.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    popts.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    ceres::Problem problem(popts);
    for (PoseBlock& p : poses_) problem.AddParameterBlock(p.data(), p.size(), &manifold_);
    addOdometry(problem);
    addFixes(problem);
    // The Cauchy scale at the chi-square bound: loops beyond it lose their pull.
    ceres::CauchyLoss cauchy(std::sqrt(config_.loop_chi2));
    for (std::size_t k = 0; k < loops_.size(); ++k) {
      if (!active[k]) continue;
      problem.AddResidualBlock(new RelativePoseFactor(loops_[k].T_i_j, sqrt_info_[k]),
                               robust ? &cauchy : nullptr, poses_[loops_[k].i].data(),
                               poses_[loops_[k].j].data());
    }
    for (std::size_t k : gaugeNodes(nodes_, fixes_, loops_)) {
      problem.SetParameterBlockConstant(poses_[k].data());
    }
    const ceres::Solver::Options options = batchSolverOptions(config_.max_iterations);
    ceres::Solver::Summary summary;
    ceres::Solve(options, &problem, &summary);
    return summary;
  }

  [[nodiscard]] Eigen::Isometry3d pose(std::size_t k) const {
    return odometry::poseFromBlock(poses_[k].data());
  }

  // e^T Sigma^-1 e of loop k at the current solution.
  [[nodiscard]] double chi2(std::size_t k) const {
    const RelativePoseFactor factor(loops_[k].T_i_j, sqrt_info_[k]);
    return (sqrt_info_[k] * factor.error(pose(loops_[k].i), pose(loops_[k].j))).squaredNorm();
  }

 private:
  void addOdometry(ceres::Problem& problem) {
    for (std::size_t k = 0; k < nodes_.size(); ++k) {
      if (tilt_) {
        const Eigen::Vector3d g_b =
            nodes_[k].T_w_b.rotation().transpose() * Eigen::Vector3d::UnitZ();
        problem.AddResidualBlock(new TiltFactor(g_b, config_.tilt_sigma_rad), nullptr,
                                 poses_[k].data());
      }
      if (k == 0 || nodes_[k].segment != nodes_[k - 1].segment) continue;
      const Eigen::Isometry3d T_rel = nodes_[k - 1].T_w_b.inverse() * nodes_[k].T_w_b;
      const double d = T_rel.translation().norm();
      problem.AddResidualBlock(new RelativePoseFactor(T_rel, config_.vio.rotationSigmaRad(d),
                                                      config_.vio.positionSigmaM(d)),
                               nullptr, poses_[k - 1].data(), poses_[k].data());
    }
  }

  void addFixes(ceres::Problem& problem) {
    const bool with_bias = config_.bias_ratio > 0.0;
    ReceiverBiasChains chains(config_.bias_tau_s);
    for (std::size_t k = 0; k < fixes_.size(); ++k) {
      const GraphFix& f = fixes_[k];
      double* pose = poses_[f.node].data();
      const Eigen::Matrix3d W = gnssSqrtInformation(f.sigma_h_m, f.sigma_v_m, f.shape_en);
      if (!with_bias) {
        problem.AddResidualBlock(new GnssPositionFactor(f.q_b, f.p_enu, W), &huber_, pose);
        continue;
      }
      problem.AddResidualBlock(new GnssBiasedPositionFactor(f.q_b, f.p_enu, W), &huber_, pose,
                               biases_[k].data());
      // One bias chain per drive and fix quality (ReceiverBiasChains): each drive has its own
      // receiver (or its own day).
      if (k > 0 && nodes_[f.node].segment != nodes_[fixes_[k - 1].node].segment) chains.restart();
      chains.add(problem, f.quality, f.t_ns, config_.bias_ratio * f.sigma_h_m, f.shape_en,
                 biases_[k].data());
    }
  }

  const std::vector<GraphNode>& nodes_;
  const std::vector<GraphFix>& fixes_;
  const std::vector<GraphLoop>& loops_;
  bool tilt_;
  const GlobalGraphConfig& config_;
  std::vector<Matrix6d> sqrt_info_;
  std::vector<PoseBlock> poses_;
  std::vector<Eigen::Vector3d> biases_;
  odometry::PoseManifold manifold_;
  ceres::HuberLoss huber_{config_.huber_sigmas};
};

}  // namespace

void GlobalGraphConfig::validate() const {
  const auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  if (!positive(huber_sigmas)) throw InvalidInput("config: fusion.huber_sigmas must be > 0");
  if (!(std::isfinite(bias_ratio) && bias_ratio >= 0.0)) {
    throw InvalidInput("config: fusion.smoother.bias_ratio must be >= 0");
  }
  if (!positive(bias_tau_s)) throw InvalidInput("config: fusion.smoother.bias_tau_s must be > 0");
  if (!positive(tilt_sigma_rad)) {
    throw InvalidInput("config: loops.graph_tilt_sigma_deg must be > 0");
  }
  if (!positive(loop_chi2)) throw InvalidInput("config: loops.graph_chi2 must be > 0");
  if (max_rounds < 1) throw InvalidInput("config: loops.graph_max_rounds must be >= 1");
  if (max_iterations < 1) throw InvalidInput("config: loops.graph_max_iterations must be >= 1");
}

GlobalGraphResult solveGlobalGraph(const std::vector<GraphNode>& nodes,
                                   const std::vector<GraphFix>& fixes,
                                   const std::vector<GraphLoop>& loops, bool has_imu,
                                   const GlobalGraphConfig& config) {
  config.validate();
  checkInputs(nodes, fixes, loops);
  const auto start = std::chrono::steady_clock::now();
  Graph graph(nodes, fixes, loops, has_imu && config.tilt, config);
  GlobalGraphResult result;
  std::vector<bool> active(loops.size(), true);
  bool robust = !loops.empty();
  ceres::Solver::Summary summary;
  for (int round = 1; round <= config.max_rounds; ++round) {
    summary = graph.solve(active, robust);
    result.rounds = round;
    result.iterations += static_cast<int>(summary.iterations.size());
    std::vector<bool> passing(loops.size());
    for (std::size_t k = 0; k < loops.size(); ++k) passing[k] = graph.chi2(k) <= config.loop_chi2;
    // Done once a plain (non-robust) solve leaves exactly its own loops passing.
    if (!robust && passing == active) break;
    if (round == config.max_rounds) break;  // the last solve's set stands
    robust = false;
    active = passing;
  }
  result.T.reserve(nodes.size());
  for (std::size_t k = 0; k < nodes.size(); ++k) result.T.push_back(graph.pose(k));
  result.loops.reserve(loops.size());
  for (std::size_t k = 0; k < loops.size(); ++k) result.loops.push_back({active[k], graph.chi2(k)});
  result.converged = summary.termination_type == ceres::CONVERGENCE;
  result.termination = summary.message;
  result.ms_solve =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace gvio::fusion
