#pragma once
// Simulated GNSS fixes at the antenna (lever arm in the body frame) with the receiver error models
// of the issue: none | rtk (2 cm h, 4 cm v white) | spp (1.5 m h, 3 m v white + first-order
// Gauss-Markov bias, 60 s, 1 m per axis + 1 % outliers of 5-30 m); outages remove fixes.
#include <Eigen/Geometry>
#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "fusion/geodesy.hpp"
#include "odometry/measurements.hpp"
#include "sim/gnss_error.hpp"

namespace gvio::sim {

struct GnssSimOptions {
  GnssNoise noise = GnssNoise::kSpp;
  double rate_hz = 1.0;                                           // 1, 5 or 10
  Eigen::Vector3d lever_arm_b = Eigen::Vector3d::Zero();          // antenna in the body frame
  std::vector<std::pair<std::int64_t, std::int64_t>> outages_ns;  // [t0, t1] without fixes
};

struct GnssSimFix {
  GnssFix fix;                 // what the receiver reports (sigma from the model, HDOP, sats)
  Eigen::Vector3d p_enu_true;  // true antenna position
  Eigen::Vector3d error_enu;   // reported - true, in ENU
  bool outlier = false;
};

// Fixes every 1/rate s over [t0, t1] (on whole multiples of the period since t0).
std::vector<GnssSimFix> synthesizeGnss(
    const std::function<Eigen::Isometry3d(std::int64_t)>& T_w_b_at, std::int64_t t0_ns,
    std::int64_t t1_ns, const fusion::EnuFrame& enu, const GnssSimOptions& options,
    std::uint64_t seed);

// NMEA 0183 log: one GGA and one RMC per fix (valid checksums, HDOP and satellites from the fix).
std::string toNmeaLog(const std::vector<GnssFix>& fixes);
// RTKLIB solution (.pos) as RTKPOST writes it: GPST calendar times, latitude/longitude/ellipsoidal
// height, Q (from the fix's NMEA quality), satellites, sdn, sde and sdne of the fix's ellipse, sdu.
std::string toRtklibPos(const std::vector<GnssFix>& fixes);
// EuRoC-style gnss0/data.csv: "#timestamp [ns],lat_deg,lon_deg,height_m,sigma_h_m,sigma_v_m" (no
// ellipse: its fixes are circles).
std::string toGnssCsv(const std::vector<GnssFix>& fixes);

}  // namespace gvio::sim
