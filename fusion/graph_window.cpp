#include "fusion/graph_window.hpp"

#include <ceres/problem.h>
#include <ceres/solver.h>

namespace gvio::fusion {

GraphWindow::GraphWindow(int max_nodes, double huber_sigmas, int max_iterations)
    : max_nodes_(max_nodes),
      max_iterations_(max_iterations),
      loss_(std::make_shared<ceres::HuberLoss>(huber_sigmas)),
      context_(ceres::Context::Create()) {}

GraphNode& GraphWindow::addNode(std::int64_t t_ns, const Eigen::Isometry3d& T_enu_b,
                                const Eigen::Isometry3d& T_w_b,
                                std::shared_ptr<ceres::CostFunction> relative) {
  auto node = std::make_unique<GraphNode>();
  node->t_ns = t_ns;
  odometry::poseToBlock(T_enu_b, node->pose.data());
  node->T_w_b = T_w_b;
  if (!nodes_.empty()) node->relative = std::move(relative);
  nodes_.push_back(std::move(node));
  return *nodes_.back();
}

void GraphWindow::addGnssFactor(GraphNode& node, std::shared_ptr<ceres::CostFunction> factor) {
  node.unary.push_back(std::move(factor));
}

void GraphWindow::addPrior(GraphNode& node, std::shared_ptr<ceres::CostFunction> factor) {
  node.exact.push_back(std::move(factor));
}

void GraphWindow::solve() {
  if (nodes_.empty()) return;
  ceres::Problem::Options popts;
  popts.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  popts.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  popts.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  popts.context = context_.get();
  ceres::Problem problem(popts);
  std::shared_ptr<ceres::CostFunction> prior_factor;
  for (std::size_t k = 0; k < nodes_.size(); ++k) {
    GraphNode& n = *nodes_[k];
    problem.AddParameterBlock(n.pose.data(), odometry::kPoseAmbient, &manifold_);
    for (const auto& f : n.unary) problem.AddResidualBlock(f.get(), loss_.get(), n.pose.data());
    for (const auto& f : n.exact) problem.AddResidualBlock(f.get(), nullptr, n.pose.data());
    if (k > 0 && n.relative) {
      problem.AddResidualBlock(n.relative.get(), nullptr, nodes_[k - 1]->pose.data(),
                               n.pose.data());
    }
  }
  if (prior_) {
    prior_factor = std::make_shared<odometry::MarginalizationFactor>(prior_);
    problem.AddResidualBlock(prior_factor.get(), nullptr, prior_->blockAddresses());
  }
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
  options.max_num_iterations = max_iterations_;
  options.num_threads = 1;
  options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  while (static_cast<int>(nodes_.size()) > max_nodes_) marginalizeOldest();
}

void GraphWindow::marginalizeOldest() {
  GraphNode& oldest = *nodes_.front();
  GraphNode& next = *nodes_[1];
  odometry::Marginalizer m;
  for (const auto& n : nodes_) m.setManifold(n->pose.data(), &manifold_);
  bool named = false;
  if (prior_) {
    m.addResidualBlock(std::make_shared<odometry::MarginalizationFactor>(prior_), nullptr,
                       prior_->blockAddresses());
    named = prior_->blockIndex(oldest.pose.data()) >= 0;
  }
  for (const auto& f : oldest.unary) {
    m.addResidualBlock(f, loss_, {oldest.pose.data()});
    named = true;
  }
  for (const auto& f : oldest.exact) {
    m.addResidualBlock(f, nullptr, {oldest.pose.data()});
    named = true;
  }
  if (next.relative) {
    m.addResidualBlock(next.relative, nullptr, {oldest.pose.data(), next.pose.data()});
    next.relative.reset();
    named = true;
  }
  if (named) m.markForRemoval(oldest.pose.data());
  try {
    prior_ = named || prior_ ? m.marginalize() : nullptr;
  } catch (const std::exception&) {
    prior_.reset();  // a degenerate linearisation costs the prior, never the run
  }
  nodes_.pop_front();
}

}  // namespace gvio::fusion
