#pragma once
// Screening of GNSS fixes before fusion (issue 7, bad input): fixes with NaN, zero or negative
// sigma, latitude/longitude out of range, or stamps far outside the drive are skipped and counted,
// never fatal and never used.
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "odometry/measurements.hpp"

namespace gvio::fusion {

// A latitude/longitude no place on Earth has: |lat| > 90 deg or |lon| > 180 deg. NaN is not out
// of range here (every caller checks finiteness on its own, and counts it apart).
[[nodiscard]] inline bool latLonOutOfRange(double lat_deg, double lon_deg) {
  return std::abs(lat_deg) > 90.0 || std::abs(lon_deg) > 180.0;
}

struct ScreeningCounts {
  int kept = 0;
  int non_finite = 0;     // NaN or infinite position or sigma
  int bad_sigma = 0;      // sigma <= 0
  int out_of_range = 0;   // |lat| > 90 or |lon| > 180
  int outside_drive = 0;  // further than the margin before the first / after the last frame
  int out_of_order = 0;   // stamp not after the previous kept fix

  [[nodiscard]] int skipped() const {
    return non_finite + bad_sigma + out_of_range + outside_drive + out_of_order;
  }
  // "3 skipped: 1 NaN, 2 outside the drive" (empty when nothing was skipped).
  [[nodiscard]] std::string summary() const;
};

struct ScreeningResult {
  std::vector<GnssFix> fixes;  // the usable fixes, in time order
  ScreeningCounts counts;
};

// drive_begin_ns / drive_end_ns: span of the camera (or IMU) data; fixes further than margin_ns
// outside it are skipped.
ScreeningResult screenFixes(const std::vector<GnssFix>& fixes, std::int64_t drive_begin_ns,
                            std::int64_t drive_end_ns, std::int64_t margin_ns = 1'000'000'000);

}  // namespace gvio::fusion
