#pragma once
// Which views of a drive the image check flags (gvio consistency --images), from their scores
// (mapping/image_consistency.hpp) alone: how well a correct map matches its image varies with the
// world's texture and depth, slowly along a drive, and with how near the drawn map is, so a view
// is flagged for a dip below what is typical of its stretch of the drive (or of the whole drive)
// and of the views drawn as near as it, measured in their own spread and the view's own standard
// error: a fault stands out whatever the world looks like, and a view
// with little support (few patches) needs a larger dip to be flagged. The rule and its parameters
// are ImageConsistencyConfig's. No file I/O.
#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include "mapping/image_consistency.hpp"

namespace gvio::mapping {

// What the flag rule found for one score over a drive.
struct ScoreThresholds {
  double median = std::numeric_limits<double>::quiet_NaN();    // of the whole drive
  double tau = std::numeric_limits<double>::quiet_NaN();       // spread of correct views, beyond se
  double z_spread = std::numeric_limits<double>::quiet_NaN();  // of the standardised residuals
  // per view: what is typical of it, the median it is compared with plus the shift of the views
  // drawn as near (NaN: none)
  std::vector<double> reference;
  std::vector<double> below;  // per view: flagged below this (-inf: not judged)
  std::vector<double> z;      // per view: standardised residual (NaN: not judged)
};

// Why a view is or is not flagged.
enum class ViewStatus { kOk, kFlagged, kNotEnoughEvidence };
const char* toString(ViewStatus status);  // "ok", "flagged", "not_enough_evidence"

struct FlaggedViews {
  std::vector<bool> flagged;        // per view
  std::vector<ViewStatus> status;   // per view
  std::vector<std::string> reason;  // per view: the score, threshold and support behind a flag
  ScoreThresholds ncc, depth;
};

// t_s: the views' times (s), ascending. Unscored values never flag; a view with neither score
// scored, or in a drive with too few scored views to know what is typical, is "not enough
// evidence".
[[nodiscard]] FlaggedViews flagOutliers(const std::vector<ViewScore>& views,
                                        const std::vector<double>& t_s,
                                        const ImageConsistencyConfig& config);

struct ViewStretch {
  std::size_t first = 0, last = 0;  // view indices, inclusive
};

// Runs of flagged views, joined across gaps of at most max_gap unflagged views.
[[nodiscard]] std::vector<ViewStretch> flaggedStretches(const std::vector<bool>& flagged,
                                                        std::size_t max_gap = 1);

}  // namespace gvio::mapping
