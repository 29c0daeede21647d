#include "fusion/gnss_screening.hpp"

#include <cmath>

namespace gvio::fusion {
namespace {

void append(std::string& out, int n, const char* what) {
  if (n == 0) return;
  out += (out.empty() ? "" : ", ") + std::to_string(n) + " " + what;
}

}  // namespace

std::string ScreeningCounts::summary() const {
  if (skipped() == 0) return "";
  std::string parts;
  append(parts, non_finite, "not finite");
  append(parts, bad_sigma, "with sigma <= 0");
  append(parts, out_of_range, "with lat/lon out of range");
  append(parts, outside_drive, "outside the drive's time span");
  append(parts, out_of_order, "out of time order");
  return std::to_string(skipped()) + " skipped: " + parts;
}

ScreeningResult screenFixes(const std::vector<GnssFix>& fixes, std::int64_t drive_begin_ns,
                            std::int64_t drive_end_ns, std::int64_t margin_ns) {
  ScreeningResult out;
  ScreeningCounts& c = out.counts;
  for (const GnssFix& f : fixes) {
    if (!std::isfinite(f.lat_deg) || !std::isfinite(f.lon_deg) || !std::isfinite(f.h_ellipsoid_m) ||
        !std::isfinite(f.sigma_h_m) || !std::isfinite(f.sigma_v_m)) {
      ++c.non_finite;
    } else if (!(f.sigma_h_m > 0.0) || !(f.sigma_v_m > 0.0)) {
      ++c.bad_sigma;
    } else if (latLonOutOfRange(f.lat_deg, f.lon_deg)) {
      ++c.out_of_range;
    } else if (f.t_ns < drive_begin_ns - margin_ns || f.t_ns > drive_end_ns + margin_ns) {
      ++c.outside_drive;
    } else if (!out.fixes.empty() && f.t_ns <= out.fixes.back().t_ns) {
      ++c.out_of_order;
    } else {
      out.fixes.push_back(f);
      ++c.kept;
    }
  }
  return out;
}

}  // namespace gvio::fusion
