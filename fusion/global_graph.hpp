#pragma once
// The global pose graph solved after the drive (the smoother grown up, DESIGN.md section 1): one
// node per keyframe, in the run's target frame (local ENU when georeferenced, else the VIO world),
//  - VIO relative-pose factors between consecutive keyframes (RelativeNoise: drift per metre),
//  - GNSS position factors on the antenna with a first-order Gauss-Markov receiver bias per fix
//    (as fusion/gnss_smoother.hpp), Huber-robust,
//  - loop-closure factors (relative pose measured by place recognition, with its covariance),
//  - with an IMU, a tilt factor per node: roll and pitch stay what the IMU observed, so loops and
//    fixes move yaw and position only (4 DoF in effect, as VINS-Mono's pose graph).
// A wrong loop must not corrupt the estimate (OpenVINS ov_secondary's README warns that one does):
// the first round solves with a Cauchy kernel on every loop; then each loop's error against the
// solution is tested (chi-square, 6 DoF) and only those that pass stay active; the graph is solved
// again without robust kernels on the loops, until the active set no longer changes. Each solve
// runs to Ceres' convergence criteria (not a fixed handful of iterations: VINS-Mono issue 30);
// the result says whether it converged.
// Several drives in one graph (gvio merge's joint alignment, issue 18): each node names its
// segment (drive); VIO factors and the receiver bias's Gauss-Markov chain stay within a segment,
// and loops between segments are what ties the drives together.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "fusion/gnss_smoother.hpp"

namespace gvio::fusion {

struct GlobalGraphConfig {
  RelativeNoise vio;          // VIO relative-motion noise between consecutive keyframes
  double huber_sigmas = 2.0;  // robust loss on GNSS residuals, sigmas
  // Gauss-Markov receiver bias (fusion.smoother.*): sigma as a fraction of the fix's reported
  // horizontal sigma (0: no bias state) and correlation time.
  double bias_ratio = 0.5;
  double bias_tau_s = 60.0;
  bool tilt = true;               // tilt factors (only when the VIO had an IMU)
  double tilt_sigma_rad = 0.017;  // their 1 sigma (1 deg)
  // A loop whose error against the solution exceeds this chi-square (6 DoF; 99.9 %: 22.46) is
  // switched off.
  double loop_chi2 = 22.46;
  int max_rounds = 5;        // solve / test rounds before the active set must be stable
  int max_iterations = 200;  // per solve; each stops earlier at Ceres' convergence criteria
  void validate() const;     // throws InvalidInput naming the field
};

struct GraphNode {
  std::int64_t t_ns = 0;
  std::uint32_t segment = 0;  // the drive; nodes are grouped by segment, in increasing order
  Eigen::Isometry3d T_w_b = Eigen::Isometry3d::Identity();   // the VIO pose (relative factors)
  Eigen::Isometry3d T_init = Eigen::Isometry3d::Identity();  // initial estimate, target frame
};

// A GNSS fix attached to node `node`: the antenna sits at q_b in that node's body frame (the lever
// arm carried by the VIO motion from the node's time to the fix's).
struct GraphFix {
  std::size_t node = 0;
  std::int64_t t_ns = 0;
  Eigen::Vector3d q_b = Eigen::Vector3d::Zero();
  Eigen::Vector3d p_enu = Eigen::Vector3d::Zero();
  double sigma_h_m = 1.0, sigma_v_m = 1.0;
  int quality = 1;  // NMEA GGA fix quality: each quality has its own receiver-bias chain
  Eigen::Matrix2d shape_en = Eigen::Matrix2d::Identity();  // the stated ellipse's shape
};

// A loop closure: the relative pose T_i_j = T_i^-1 T_j of two nodes (i older) and the covariance
// of its error in RelativePoseFactor's convention (rotation (rad), then translation in i (m)).
struct GraphLoop {
  std::size_t i = 0, j = 0;
  Eigen::Isometry3d T_i_j = Eigen::Isometry3d::Identity();
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Identity();
};

struct LoopVerdict {
  bool active = false;  // used by the final solution
  double chi2 = 0.0;    // its error against the final solution, e^T Sigma^-1 e
};

struct GlobalGraphResult {
  std::vector<Eigen::Isometry3d> T;  // per node, target frame
  std::vector<LoopVerdict> loops;    // per loop, in the given order
  int rounds = 0;                    // solve / test rounds
  int iterations = 0;                // Ceres iterations over all rounds
  bool converged = false;            // the last solve met Ceres' convergence criteria
  std::string termination;           // Ceres' report of the last solve
  double ms_solve = 0.0;             // wall time of all rounds
};

// Nodes in time order within each segment (>= 1 node); fixes in time order within each segment,
// the segments' fixes in segment order. Fixes anchor the graph; a segment that neither has fixes
// nor is joined by loops to one that has (or to the first segment, when no segment has fixes)
// holds its first node fixed (its gauge). `has_imu` enables the tilt factors (config.tilt
// permitting). Loops whose indices are out of range or equal throw InvalidInput.
GlobalGraphResult solveGlobalGraph(const std::vector<GraphNode>& nodes,
                                   const std::vector<GraphFix>& fixes,
                                   const std::vector<GraphLoop>& loops, bool has_imu,
                                   const GlobalGraphConfig& config);

}  // namespace gvio::fusion
