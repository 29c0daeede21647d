#pragma once
// The GNSS receiver error models of the simulator (none | rtk | spp, or one read from a file) as a
// random process over time, shared by `gvio simulate` (fixes from a true trajectory) and
// `gvio run --gnss-noise` (degrading an accurate recorded source, e.g. KITTI's RTK-grade OXTS, to
// reproduce the reference experiment's SPP-grade GNSS on a real drive).
#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "fusion/geodesy.hpp"
#include "odometry/measurements.hpp"
#include "sim/rng.hpp"

namespace gvio::sim {

enum class GnssNoise { kNone, kRtk, kSpp };
GnssNoise parseGnssNoise(const std::string& name);  // none|rtk|spp; throws InvalidInput
std::string toString(GnssNoise noise);

// One receiver error model, all values 1-sigma in metres.
struct GnssErrorModel {
  double white_h_m = 0.0;  // white noise per horizontal axis (east, north)
  double white_v_m = 0.0;  // white noise, up
  double bias_m = 0.0;     // steady-state sigma of the Gauss-Markov bias per axis (0: no bias)
  double bias_tau_s = 60.0;
  double outlier_probability = 0.0;
  double outlier_min_m = 5.0, outlier_max_m = 30.0;
  // What the receiver reports: it knows its white noise, not the bias or the outliers.
  double reported_sigma_h_m = 0.0, reported_sigma_v_m = 0.0;
  int quality = 1;  // GGA fix quality (1 SPP, 4 RTK fixed)
  double hdop_min = 0.0, hdop_max = 0.0;
  int sats_min = 0, sats_max = 0;

  // The presets: rtk 2 cm h / 4 cm v white; spp 1.5 m h / 3 m v white + a Gauss-Markov
  // bias of 1 m per axis (tau 60 s) + 1 % outliers of 5-30 m; none: exact, tiny positive sigmas.
  static GnssErrorModel preset(GnssNoise noise);
  void validate() const;  // throws InvalidInput naming the field
};

// The error of successive fixes: Gauss-Markov bias + white noise + rare outliers.
class GnssErrorProcess {
 public:
  // The bias starts from its stationary distribution at t0_ns.
  GnssErrorProcess(const GnssErrorModel& model, std::uint64_t seed, std::int64_t t0_ns);

  // Error (reported - true, ENU metres) of the fix at t_ns (non-decreasing); sets `outlier`.
  Eigen::Vector3d draw(std::int64_t t_ns, bool& outlier);
  // Random phase of the slow HDOP / satellite-count variation.
  [[nodiscard]] double geometryPhase() const { return phase_; }

 private:
  GnssErrorModel model_;
  Rng rng_;
  double phase_ = 0.0;
  Eigen::Vector3d bias_ = Eigen::Vector3d::Zero();
  std::int64_t t_ns_ = 0;
};

// Sets what a receiver of this model reports for a fix at `lla`: the position, the model's sigmas
// and fix quality (time, HDOP and satellites are left as they are).
void reportAs(GnssFix& fix, const fusion::Lla& lla, const GnssErrorModel& model);

struct DegradedFixes {
  std::vector<GnssFix> fixes;
  std::vector<Eigen::Vector3d> added_error_enu;  // per fix, in the ENU frame at the first fix
  int outliers = 0;
};

// Adds the model's error to each (accurate) fix and reports the model's sigmas and quality in
// place of the receiver's. Errors are drawn in the local ENU frame of the first fix.
DegradedFixes degradeFixes(const std::vector<GnssFix>& fixes, const GnssErrorModel& model,
                           std::uint64_t seed);

}  // namespace gvio::sim
