#pragma once
// loops.csv in a run folder: every loop-closure candidate the run examined and what became of it.
// One header line, then one row per candidate:
//   query_t_s,candidate_t_s,distance_m,search_radius_m,matches,inliers,reprojection_px,
//   correction_m,correction_deg,verdict,reason
// Stamps are seconds with 9 decimals (the int64 nanoseconds exactly); a quantity that was not
// measured is "nan" (pandas and Python's float() read it); verdict is accepted or rejected.
#include <cstdint>
#include <filesystem>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

namespace gvio::io {

struct LoopCsvRow {
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  std::int64_t query_t_ns = 0;      // the newer keyframe
  std::int64_t candidate_t_ns = 0;  // the older keyframe it was matched against
  double distance_m = kNaN;         // distance between the two keyframes predicted before the loop
  double search_radius_m = kNaN;    // the candidate search radius used for this query
  int matches = 0;                  // descriptor matches (after the ratio test)
  int inliers = 0;                  // PnP-RANSAC inliers (0 when not run)
  double reprojection_px = kNaN;    // mean reprojection error of the inliers (NaN when not run)
  double correction_m = kNaN;       // translation of the measured relative pose against the prior's
  double correction_deg = kNaN;     // rotation angle of the same (NaN when not verified)
  bool accepted = false;
  std::string reason;  // "ok" when accepted; else a short [a-z_]+ token (few_inliers, ...)
};

inline constexpr std::string_view kLoopsCsvHeader =
    "query_t_s,candidate_t_s,distance_m,search_radius_m,matches,inliers,reprojection_px,"
    "correction_m,correction_deg,verdict,reason";

// Writes the rows atomically (io::writeTextAtomic). Non-finite quantities are written as "nan"
// (not measured). Throws std::invalid_argument for a row the reader would reject (negative
// count, reason not a [a-z_]+ token or not "ok" exactly when accepted): a bug in the caller.
void writeLoopsCsv(const std::filesystem::path& file, const std::vector<LoopCsvRow>& rows);
// One row as writeLoopsCsv writes it (no newline), for files that add columns before it.
std::string loopsCsvLine(const LoopCsvRow& row);

// Reads the file strictly: the exact header, 11 fields per row, numbers (or "nan" for the
// quantities), counts >= 0, verdict accepted|rejected, reason "ok" exactly when accepted and a
// [a-z_]+ token otherwise. Blank lines are skipped; a header-only file holds no rows. Throws
// InputError "file:line: ..." on anything else.
std::vector<LoopCsvRow> readLoopsCsv(const std::filesystem::path& file);

}  // namespace gvio::io
