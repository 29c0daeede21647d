#pragma once
// GnssFusion's state and steps, shared by its translation units (gnss_fusion.cpp: the filters and
// the public interface; gnss_fusion_registration.cpp: the first registration of the VIO world to
// ENU). Private to fusion/: included from nowhere else.
#include <Eigen/Geometry>
#include <cstdint>
#include <deque>
#include <optional>
#include <vector>

#include "fusion/gnss_fusion.hpp"
#include "fusion/gnss_smoother.hpp"
#include "fusion/graph_window.hpp"
#include "fusion/kf_baseline.hpp"
#include "fusion/online_sigma_scale.hpp"

namespace gvio::fusion {

// Solver iterations per fix in graph mode (the window is small and warm-started).
inline constexpr int kGraphIterations = 5;
// Sigmas that leave a prior's component free.
inline constexpr double kFreeRad = 10.0;
inline constexpr double kFreePositionM = 1e4;

struct GnssFusion::Impl {
  struct Pair {
    std::int64_t t_ns;
    Eigen::Isometry3d T_w_b;
    Eigen::Vector3d p_enu;
    GnssFix fix;
  };

  Impl(const FusionConfig& c, const EnuFrame& e)
      : config(c), enu(e), graph(c.window_nodes, c.huber_sigmas, kGraphIterations), kf(c.kf) {}

  void processFix(const GnssFix& fix);
  void align(const Pair& pair);
  [[nodiscard]] bool residualsConsistent(const Eigen::Isometry3d& T_enu_w,
                                         const std::vector<bool>& use) const;
  [[nodiscard]] std::optional<Eigen::Isometry3d> registration(const std::vector<bool>& use) const;
  [[nodiscard]] std::optional<std::vector<bool>> registrationPairs(
      const Eigen::Isometry3d& T_ls) const;
  bool fuseGraph(const Pair& pair);
  void addNodePriors(GraphNode& node, bool first);
  void setRegistrationAngleSigmas(const std::vector<bool>& use);
  bool fuseKf(const Pair& pair);
  Eigen::Isometry3d fusedPose(std::int64_t t_ns, const Eigen::Isometry3d& T_w_b) const;
  void noteAccepted(std::int64_t t_ns);
  void noteOutcome(const Pair& pair, bool used);
  void noteGraphNode(const Pair& pair);
  void smooth();

  FusionConfig config;
  EnuFrame enu;
  Trajectory vio, fused, smoothed;
  std::vector<PoseCovariance> smoothed_covariance;
  std::vector<SmootherFix> graph_fixes;  // every fix the graph used, for the smoothing pass
  std::deque<GnssFix> pending;
  std::vector<Pair> alignment_pairs;
  std::optional<Eigen::Isometry3d> T_enu_w;
  double registration_yaw_sigma_rad = 0.0;   // how well the registration's fixes fix the heading
  double registration_tilt_sigma_rad = 0.0;  // ... and the tilt (used without an IMU)
  GraphWindow graph;
  KfBaseline kf;
  OnlineSigmaScale kf_noise;
  std::int64_t kf_t_ns = 0;
  std::optional<Pair> previous_fix;  // KF: finite-difference GNSS velocity
  int consecutive_rejections = 0;
  std::optional<std::int64_t> last_accepted_ns;
  FusionStats stats;
};

}  // namespace gvio::fusion
