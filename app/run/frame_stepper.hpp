#pragma once
// Feeds a VioEstimator frame by frame, with addFrame's results bit for bit. Threaded, it tracks
// the next frame (the front end: pyramids, KLT, corners, stereo matching) on a thread of its own
// while the current frame is estimated (the window solve), the two halves of a frame's work that
// otherwise run one after the other on one core (VioEstimator::trackAhead / takeAhead).
#include <cstdint>
#include <optional>

#include "odometry/rectifier.hpp"
#include "odometry/vio_estimator.hpp"

namespace gvio::run {

class FrameStepper {
 public:
  FrameStepper(odometry::VioEstimator& estimator, bool threaded)
      : estimator_(estimator), threaded_(threaded) {}

  // The frame that comes right after the one being stepped, already decoded.
  struct Next {
    std::int64_t t_ns = 0;
    const odometry::RectifiedImages* images = nullptr;
  };

  // addFrame(t_ns, images) for this frame; `next` (may be null: not loaded or unreadable) is
  // tracked ahead while this frame is estimated. A failure of that tracking is rethrown here.
  odometry::FrameResult step(std::int64_t t_ns, const odometry::RectifiedImages& images,
                             const Next* next);

 private:
  odometry::VioEstimator& estimator_;
  bool threaded_;
  std::optional<odometry::VioEstimator::TrackAhead> ahead_;
};

}  // namespace gvio::run
