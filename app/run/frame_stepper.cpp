#include "run/frame_stepper.hpp"

#include <chrono>
#include <future>
#include <stdexcept>
#include <utility>

#include "run/stats.hpp"

namespace gvio::run {

odometry::FrameResult FrameStepper::step(std::int64_t t_ns, const odometry::RectifiedImages& images,
                                         const Next* next) {
  using Clock = std::chrono::steady_clock;
  if (ahead_ && ahead_->t_ns != t_ns) {
    throw std::logic_error("FrameStepper: a frame was tracked ahead but another one came");
  }
  if (!estimator_.beginFrame(t_ns)) {
    odometry::FrameResult ignored;
    ignored.t_ns = t_ns;
    return ignored;  // never tracked ahead: wouldAccept() said no before
  }
  double ms_tracking = 0.0;
  odometry::TrackedFrame tracked;
  if (ahead_) {
    tracked = estimator_.takeAhead(std::move(*ahead_), images.left, images.right, ms_tracking);
    ahead_.reset();
  } else {
    const auto start = Clock::now();
    tracked = estimator_.trackFrame(t_ns, images.left, images.right);
    ms_tracking = msSince(start);
  }
  // wouldAccept(next) depends on this frame's stamp only, which beginFrame has recorded; the
  // tracking ahead touches the front end alone, which processFrame leaves to it.
  std::future<odometry::VioEstimator::TrackAhead> tracking_ahead;
  if (threaded_ && next != nullptr && next->images != nullptr &&
      estimator_.wouldAccept(next->t_ns)) {
    tracking_ahead = std::async(std::launch::async, [this, next] {
      return estimator_.trackAhead(next->t_ns, next->images->left, next->images->right);
    });
  }
  odometry::FrameResult result = estimator_.processFrame(t_ns, tracked, ms_tracking);
  if (tracking_ahead.valid()) ahead_ = tracking_ahead.get();
  return result;
}

}  // namespace gvio::run
