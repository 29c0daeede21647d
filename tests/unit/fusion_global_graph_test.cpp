// The global pose graph (fusion/global_graph.hpp): its new factors' Jacobians against central
// differences, loops pulling a drifting VIO back onto the truth, a wrong loop switched off, GNSS
// fixes with a receiver bias, and bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <iostream>
#include <numbers>
#include <random>

#include "fusion/global_graph.hpp"
#include "fusion/gnss_factors.hpp"
#include "odometry/error.hpp"
#include "odometry/lie.hpp"
#include "odometry/pose_manifold.hpp"
#include "support/ceres_jacobian.hpp"

namespace gvio::fusion {
namespace {

using test::analyticTangentJacobian;
using test::numericTangentJacobian;
using test::poseBlock;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

TEST(RelativePoseFactor, FullSquareRootInformationWhitensAndJacobians) {
  std::vector<std::vector<double>> blocks = {
      poseBlock(Eigen::Vector3d(0.1, -0.2, 1.3), Eigen::Vector3d(10, -5, 2)),
      poseBlock(Eigen::Vector3d(0.05, 0.1, 1.6), Eigen::Vector3d(14, -2, 2.5))};
  const Eigen::Isometry3d T_i = odometry::poseFromBlock(blocks[0].data());
  const Eigen::Isometry3d T_j = odometry::poseFromBlock(blocks[1].data());
  Eigen::Isometry3d measured = T_i.inverse() * T_j;
  measured.translation() += Eigen::Vector3d(0.3, -0.1, 0.2);
  measured.linear() = measured.linear() * odometry::expSo3(Eigen::Vector3d(0.02, 0.05, -0.03));
  Matrix6d S = Matrix6d::Identity() * 3.0;
  S(4, 1) = 1.5;
  S(5, 3) = -2.0;  // lower triangular, correlated
  const RelativePoseFactor factor(measured, S);
  const double* params[] = {blocks[0].data(), blocks[1].data()};
  Eigen::Matrix<double, 6, 1> r;
  ASSERT_TRUE(factor.Evaluate(params, r.data(), nullptr));
  EXPECT_LT((r - S * factor.error(T_i, T_j)).norm(), 1e-12);
  EXPECT_GT(factor.error(T_i, T_j).norm(), 0.1);
  for (std::size_t b = 0; b < 2; ++b) {
    const auto num = numericTangentJacobian<6>(factor, blocks, b, true);
    const auto ana = analyticTangentJacobian<6>(factor, blocks, b, true);
    EXPECT_LT((num - ana).norm(), 1e-5 * std::max(1.0, ana.norm())) << "block " << b;
  }
}

TEST(TiltFactor, ZeroAtTheObservedGravityFreeInYawAndJacobian) {
  std::vector<std::vector<double>> blocks = {
      poseBlock(Eigen::Vector3d(0.05, -0.08, 2.0), Eigen::Vector3d(3, 4, 5))};
  const Eigen::Isometry3d T = odometry::poseFromBlock(blocks[0].data());
  const Eigen::Vector3d g_b = T.rotation().transpose() * Eigen::Vector3d::UnitZ();
  const TiltFactor exact(g_b, 0.01);
  const double* params[] = {blocks[0].data()};
  Eigen::Vector3d r;
  ASSERT_TRUE(exact.Evaluate(params, r.data(), nullptr));
  EXPECT_LT(r.norm(), 1e-12);
  // A yaw change leaves it at zero; a roll does not.
  for (const auto& [axis, zero] :
       {std::pair{Eigen::Vector3d::UnitZ(), true}, std::pair{Eigen::Vector3d::UnitX(), false}}) {
    Eigen::Isometry3d moved = T;
    moved.linear() = Eigen::AngleAxisd(0.3, axis).toRotationMatrix() * T.rotation();
    std::vector<double> block(7);
    odometry::poseToBlock(moved, block.data());
    const double* p[] = {block.data()};
    ASSERT_TRUE(exact.Evaluate(p, r.data(), nullptr));
    EXPECT_EQ(r.norm() < 1e-9, zero) << axis.transpose();
  }
  const TiltFactor off(Eigen::Vector3d(0.1, -0.05, 1.0), 0.01);
  const auto num = numericTangentJacobian<3>(off, blocks, 0, true);
  const auto ana = analyticTangentJacobian<3>(off, blocks, 0, true);
  EXPECT_LT((num - ana).norm(), 1e-5 * std::max(1.0, ana.norm()));
}

// Two laps of a 60 m radius circle, a node every 2 m; the VIO drifts in yaw (0.02 deg/m) and scale
// (+0.5 %) with a little noise; loops from the second lap onto the first are the true relative
// poses with 2 cm / 0.05 deg noise.
struct LoopWorld {
  std::vector<Eigen::Isometry3d> truth;
  std::vector<GraphNode> nodes;
  std::vector<GraphLoop> loops;
  std::size_t per_lap = 0;
};

LoopWorld makeLoopWorld() {
  LoopWorld w;
  constexpr double kRadius = 60.0, kStep = 2.0;
  w.per_lap = static_cast<std::size_t>(std::round(2.0 * std::numbers::pi * kRadius / kStep));
  const std::size_t n = 2 * w.per_lap + 1;
  std::mt19937_64 rng(11);
  std::normal_distribution<double> n01(0.0, 1.0);
  for (std::size_t k = 0; k < n; ++k) {
    const double a = kStep * static_cast<double>(k) / kRadius;
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    T.translation() = Eigen::Vector3d(kRadius * std::sin(a), kRadius * (1.0 - std::cos(a)), 0.0);
    w.truth.push_back(T);
  }
  Eigen::Isometry3d vio = w.truth[0];
  for (std::size_t k = 0; k < n; ++k) {
    if (k > 0) {
      Eigen::Isometry3d step = w.truth[k - 1].inverse() * w.truth[k];
      step.translation() *= 1.005;
      step.translation() += 0.01 * Eigen::Vector3d{n01(rng), n01(rng), n01(rng)};
      step.linear() = step.linear() * Eigen::AngleAxisd(0.02 * std::numbers::pi / 180.0 * kStep,
                                                        Eigen::Vector3d::UnitZ())
                                          .toRotationMatrix();
      vio = vio * step;
    }
    GraphNode node;
    node.t_ns = static_cast<std::int64_t>(k) * 200'000'000;  // 10 m/s
    node.T_w_b = vio;
    node.T_init = vio;
    w.nodes.push_back(node);
  }
  for (std::size_t j = w.per_lap + 20; j < n; j += 5) {
    const std::size_t i = j - w.per_lap;
    GraphLoop loop;
    loop.i = i;
    loop.j = j;
    loop.T_i_j = w.truth[i].inverse() * w.truth[j];
    loop.T_i_j.translation() += 0.02 * Eigen::Vector3d{n01(rng), n01(rng), n01(rng)};
    const double s_rot = 0.05 * std::numbers::pi / 180.0, s_pos = 0.02;
    loop.covariance.diagonal() << s_rot * s_rot, s_rot * s_rot, s_rot * s_rot, s_pos * s_pos,
        s_pos * s_pos, s_pos * s_pos;
    w.loops.push_back(loop);
  }
  return w;
}

double rmse(const std::vector<Eigen::Isometry3d>& truth, const std::vector<Eigen::Isometry3d>& T) {
  double sum = 0.0;
  for (std::size_t k = 0; k < truth.size(); ++k) {
    sum += (truth[k].translation() - T[k].translation()).squaredNorm();
  }
  return std::sqrt(sum / static_cast<double>(truth.size()));
}

GlobalGraphConfig graphConfig() {
  GlobalGraphConfig c;
  c.vio = RelativeNoise{0.004, 0.02, 1e-5, 5e-4};
  return c;
}

TEST(GlobalGraph, LoopsPullADriftingVioOntoTheTruth) {
  const LoopWorld w = makeLoopWorld();
  std::vector<Eigen::Isometry3d> vio;
  for (const GraphNode& n : w.nodes) vio.push_back(n.T_w_b);
  const GlobalGraphResult r = solveGlobalGraph(w.nodes, {}, w.loops, true, graphConfig());
  const double before = rmse(w.truth, vio), after = rmse(w.truth, r.T);
  std::cout << "global graph, pure VIO: rmse " << before << " m -> " << after << " m with "
            << w.loops.size() << " loops, " << r.rounds << " rounds, " << r.iterations
            << " iterations, " << r.ms_solve << " ms\n";
  EXPECT_GT(before, 3.0);
  EXPECT_LT(after, 0.25 * before);
  EXPECT_TRUE(r.converged) << r.termination;
  for (const LoopVerdict& v : r.loops) EXPECT_TRUE(v.active) << v.chi2;
  // The gauge: the first node stays where the VIO put it.
  EXPECT_LT((r.T[0].translation() - w.nodes[0].T_init.translation()).norm(), 1e-9);
}

TEST(GlobalGraph, AWrongLoopFiveMetresOffIsSwitchedOff) {
  const LoopWorld w = makeLoopWorld();
  const GlobalGraphResult clean = solveGlobalGraph(w.nodes, {}, w.loops, true, graphConfig());
  std::vector<GraphLoop> loops = w.loops;
  GraphLoop wrong = loops[loops.size() / 2];
  wrong.i += 3;  // a neighbouring place, then 5 m off across the road
  wrong.T_i_j = w.truth[wrong.i].inverse() * w.truth[wrong.j];
  wrong.T_i_j.translation() += Eigen::Vector3d(0.0, 5.0, 0.0);
  loops.push_back(wrong);
  const GlobalGraphResult r = solveGlobalGraph(w.nodes, {}, loops, true, graphConfig());
  EXPECT_FALSE(r.loops.back().active) << r.loops.back().chi2;
  for (std::size_t k = 0; k + 1 < loops.size(); ++k) EXPECT_TRUE(r.loops[k].active) << k;
  const double ape_clean = rmse(w.truth, clean.T), ape = rmse(w.truth, r.T);
  std::cout << "wrong loop: chi2 " << r.loops.back().chi2 << ", rmse " << ape << " m (clean "
            << ape_clean << " m), " << r.rounds << " rounds\n";
  EXPECT_LE(ape, 1.05 * ape_clean);
  EXPECT_TRUE(r.converged);
}

TEST(GlobalGraph, WithoutLoopsOneSolveAndTheVioStays) {
  const LoopWorld w = makeLoopWorld();
  const GlobalGraphResult r = solveGlobalGraph(w.nodes, {}, {}, true, graphConfig());
  EXPECT_EQ(r.rounds, 1);
  for (std::size_t k = 0; k < w.nodes.size(); ++k) {
    EXPECT_LT((r.T[k].translation() - w.nodes[k].T_w_b.translation()).norm(), 1e-6) << k;
  }
}

// GNSS fixes every 10 m with 1.5 m white noise plus a Gauss-Markov bias: the graph's positions
// beat the fixes, and with loops the two laps agree with each other far better than without.
TEST(GlobalGraph, FixesWithABiasAndLoopsMakeTheLapsAgree) {
  const LoopWorld w = makeLoopWorld();
  std::mt19937_64 rng(5);
  std::normal_distribution<double> n01(0.0, 1.0);
  std::vector<GraphFix> fixes;
  Eigen::Vector3d bias = Eigen::Vector3d::Zero();
  const double phi = std::exp(-1.0 / 60.0 * 1.0);
  double fix_sq = 0.0;
  for (std::size_t k = 0; k < w.nodes.size(); k += 5) {
    for (int a = 0; a < 3; ++a) bias(a) = phi * bias(a) + std::sqrt(1 - phi * phi) * n01(rng);
    GraphFix f;
    f.node = k;
    f.t_ns = w.nodes[k].t_ns;
    f.q_b = Eigen::Vector3d(0, 0, 0.8);
    const Eigen::Vector3d err = bias + 1.5 * Eigen::Vector3d{n01(rng), n01(rng), 0.0};
    f.p_enu = w.truth[k] * f.q_b + err;
    f.sigma_h_m = 1.5;
    f.sigma_v_m = 3.0;
    fix_sq += err.squaredNorm();
    fixes.push_back(f);
  }
  // Start from the VIO registered at the first fix (as the online fusion would).
  std::vector<GraphNode> nodes = w.nodes;
  const auto lapError = [&](const std::vector<Eigen::Isometry3d>& T) {
    double sum = 0.0;
    for (const GraphLoop& l : w.loops) {
      const Eigen::Vector3d est = T[l.j].translation() - T[l.i].translation();
      const Eigen::Vector3d ref = w.truth[l.j].translation() - w.truth[l.i].translation();
      sum += (est - ref).squaredNorm();
    }
    return std::sqrt(sum / static_cast<double>(w.loops.size()));
  };
  const GlobalGraphResult without = solveGlobalGraph(nodes, fixes, {}, true, graphConfig());
  const GlobalGraphResult with = solveGlobalGraph(nodes, fixes, w.loops, true, graphConfig());
  const double fix_rms = std::sqrt(fix_sq / static_cast<double>(fixes.size()));
  std::cout << "fixes rms " << fix_rms << " m; graph rmse " << rmse(w.truth, without.T)
            << " m without loops, " << rmse(w.truth, with.T) << " m with; lap disagreement "
            << lapError(without.T) << " -> " << lapError(with.T) << " m\n";
  EXPECT_LT(rmse(w.truth, with.T), fix_rms);
  EXPECT_LT(lapError(with.T), 0.1);
  EXPECT_LT(lapError(with.T), 0.3 * lapError(without.T));
  EXPECT_TRUE(with.converged);
}

// Two drives of the circle (segments 0 and 1: the first lap, then the second as a drive of its
// own, in a VIO world of its own), each with its own receiver bias: loops between them make the
// drives agree; without loops each keeps its own GNSS error. No VIO factor joins the segments.
struct TwoDrives {
  std::vector<GraphNode> nodes;
  std::vector<GraphFix> fixes;
  std::vector<GraphLoop> loops;
  std::vector<Eigen::Isometry3d> truth;
};

TwoDrives makeTwoDrives(const LoopWorld& w) {
  TwoDrives d;
  d.truth = w.truth;
  d.loops = w.loops;  // i on the first lap (drive 0), j on the second (drive 1)
  std::mt19937_64 rng(9);
  std::normal_distribution<double> n01(0.0, 1.0);
  Eigen::Isometry3d other_world = Eigen::Isometry3d::Identity();
  other_world.linear() = Eigen::AngleAxisd(1.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  other_world.translation() = Eigen::Vector3d(300.0, -40.0, 2.0);
  const std::array<Eigen::Vector3d, 2> bias = {Eigen::Vector3d(0.9, -0.6, 0.3),
                                               Eigen::Vector3d(-0.7, 0.8, -0.2)};
  for (std::size_t k = 0; k < w.nodes.size(); ++k) {
    GraphNode n = w.nodes[k];
    n.segment = k > w.per_lap ? 1 : 0;
    if (n.segment == 1) n.T_w_b = other_world * n.T_w_b;
    // Each drive's own registration: placed at its biased fixes.
    n.T_init = w.truth[k];
    n.T_init.translation() += bias[n.segment];
    d.nodes.push_back(n);
  }
  for (std::size_t k = 0; k < d.nodes.size(); k += 5) {
    GraphFix f;
    f.node = k;
    f.t_ns = d.nodes[k].t_ns;
    f.p_enu = w.truth[k].translation() + bias[d.nodes[k].segment] +
              0.3 * Eigen::Vector3d{n01(rng), n01(rng), 0.0};
    f.sigma_h_m = 1.5;
    f.sigma_v_m = 3.0;
    d.fixes.push_back(f);
  }
  return d;
}

TEST(GlobalGraph, LoopsBetweenDrivesMakeTwoDrivesAgree) {
  const TwoDrives d = makeTwoDrives(makeLoopWorld());
  const auto disagreement = [&](const std::vector<Eigen::Isometry3d>& T) {
    double sum = 0.0;
    for (const GraphLoop& l : d.loops) {
      const Eigen::Vector3d est = T[l.j].translation() - T[l.i].translation();
      const Eigen::Vector3d ref = d.truth[l.j].translation() - d.truth[l.i].translation();
      sum += (est - ref).squaredNorm();
    }
    return std::sqrt(sum / static_cast<double>(d.loops.size()));
  };
  const GlobalGraphResult apart = solveGlobalGraph(d.nodes, d.fixes, {}, true, graphConfig());
  const GlobalGraphResult joint = solveGlobalGraph(d.nodes, d.fixes, d.loops, true, graphConfig());
  std::cout << "two drives: disagreement " << disagreement(apart.T) << " m apart, "
            << disagreement(joint.T) << " m joint (" << joint.rounds << " rounds); rmse "
            << rmse(d.truth, apart.T) << " m apart, " << rmse(d.truth, joint.T) << " m joint\n";
  EXPECT_GT(disagreement(apart.T), 1.0);  // the two receivers' biases differ by ~2 m
  EXPECT_LT(disagreement(joint.T), 0.1);
  EXPECT_TRUE(joint.converged) << joint.termination;
  for (const LoopVerdict& v : joint.loops) EXPECT_TRUE(v.active) << v.chi2;
  EXPECT_LT(rmse(d.truth, joint.T), rmse(d.truth, apart.T));
  // No VIO factor across the segments: drive 1's own VIO world (300 m away, turned 57 deg) would
  // otherwise pull the drives apart, as it does when they are declared one segment.
  std::vector<GraphNode> one = d.nodes;
  for (GraphNode& n : one) n.segment = 0;
  const GlobalGraphResult mixed = solveGlobalGraph(one, d.fixes, d.loops, true, graphConfig());
  std::cout << "as one segment: rmse " << rmse(d.truth, mixed.T) << " m\n";
  EXPECT_GT(rmse(d.truth, mixed.T), 3.0 * rmse(d.truth, joint.T));
}

// Each drive's receiver bias starts from its own stationary prior: with no loop between them, a
// drive solved beside another comes out as it does alone (the second drive's bias chain once had
// no prior of its own, its prior landing on the first drive's first bias).
TEST(GlobalGraph, DrivesWithoutLoopsAreSolvedAsIfAlone) {
  const TwoDrives d = makeTwoDrives(makeLoopWorld());
  const std::size_t first1 = static_cast<std::size_t>(
      std::find_if(d.nodes.begin(), d.nodes.end(), [](const GraphNode& n) { return n.segment; }) -
      d.nodes.begin());
  std::vector<GraphNode> alone_nodes(d.nodes.begin() + static_cast<std::ptrdiff_t>(first1),
                                     d.nodes.end());
  for (GraphNode& n : alone_nodes) n.segment = 0;
  std::vector<GraphFix> alone_fixes;
  for (GraphFix f : d.fixes) {
    if (f.node < first1) continue;
    f.node -= first1;
    alone_fixes.push_back(f);
  }
  ASSERT_GT(alone_fixes.size(), 10U);
  const GlobalGraphResult both = solveGlobalGraph(d.nodes, d.fixes, {}, true, graphConfig());
  const GlobalGraphResult alone =
      solveGlobalGraph(alone_nodes, alone_fixes, {}, true, graphConfig());
  double worst = 0.0;
  for (std::size_t k = 0; k < alone_nodes.size(); ++k) {
    worst = std::max(worst, (both.T[first1 + k].translation() - alone.T[k].translation()).norm());
  }
  std::cout << "drive 2 beside drive 1 against alone: at most " << worst << " m apart\n";
  EXPECT_LT(worst, 1e-3);
}

// An RTK receiver between float (a metre off that persists) and fixed (centimetres): each quality
// has its own bias chain, so the fixed epochs' nodes are fused to their centimetres (the
// smoother's GnssSmoother.EachFixQualityHasItsOwnBias, for the global graph).
TEST(GlobalGraph, EachFixQualityHasItsOwnBias) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> n01(0.0, 1.0);
  std::vector<GraphNode> nodes;
  std::vector<GraphFix> fixes;
  for (int k = 0; k < 1000; ++k) {  // 200 s at 5 Hz, 10 m/s on a gentle curve
    const double t = 0.2 * k;
    GraphNode n;
    n.t_ns = static_cast<std::int64_t>(k) * 200'000'000;
    n.T_w_b.linear() = odometry::expSo3(Eigen::Vector3d(0, 0, 0.005 * t));
    n.T_w_b.translation() = Eigen::Vector3d(10.0 * t, 0.025 * t * t, 0.0);
    n.T_init = n.T_w_b;  // an exact VIO in ENU
    nodes.push_back(n);
    const bool fixed = t >= 60.0 && t < 140.0;
    const Eigen::Vector3d float_bias =
        t < 60.0 ? Eigen::Vector3d(0.8, -0.6, 0.3) : Eigen::Vector3d(-0.5, 0.7, -0.2);
    GraphFix f;
    f.node = static_cast<std::size_t>(k);
    f.t_ns = n.t_ns;
    f.p_enu = n.T_w_b.translation() + (fixed ? Eigen::Vector3d::Zero() : float_bias) +
              (fixed ? 0.01 : 0.05) * Eigen::Vector3d{n01(rng), n01(rng), n01(rng)};
    f.sigma_h_m = fixed ? 0.015 : 0.4;
    f.sigma_v_m = fixed ? 0.03 : 0.8;
    f.quality = fixed ? 4 : 5;
    fixes.push_back(f);
  }
  const GlobalGraphResult r = solveGlobalGraph(nodes, fixes, {}, true, graphConfig());
  std::vector<double> fixed_error;
  for (const GraphFix& f : fixes) {
    if (f.quality != 4) continue;
    fixed_error.push_back(
        (r.T[f.node].translation() - nodes[f.node].T_w_b.translation()).head<2>().norm());
  }
  std::sort(fixed_error.begin(), fixed_error.end());
  const double median = fixed_error[fixed_error.size() / 2];
  std::cout << "fixed epochs: horizontal median " << median << " m\n";
  EXPECT_LT(median, 0.02);
}

TEST(GlobalGraph, ASegmentWithoutFixesOrLoopsHoldsItsFirstNode) {
  TwoDrives d = makeTwoDrives(makeLoopWorld());
  std::erase_if(d.fixes, [&](const GraphFix& f) { return d.nodes[f.node].segment == 1; });
  const GlobalGraphResult r = solveGlobalGraph(d.nodes, d.fixes, {}, true, graphConfig());
  const std::size_t first1 = static_cast<std::size_t>(
      std::find_if(d.nodes.begin(), d.nodes.end(), [](const GraphNode& n) { return n.segment; }) -
      d.nodes.begin());
  EXPECT_LT((r.T[first1].translation() - d.nodes[first1].T_init.translation()).norm(), 1e-9);
  EXPECT_TRUE(r.converged) << r.termination;
  // Joined by loops to the anchored drive, it is free and follows the loops.
  const GlobalGraphResult joined = solveGlobalGraph(d.nodes, d.fixes, d.loops, true, graphConfig());
  EXPECT_GT((joined.T[first1].translation() - d.nodes[first1].T_init.translation()).norm(), 0.5);
  // Segments out of order are refused.
  std::swap(d.nodes.front().segment, d.nodes.back().segment);
  EXPECT_THROW(solveGlobalGraph(d.nodes, d.fixes, {}, true, graphConfig()), InvalidInput);
}

TEST(GlobalGraph, BadInputThrows) {
  const LoopWorld w = makeLoopWorld();
  std::vector<GraphLoop> loops = {w.loops.front()};
  loops[0].j = loops[0].i;
  EXPECT_THROW(solveGlobalGraph(w.nodes, {}, loops, true, graphConfig()), InvalidInput);
  loops[0].j = w.nodes.size();
  EXPECT_THROW(solveGlobalGraph(w.nodes, {}, loops, true, graphConfig()), InvalidInput);
  loops = {w.loops.front()};
  loops[0].covariance(0, 0) = -1.0;
  EXPECT_THROW(solveGlobalGraph(w.nodes, {}, loops, true, graphConfig()), InvalidInput);
  EXPECT_THROW(solveGlobalGraph({}, {}, {}, true, graphConfig()), InvalidInput);
  GlobalGraphConfig bad = graphConfig();
  bad.loop_chi2 = 0.0;
  EXPECT_THROW(solveGlobalGraph(w.nodes, {}, {}, true, bad), InvalidInput);
}

}  // namespace
}  // namespace gvio::fusion
