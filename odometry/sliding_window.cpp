#include "odometry/sliding_window.hpp"

#include <ceres/normal_prior.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include <algorithm>
#include <vector>

#include "odometry/fixed_block_cost.hpp"
#include "odometry/imu_factor.hpp"
#include "odometry/lie.hpp"
#include "odometry/time_offset_factor.hpp"

namespace gvio::odometry {
namespace {

const Eigen::Vector3d kGravityW(0.0, 0.0, -kGravity_mps2);
// Inverse depths are kept positive (a point behind the anchor camera is meaningless).
constexpr double kMinInverseDepth = 1e-4;

}  // namespace

ImuBias WindowFrame::bias() const {
  ImuBias b;
  b.acc = Eigen::Map<const Eigen::Vector3d>(speed_bias.data() + 3);
  b.gyr = Eigen::Map<const Eigen::Vector3d>(speed_bias.data() + 6);
  return b;
}

void WindowFrame::setBias(const ImuBias& b) {
  Eigen::Map<Eigen::Vector3d>{speed_bias.data() + 3} = b.acc;
  Eigen::Map<Eigen::Vector3d>{speed_bias.data() + 6} = b.gyr;
}

SlidingWindow::SlidingWindow(const EstimatorConfig& config, const StereoGeometry& geometry)
    : config_(config),
      geometry_(geometry),
      huber_(std::make_shared<ceres::HuberLoss>(config.huber_sigmas)),
      context_(ceres::Context::Create()),
      time_offset_prior_sigma_s_(config.time_offset_sigma_s) {}

WindowFrame* SlidingWindow::find(std::uint64_t uid) const {
  for (const auto& f : frames_) {
    if (f->uid == uid) return f.get();
  }
  return nullptr;
}

PoseLookup SlidingWindow::poseLookup() const {
  return [this](std::uint64_t uid) -> const double* {
    const WindowFrame* f = find(uid);
    return f == nullptr ? nullptr : f->pose.data();
  };
}

int SlidingWindow::keyframeCount() const {
  int n = 0;
  for (const auto& f : frames_) n += f->keyframe ? 1 : 0;
  return n;
}

bool SlidingWindow::usable(const Landmark& lm) {
  return lm.has_depth && lm.observations.size() >= 2;
}

bool SlidingWindow::priorHoldsTimeOffset() const {
  return prior_ && prior_->blockIndex(time_offset_s_.get()) >= 0;
}

std::shared_ptr<ceres::CostFunction> SlidingWindow::timeOffsetPrior() const {
  const ceres::Matrix A = ceres::Matrix::Constant(1, 1, 1.0 / time_offset_prior_sigma_s_);
  const ceres::Vector b = ceres::Vector::Constant(1, time_offset_prior_mean_s_);
  return std::make_shared<ceres::NormalPrior>(A, b);
}

int SlidingWindow::landmarkFactors(Landmark& lm, const FactorSink& raw_sink,
                                   bool with_time_offset) const {
  if (!usable(lm)) return 0;
  WindowFrame* anchor = find(lm.anchor().frame_uid);
  if (anchor == nullptr) return 0;
  int forwarded = 0;
  const Eigen::Vector3d bearing = geometry_.bearing(lm.anchor().px_left);
  const double sigma = config_.pixel_sigma_px;
  const ceres::LossFunction* loss = huber_.get();
  // A residual that cannot be evaluated at the current state (the point behind a camera after a
  // poor prediction) would make Ceres abandon the whole solve: such observations sit this one out.
  const FactorSink sink = [&raw_sink, &forwarded](std::shared_ptr<ceres::CostFunction> cost,
                                                  const ceres::LossFunction* l,
                                                  std::vector<double*> blocks) {
    Eigen::Vector2d r;
    if (!cost->Evaluate(blocks.data(), r.data(), nullptr)) return;
    raw_sink(std::move(cost), l, std::move(blocks));
    ++forwarded;
  };
  if (with_time_offset) {
    timeOffsetFactors(lm, *anchor, sink);
    return forwarded;
  }
  if (geometry_.stereo && lm.anchor().has_right) {
    sink(std::make_shared<SameFrameReprojectionFactor>(
             bearing, geometry_.left.T_b_c, geometry_.right, lm.anchor().px_right, sigma),
         loss, {&lm.inv_depth});
  }
  for (std::size_t k = 1; k < lm.observations.size(); ++k) {
    const Observation& o = lm.observations[k];
    WindowFrame* f = find(o.frame_uid);
    if (f == nullptr || f == anchor) continue;
    sink(std::make_shared<ReprojectionFactor>(bearing, geometry_.left.T_b_c, geometry_.left,
                                              o.px_left, sigma),
         loss, {anchor->pose.data(), f->pose.data(), &lm.inv_depth});
    if (geometry_.stereo && o.has_right) {
      sink(std::make_shared<ReprojectionFactor>(bearing, geometry_.left.T_b_c, geometry_.right,
                                                o.px_right, sigma),
           loss, {anchor->pose.data(), f->pose.data(), &lm.inv_depth});
    }
  }
  return forwarded;
}

// The same residuals with t_d as a block, each pixel moving at its own image's velocity.
void SlidingWindow::timeOffsetFactors(Landmark& lm, WindowFrame& anchor,
                                      const FactorSink& sink) const {
  double* t_d = time_offset_s_.get();
  const double sigma = config_.pixel_sigma_px;
  const ceres::LossFunction* loss = huber_.get();
  const Observation& a = lm.anchor();
  const MovingPixel anchor_px = a.movingLeft();
  if (geometry_.stereo && a.has_right) {
    sink(std::make_shared<SameFrameTimeOffsetFactor>(anchor_px, geometry_.left, geometry_.right,
                                                     a.movingRight(), sigma),
         loss, {&lm.inv_depth, t_d});
  }
  double* anchor_pose = anchor.pose.data();
  for (std::size_t k = 1; k < lm.observations.size(); ++k) {
    const Observation& o = lm.observations[k];
    WindowFrame* f = find(o.frame_uid);
    if (f == nullptr || f == &anchor) continue;
    sink(std::make_shared<ReprojectionTimeOffsetFactor>(anchor_px, geometry_.left, geometry_.left,
                                                        o.movingLeft(), sigma),
         loss, {anchor_pose, f->pose.data(), &lm.inv_depth, t_d});
    if (geometry_.stereo && o.has_right) {
      sink(std::make_shared<ReprojectionTimeOffsetFactor>(anchor_px, geometry_.left,
                                                          geometry_.right, o.movingRight(), sigma),
           loss, {anchor_pose, f->pose.data(), &lm.inv_depth, t_d});
    }
  }
}

TimeOffsetExcitation SlidingWindow::timeOffsetExcitation() const {
  // Each IMU interval's mean angular rate Log(dR)/dt and mean specific force dv/dt, both in the
  // body frame at the interval's start: constant over the window for a stationary motion.
  std::vector<Eigen::Vector3d> rates, forces;
  for (std::size_t k = 1; k < frames_.size(); ++k) {
    const auto& pre = frames_[k]->preintegration;
    if (!pre || pre->deltaT() <= 0.0) continue;
    rates.push_back(logSo3(pre->deltaR()) / pre->deltaT());
    forces.push_back(pre->deltaV() / pre->deltaT());
  }
  TimeOffsetExcitation e;
  if (rates.size() < 2) return e;
  const auto spread = [](const std::vector<Eigen::Vector3d>& xs) {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const auto& x : xs) mean += x;
    mean /= static_cast<double>(xs.size());
    double worst = 0.0;
    for (const auto& x : xs) worst = std::max(worst, (x - mean).norm());
    return worst;
  };
  e.rate_change_radps = spread(rates);
  e.force_change_mps2 = spread(forces);
  return e;
}

bool SlidingWindow::timeOffsetUnobservable() const {
  const TimeOffsetExcitation e = timeOffsetExcitation();
  return e.rate_change_radps < config_.time_offset_min_rate_change_radps &&
         e.force_change_mps2 < config_.time_offset_min_force_change_mps2;
}

void SlidingWindow::reintegrateIfNeeded() {
  for (std::size_t k = 1; k < frames_.size(); ++k) {
    auto& pre = frames_[k]->preintegration;
    if (!pre) continue;
    const ImuBias b = frames_[k - 1]->bias();
    if (pre->needsReintegration(b)) pre->reintegrate(b);
  }
}

SolveStats SlidingWindow::solve(bool use_imu) {
  SolveStats stats;
  if (frames_.empty()) return stats;
  if (use_imu) reintegrateIfNeeded();
  ceres::Problem::Options popts;
  popts.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  popts.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  popts.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  popts.context = context_.get();
  // The checks guard against caller errors (a block added twice to one residual, sizes that do not
  // match) that the tests cover; they cost a sort and hash lookups per residual block, every frame.
  popts.disable_all_safety_checks = true;
  ceres::Problem problem(popts);
  std::vector<std::shared_ptr<ceres::CostFunction>> alive;  // the problem does not own them
  const auto add = [&](std::shared_ptr<ceres::CostFunction> cost, const ceres::LossFunction* loss,
                       std::vector<double*> blocks) {
    problem.AddResidualBlock(cost.get(), const_cast<ceres::LossFunction*>(loss), blocks);
    alive.push_back(std::move(cost));
    ++stats.residual_blocks;
  };

  for (const auto& f : frames_) {
    problem.AddParameterBlock(f->pose.data(), kPoseAmbient, &pose_manifold_);
    if (use_imu) problem.AddParameterBlock(f->speed_bias.data(), kSpeedBiasSize);
  }
  if (use_imu) {
    for (std::size_t k = 1; k < frames_.size(); ++k) {
      WindowFrame& a = *frames_[k - 1];
      WindowFrame& b = *frames_[k];
      if (!b.preintegration) continue;
      add(std::make_shared<ImuFactor>(b.preintegration, kGravityW), nullptr,
          {a.pose.data(), a.speed_bias.data(), b.pose.data(), b.speed_bias.data()});
    }
  }
  const bool with_time_offset = estimatesTimeOffset(use_imu);
  for (auto& [id, lm] : landmarks_.all()) {
    if (landmarkFactors(lm, add, with_time_offset) > 0) {
      ++stats.landmarks;
      problem.SetParameterLowerBound(&lm.inv_depth, 0, kMinInverseDepth);
    }
  }
  if (prior_) {
    add(std::make_shared<MarginalizationFactor>(prior_), nullptr, prior_->blockAddresses());
  }
  if (with_time_offset && !priorHoldsTimeOffset()) {
    add(timeOffsetPrior(), nullptr, {time_offset_s_.get()});
  }
  stats.time_offset_held = with_time_offset && timeOffsetUnobservable();
  if (stats.time_offset_held) startTimeOffsetHold();
  if (stats.time_offset_held && problem.HasParameterBlock(time_offset_s_.get())) {
    problem.SetParameterBlockConstant(time_offset_s_.get());
  }
  bool anchored = false;
  for (const AnchorFactor& a : anchors_) {
    if (a.speed_bias && !use_imu) continue;
    add(a.cost, nullptr, a.blocks);
    anchored = true;
  }
  if (!prior_ && !anchored) problem.SetParameterBlockConstant(frames_.front()->pose.data());
  // A frame whose speed/bias no residual constrains (an IMU outage) is held at its prediction.
  if (use_imu) {
    for (std::size_t k = 0; k < frames_.size(); ++k) {
      const bool linked_before = k > 0 && frames_[k]->preintegration;
      const bool linked_after = k + 1 < frames_.size() && frames_[k + 1]->preintegration;
      const bool in_prior = prior_ && prior_->blockIndex(frames_[k]->speed_bias.data()) >= 0;
      if (!linked_before && !linked_after && !in_prior) {
        problem.SetParameterBlockConstant(frames_[k]->speed_bias.data());
      }
    }
  }

  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_SCHUR;
  options.trust_region_strategy_type = ceres::DOGLEG;
  options.max_num_iterations = config_.solverIterations();
  // The inverse-depth lower bound makes the problem constrained, and Ceres then runs an Armijo
  // line search along every trust-region step, with a full Jacobian evaluation each time (about
  // 15 % of the solve). Its own source calls that search "not terribly effective" (ceres-solver
  // issue 187); the bound is kept by the projection in Plus either way. With the IMU it is left
  // out: the estimator takes 23 % less time on KITTI-00 (with the two-stage Schur complement of
  // the marginalisation), a street drive's poses were the same to the last bit, 14 of the 15
  // style-matrix drives gave the same APE to the millimetre and sparse texture seed 3 moved from
  // 0.379 to 0.393 m. Without the IMU (stereo only) the steps are poorer and the search shortens
  // ones that would otherwise be rejected, costing one of the few iterations: there it stays
  // (the block drive of the loop tests: 1.90 m APE with it, 6.58 m without).
  if (use_imu) options.max_num_line_search_step_size_iterations = 0;
  options.num_threads = 1;
  options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  stats.iterations = static_cast<int>(summary.iterations.size());
  stats.converged = summary.termination_type == ceres::CONVERGENCE;
  stats.time_offset_free = with_time_offset && !stats.time_offset_held;
  if (stats.time_offset_free) recordFreeTimeOffset();
  return stats;
}

void SlidingWindow::startTimeOffsetHold() {
  if (free_time_offsets_s_.empty()) return;  // held already (or never free): stays where it is
  std::vector<double> v(free_time_offsets_s_.begin(), free_time_offsets_s_.end());
  // The lower median for an even count: a value one solve actually reached.
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>((v.size() - 1) / 2);
  std::nth_element(v.begin(), mid, v.end());
  *time_offset_s_ = *mid;
  free_time_offsets_s_.clear();
}

void SlidingWindow::recordFreeTimeOffset() {
  free_time_offsets_s_.push_back(*time_offset_s_);
  while (static_cast<int>(free_time_offsets_s_.size()) > config_.time_offset_hold_median_solves) {
    free_time_offsets_s_.pop_front();
  }
}

void SlidingWindow::marginalizeOldest(bool use_imu) {
  if (frames_.empty()) return;
  WindowFrame& oldest = *frames_.front();
  if (frames_.size() >= 2) {
    Marginalizer m;
    for (const auto& f : frames_) m.setManifold(f->pose.data(), &pose_manifold_);
    // A block may only be marked when some residual names it.
    bool pose_named = false, speed_bias_named = false;
    if (prior_) {
      m.addResidualBlock(std::make_shared<MarginalizationFactor>(prior_), nullptr,
                         prior_->blockAddresses());
      pose_named = prior_->blockIndex(oldest.pose.data()) >= 0;
      speed_bias_named = prior_->blockIndex(oldest.speed_bias.data()) >= 0;
    }
    WindowFrame& next = *frames_[1];
    if (use_imu && next.preintegration) {
      m.addResidualBlock(
          std::make_shared<ImuFactor>(next.preintegration, kGravityW), nullptr,
          {oldest.pose.data(), oldest.speed_bias.data(), next.pose.data(), next.speed_bias.data()});
      pose_named = speed_bias_named = true;
    }
    const bool with_time_offset = estimatesTimeOffset(use_imu);
    // Where the motion cannot observe t_d, what the residuals appear to say about it is model
    // error: they are folded in with t_d held at its value, so the prior learns nothing of it.
    const bool hold_time_offset = with_time_offset && timeOffsetUnobservable();
    bool time_offset_named = false;
    const auto sink = [&](std::shared_ptr<ceres::CostFunction> cost,
                          const ceres::LossFunction* loss, std::vector<double*> blocks) {
      if (hold_time_offset && blocks.back() == time_offset_s_.get()) {
        cost =
            std::make_shared<FixedBlockCost>(std::move(cost), static_cast<int>(blocks.size()) - 1,
                                             std::vector<double>{*time_offset_s_});
        blocks.pop_back();
      }
      time_offset_named = time_offset_named || blocks.back() == time_offset_s_.get();
      // The loss is owned by the window and outlives the marginaliser.
      m.addResidualBlock(std::move(cost), std::shared_ptr<const ceres::LossFunction>(huber_, loss),
                         blocks);
    };
    std::vector<std::uint64_t> folded;
    for (auto& [id, lm] : landmarks_.all()) {
      if (lm.anchor().frame_uid != oldest.uid) continue;
      if (landmarkFactors(lm, sink, with_time_offset) > 0) {
        m.markForRemoval(&lm.inv_depth);
        pose_named = true;
        folded.push_back(id);
      }
    }
    // The t_d prior is folded in once, with the first factors that take t_d into the prior.
    if (time_offset_named && !priorHoldsTimeOffset()) {
      m.addResidualBlock(timeOffsetPrior(), nullptr, {time_offset_s_.get()});
    }
    for (const AnchorFactor& a : anchors_) {
      if (a.frame_uid != oldest.uid || (a.speed_bias && !use_imu)) continue;
      m.addResidualBlock(a.cost, nullptr, a.blocks);
      (a.speed_bias ? speed_bias_named : pose_named) = true;
    }
    if (pose_named) m.markForRemoval(oldest.pose.data());
    if (speed_bias_named) m.markForRemoval(oldest.speed_bias.data());
    try {
      // Also replaces an old prior that did not involve the oldest frame (carried through).
      prior_ = (pose_named || prior_) ? m.marginalize() : nullptr;
      if (with_time_offset && priorHoldsTimeOffset()) {
        const double dt_s = static_cast<double>(next.t_ns - oldest.t_ns) * 1e-9;
        const double sigma = config_.time_offset_random_walk_s;
        prior_ = withRandomWalk(prior_, time_offset_s_.get(), 0, sigma * sigma * dt_s);
      }
    } catch (const std::exception&) {
      // A degenerate linearisation (it should not happen) costs the prior, never the run.
      prior_.reset();
    }
    // A landmark folded into the prior took every observation it has in the window with it, so
    // it leaves too. Re-anchoring it in its next observation (VINS-Mono's removeBackShiftDepth)
    // would put those observations into the solve a second time, and again at every later
    // marginalisation: a feature tracked through the whole window then counts up to window_size
    // times, the window grows overconfident in vision, and the tilt / accelerometer-bias pair,
    // unobservable on a straight, follows whatever the images pull (docs/benchmarks/vio-matrix.md,
    // "Each observation counted once"). Its track goes on: the next keyframe that sees it starts a
    // new landmark there. (EstimatorConfig::foldedLandmarksDropped says where it is done.)
    if (prior_ && config_.foldedLandmarksDropped()) {
      for (const std::uint64_t id : folded) landmarks_.all().erase(id);
    }
  } else {
    prior_.reset();
  }
  std::erase_if(anchors_, [&](const AnchorFactor& a) { return a.frame_uid == oldest.uid; });
  landmarks_.removeFrame(oldest.uid, poseLookup(), geometry_, *time_offset_s_);
  frames_.pop_front();
}

void SlidingWindow::dropNewest() {
  if (frames_.empty()) return;
  const std::uint64_t uid = frames_.back()->uid;
  std::erase_if(anchors_, [uid](const AnchorFactor& a) { return a.frame_uid == uid; });
  landmarks_.removeFrame(uid, poseLookup(), geometry_, *time_offset_s_);
  frames_.pop_back();
}

void SlidingWindow::clear() {
  // The next window starts from the estimate, with the configured uncertainty (what the window
  // had learnt about it is gone with its prior).
  time_offset_prior_mean_s_ = *time_offset_s_;
  time_offset_prior_sigma_s_ = config_.time_offset_sigma_s;
  frames_.clear();
  landmarks_.clear();
  prior_.reset();
  anchors_.clear();
}

void SlidingWindow::anchorOldest(const StartPrior& start) {
  anchors_.clear();
  if (frames_.empty()) return;
  WindowFrame& f = *frames_.front();
  anchors_.push_back({f.uid,
                      std::make_shared<PosePriorFactor>(f.pose.data(), start.pose),
                      {f.pose.data()},
                      false});
  if (!start.speed_bias) return;
  Eigen::Matrix<double, 9, 1> inv_sigma;
  inv_sigma << Eigen::Vector3d::Constant(1.0 / start.velocity_mps),
      Eigen::Vector3d::Constant(1.0 / start.acc_bias_mps2),
      Eigen::Vector3d::Constant(1.0 / start.gyr_bias_radps);
  const ceres::Matrix A = inv_sigma.asDiagonal();
  const ceres::Vector b = Eigen::Map<const Eigen::Matrix<double, 9, 1>>(f.speed_bias.data());
  anchors_.push_back(
      {f.uid, std::make_shared<ceres::NormalPrior>(A, b), {f.speed_bias.data()}, true});
}

}  // namespace gvio::odometry
