#pragma once
// A real receiver's errors replayed on a simulated drive (gvio simulate --gnss-errors-from SOL):
// at each epoch the receiver solved, its error is the fix minus the reference trajectory at that
// instant (in the local ENU frame of the reference), and the simulated fix is the simulated
// antenna's true position plus that error, reported with the receiver's own sigmas, quality flag
// and satellite count. Epochs it did not solve stay gaps: real SPP in a city has long ones.
// Interpolating the reference between its epochs (linearly; a 5 Hz GNSS/INS reference moves < 4 m
// between epochs at 70 km/h and curves by centimetres) is only done across gaps of at most
// max_reference_gap_ns; fixes outside the reference or in a larger gap are dropped and counted.
#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <vector>

#include "fusion/geodesy.hpp"
#include "odometry/measurements.hpp"
#include "sim/gnss_synth.hpp"

namespace gvio::sim {

struct RealGnssError {
  GnssFix fix;                // as the receiver reported it
  Eigen::Vector3d error_enu;  // fix - reference, in the reference's ENU frame
};

struct RealGnssErrors {
  std::vector<RealGnssError> errors;
  std::size_t outside_reference = 0;  // fixes before or after the reference
  std::size_t in_reference_gap = 0;   // fixes where the reference has a gap
};

// `reference_t_ns` strictly increasing, `reference_enu` its positions in `enu`.
RealGnssErrors realGnssErrors(const std::vector<GnssFix>& solution,
                              const std::vector<std::int64_t>& reference_t_ns,
                              const std::vector<Eigen::Vector3d>& reference_enu,
                              const fusion::EnuFrame& enu,
                              std::int64_t max_reference_gap_ns = 1'000'000'000);

// The replayed fixes within [t0_ns, t1_ns], outside the outages: the antenna (lever arm
// lever_arm_b in the body) plus each epoch's real error. Errors taken in one ENU frame are used in
// the simulator's: both are local tangent frames, the same one when the simulator's origin is the
// reference's (gvio simulate sets it so).
std::vector<GnssSimFix> replayGnss(const std::function<Eigen::Isometry3d(std::int64_t)>& T_w_b_at,
                                   std::int64_t t0_ns, std::int64_t t1_ns,
                                   const fusion::EnuFrame& enu, const GnssSimOptions& options,
                                   const RealGnssErrors& errors);

}  // namespace gvio::sim
