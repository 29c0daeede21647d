#pragma once
// How much of its input a run's trajectory covers. A run whose estimator started late (a VIO
// that initialised near the end, GNSS/INS that found no heading until the robot had nearly
// stopped) still writes a trajectory and exits 0, but it is not the drive the user asked for:
// report.json says "partial" instead of "complete" and the summary line says how much is missing.
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace gvio::run {

// A trajectory covering less than this share of its input's time span, and missing more than
// kAllowedMissingS of it, is partial: an estimator's own start (a VIO initialises in 1-3 s) does
// not make a short drive partial, a GNSS/INS that waits minutes for its heading does.
inline constexpr double kCompleteCoverage = 0.5;
inline constexpr double kAllowedMissingS = 5.0;

struct Coverage {
  double input_s = 0.0;   // first to last input stamp (frames, or IMU samples without a camera)
  double output_s = 0.0;  // first to last pose written
  [[nodiscard]] double fraction() const { return input_s > 0.0 ? output_s / input_s : 1.0; }
  [[nodiscard]] bool partial() const {
    return fraction() < kCompleteCoverage && input_s - output_s > kAllowedMissingS;
  }
};

// `input_t_ns` and `output_t_ns` in time order (either may be empty: no output is no coverage).
Coverage coverageOf(const std::vector<std::int64_t>& input_t_ns,
                    const std::vector<std::int64_t>& output_t_ns);

// "complete" or "partial".
std::string runStatus(const Coverage& c);

// report.json's "coverage": input and output spans (s) and their ratio.
nlohmann::json coverageJson(const Coverage& c);

// ", partial: the trajectory covers 5.0 s of the input's 395.0 s (1.3 %)", or "" when complete.
std::string partialNote(const Coverage& c);

}  // namespace gvio::run
