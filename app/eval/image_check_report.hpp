#pragma once
// The reports of `gvio consistency --images` (cli/consistency_images.hpp): the checked keyframes
// flagged against each other (and, at revisits, against the other passes' map alone, flagged among
// themselves), as keyframes.csv, summary.json and the run's summary line. No file I/O: the CLI
// writes them.
#include <Eigen/Core>
#include <cstddef>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "mapping/view_flags.hpp"
#include "viz/image_check.hpp"

namespace gvio::eval {

struct ImageCheckRow {
  viz::CheckedView view;
  Eigen::Vector3d p_map = Eigen::Vector3d::Zero();  // the camera in the map frame
  bool flagged = false;
};

// Keyframes' own points drawn from their own poses (viz::ImageCheck::selfCheck).
struct ImageCheckSelfCheck {
  std::size_t keyframes = 0;
  double ncc_median = std::numeric_limits<double>::quiet_NaN();
  double depth_median = std::numeric_limits<double>::quiet_NaN();
  bool depth_valid = true;  // false: the depth scores were set aside (not enough evidence)
};

// Every requested keyframe checked, then flagged against the others.
struct ImageCheckResult {
  std::vector<ImageCheckRow> rows;
  std::vector<double> t_s;  // of each row, from the start of the trajectory, ascending
  mapping::FlaggedViews flags;
  std::vector<mapping::ViewStretch> stretches;
  // Against the other passes' map alone, over the rows at a revisit (revisit_rows, ascending).
  std::vector<std::size_t> revisit_rows;
  mapping::FlaggedViews revisit_flags;
  ImageCheckSelfCheck self_check;
};

// Records the self-check's scores; below `min_depth_agreement` (its median) the drawn and stereo
// depths are not comparable on this dataset and every depth score is set aside (NaN) before
// flagging. Call before flagImageCheck.
void applySelfCheck(ImageCheckResult& result, const std::vector<mapping::ViewScore>& self,
                    double min_depth_agreement);

// Flags the rows, their stretches and the revisit scores (flagImageCheck fills everything after
// rows and t_s).
void flagImageCheck(ImageCheckResult& result, const mapping::ImageConsistencyConfig& config);

// keyframes.csv: one row per checked keyframe (the header names every column).
[[nodiscard]] std::string imageCheckCsv(const ImageCheckResult& result);

// summary.json without its "worst" images (the CLI adds those).
[[nodiscard]] nlohmann::json imageCheckSummary(const ImageCheckResult& result,
                                               std::size_t map_keyframes,
                                               const std::filesystem::path& run,
                                               const viz::ImageCheckOptions& options,
                                               std::size_t every);

// The one-line summary the command logs.
[[nodiscard]] std::string imageCheckSummaryLine(const ImageCheckResult& result);

// A score as the CSV writes it ("nan" when not finite).
[[nodiscard]] std::string csvNumber(double v, int decimals);
// ... and as the JSON writes it (null when not finite).
[[nodiscard]] nlohmann::json jsonNumber(double v);

}  // namespace gvio::eval
