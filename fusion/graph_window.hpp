#pragma once
// The global fusion's bounded graph ("graph" mode, ours): nodes are body poses in ENU at GNSS fix
// times, linked by VIO relative-pose factors and anchored by GNSS position factors (robust loss);
// the oldest node is marginalised into a prior (odometry::Marginalizer) so the cost per fix stays
// flat however long the drive.
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <deque>
#include <memory>
#include <vector>

#include <ceres/context.h>
#include <ceres/cost_function.h>
#include <ceres/loss_function.h>

#include "odometry/marginalization.hpp"
#include "odometry/pose_manifold.hpp"

namespace gvio::fusion {

struct GraphNode {
  std::int64_t t_ns = 0;
  std::array<double, 7> pose{0, 0, 0, 1, 0, 0, 0};          // T_enu_b (PoseManifold layout)
  Eigen::Isometry3d T_w_b = Eigen::Isometry3d::Identity();  // the VIO pose at this time
  // Factors attached to this node that involve only it and its predecessor (the relative factor)
  // or only it (GNSS): folded into the prior when the node leaves.
  std::vector<std::shared_ptr<ceres::CostFunction>> unary;
  // Unary factors without the robust loss: priors the node carries from the VIO (its tilt) or from
  // the registration (the first node's heading), which are never outliers.
  std::vector<std::shared_ptr<ceres::CostFunction>> exact;
  std::shared_ptr<ceres::CostFunction> relative;  // to the previous node (null for the first)
  [[nodiscard]] Eigen::Isometry3d T_enu_b() const { return odometry::poseFromBlock(pose.data()); }
};

class GraphWindow {
 public:
  GraphWindow(int max_nodes, double huber_sigmas, int max_iterations);

  // Appends a node at T_enu_b (initial guess) with the relative factor to the previous node.
  GraphNode& addNode(std::int64_t t_ns, const Eigen::Isometry3d& T_enu_b,
                     const Eigen::Isometry3d& T_w_b, std::shared_ptr<ceres::CostFunction> relative);
  void addGnssFactor(GraphNode& node, std::shared_ptr<ceres::CostFunction> factor);
  // A unary factor without the robust loss (GraphNode::exact).
  void addPrior(GraphNode& node, std::shared_ptr<ceres::CostFunction> factor);
  // Solves the window, then marginalises nodes beyond max_nodes.
  void solve();

  [[nodiscard]] bool empty() const { return nodes_.empty(); }
  [[nodiscard]] const GraphNode& newest() const { return *nodes_.back(); }
  GraphNode& newest() { return *nodes_.back(); }
  [[nodiscard]] std::size_t size() const { return nodes_.size(); }

 private:
  void marginalizeOldest();

  int max_nodes_;
  int max_iterations_;
  odometry::PoseManifold manifold_;
  std::shared_ptr<ceres::LossFunction> loss_;
  std::shared_ptr<ceres::Context> context_;
  std::deque<std::unique_ptr<GraphNode>> nodes_;
  std::shared_ptr<const odometry::MarginalizationPrior> prior_;
};

}  // namespace gvio::fusion
