#pragma once
// How well a tracker's output agrees with a simulated drive's true camera motion.
#include <vector>

#include "io/dataset.hpp"
#include "odometry/feature_tracker.hpp"

namespace gvio::test {

// Every stereo feature of frame k (disparity >= 2 px) lifted to 3-D with the true baseline, moved
// with the true camera motion to frame k + 1 and projected: its distance (px) from where the
// tracker followed it, in frame and feature order. `tracked[k]` is the tracker's output for
// `dataset.frames[k]`; every frame needs a ground-truth pose at its stamp (throws otherwise).
std::vector<double> trueMotionErrors(const io::Dataset& dataset,
                                     const std::vector<odometry::TrackedFrame>& tracked);

}  // namespace gvio::test
