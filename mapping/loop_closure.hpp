#pragma once
// Loop detection over a drive's keyframes (place recognition), after the drive: every keyframe in
// time order is a query against the keyframes at least min_separation_s older.
//  1. Candidates by what the run knows (kd-tree radius search over the prior positions): the
//     radius is search_radius_m (two keyframes this far apart still see one scene) plus
//     search_sigmas x the 1-sigma uncertainty of the two keyframes' relative position: the
//     smaller of the GNSS-fused bound sqrt(sigma_i^2 + sigma_j^2) and the VIO drift over the
//     distance driven between them. Forward cameras see a place only in one direction: headings
//     must agree within max_heading_deg.
//  2. The max_candidates with the most similar thumbnails are verified (loop_verification.hpp).
//  3. Plausibility: the correction the loop makes to the prior relative pose must fit the same
//     uncertainty (search_sigmas x sigma + correction_floor_m, rotation likewise).
//  4. Temporal consistency: a loop is accepted only when verified loops of at least
//     consistent_keyframes query keyframes within consistency_window keyframes of each other
//     make the same correction (within consistency_m / consistency_deg); a single lucky match
//     (repeated texture) is not enough.
// Candidates are never too strict by default: every step's rejections are counted so that a run
// without loops says why (ORB-SLAM3 issues 533, 887).
#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "fusion/global_graph.hpp"
#include "fusion/gnss_smoother.hpp"
#include "mapping/loop_features.hpp"
#include "mapping/loop_verification.hpp"

namespace gvio::mapping {

struct LoopSearchConfig {
  double min_separation_s = 30.0;
  double max_heading_deg = 45.0;
  double search_radius_m = 10.0;
  double search_sigmas = 3.0;
  int max_candidates = 3;
  double correction_floor_m = 1.0;
  double correction_floor_deg = 3.0;
  int consistent_keyframes = 2;
  int consistency_window = 3;
  double consistency_m = 0.5;
  double consistency_deg = 2.0;
  void validate() const;  // throws InvalidInput naming the key
};

struct LoopConfig {
  bool enabled = true;
  LoopFeatureConfig features;
  LoopMatchConfig match;
  LoopSearchConfig search;
  // Floors added to a loop's covariance (in quadrature), for what the PnP covariance does not
  // see: the stereo depth noise of the candidate's points, the rectification.
  double sigma_floor_m = 0.02;
  double sigma_floor_deg = 0.05;
  void validate() const;  // throws InvalidInput naming the key
};

// What the run knows of a keyframe before loop closure.
struct KeyframePrior {
  std::int64_t t_ns = 0;
  // The drive (gvio merge's joint alignment); keyframes are grouped by segment. Between two
  // segments there is no time or path relation: neither the time separation nor the VIO drift
  // bound applies, only the GNSS-fused uncertainty.
  std::uint32_t segment = 0;
  Eigen::Isometry3d T_ref_b = Eigen::Isometry3d::Identity();  // pose in the run's target frame
  // 1-sigma absolute position uncertainty (GNSS-fused); infinity without GNSS.
  double sigma_m = 0.0;
  // 1-sigma rotation uncertainty (deg) of the GNSS-fused pose (its covariance's largest rotation
  // eigenvalue); infinity without GNSS. Bounds the heading correction of a loop between drives.
  double sigma_rot_deg = std::numeric_limits<double>::infinity();
  double path_m = 0.0;  // distance driven from the first keyframe
};

struct LoopCandidate {
  std::size_t query = 0, candidate = 0;  // keyframe indices, candidate older
  double distance_m = 0.0;               // between their prior positions
  double radius_m = 0.0;                 // the search radius for this pair
  float similarity = 0.0F;               // thumbnail correlation
  LoopMeasurement measurement;
  double correction_m = 0.0, correction_deg = 0.0;  // NaN unless verified
  bool accepted = false;
  std::string reason;  // ok, or why not (LoopCheck tokens, implausible, inconsistent, ...)
};

struct LoopDetection {
  std::vector<LoopCandidate> candidates;  // every verified candidate, query order
  std::vector<double> ms_per_keyframe;    // search + verification + checks, per query keyframe
  // Keyframe pairs that passed each stage of the search (pairs in radius, then heading).
  std::size_t pairs_in_radius = 0, pairs_heading_ok = 0;
};

// Which keyframe pairs are searched: all of them (one drive), or only pairs of different segments
// (gvio merge: each drive closed its own loops in its run).
enum class LoopPairs { kAll, kAcrossSegments };

// `keyframes` and `priors` are parallel, in time order within each segment. `camera` is the
// rectified left camera (T_b_c) of every keyframe. `drift` is the VIO's relative-motion noise
// model.
LoopDetection detectLoops(const std::vector<LoopKeyframe>& keyframes,
                          const std::vector<KeyframePrior>& priors, const CameraModel& camera,
                          const LoopConfig& config, const fusion::RelativeNoise& drift,
                          LoopPairs pairs = LoopPairs::kAll);

// The accepted loops as global-graph factors (node = keyframe index), their covariance with the
// config's floors added; `index_out` gets each one's position in detection.candidates.
std::vector<fusion::GraphLoop> acceptedGraphLoops(const LoopDetection& detection,
                                                  const LoopConfig& config,
                                                  std::vector<std::size_t>& index_out);

}  // namespace gvio::mapping
