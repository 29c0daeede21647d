#include "sim/gnss_error.hpp"

#include <cmath>
#include <numbers>

#include "odometry/error.hpp"

namespace gvio::sim {
namespace {

// Exact discretisation of a first-order Gauss-Markov process over dt: b' = phi b + sqrt(1 - phi^2)
// sigma w with phi = exp(-dt/tau). It keeps the stationary variance sigma^2 for any dt, so gaps
// from outages need no special case.
Eigen::Vector3d propagateBias(const Eigen::Vector3d& bias, double dt_s, const GnssErrorModel& m,
                              Rng& rng) {
  const double phi = std::exp(-dt_s / m.bias_tau_s);
  return phi * bias + std::sqrt(1.0 - phi * phi) * m.bias_m * rng.normal3();
}

// An outlier (multipath, wrong ambiguity): uniform magnitude in a random direction, the vertical
// component halved before normalising because such errors are mostly horizontal.
Eigen::Vector3d outlierError(const GnssErrorModel& m, Rng& rng) {
  Eigen::Vector3d direction = rng.normal3();
  direction.z() *= 0.5;
  return rng.uniform(m.outlier_min_m, m.outlier_max_m) * direction.normalized();
}

void requireNonNegative(double value, const char* name) {
  if (!std::isfinite(value) || value < 0.0) {
    throw InvalidInput(std::string("GNSS noise model: ") + name + " must be finite and >= 0");
  }
}

}  // namespace

std::string toString(GnssNoise noise) {
  switch (noise) {
    case GnssNoise::kNone:
      return "none";
    case GnssNoise::kRtk:
      return "rtk";
    case GnssNoise::kSpp:
      return "spp";
  }
  return "";
}

GnssNoise parseGnssNoise(const std::string& name) {
  if (name == "none") return GnssNoise::kNone;
  if (name == "rtk") return GnssNoise::kRtk;
  if (name == "spp") return GnssNoise::kSpp;
  throw InvalidInput("unknown GNSS noise model '" + name + "' (expected none, rtk or spp)");
}

GnssErrorModel GnssErrorModel::preset(GnssNoise noise) {
  GnssErrorModel m;
  switch (noise) {
    case GnssNoise::kNone:
      // Exact positions, yet tiny positive sigmas: readers reject non-positive ones.
      m.reported_sigma_h_m = 0.01;
      m.reported_sigma_v_m = 0.02;
      m.quality = 4;
      m.hdop_min = 0.6, m.hdop_max = 0.9, m.sats_min = 14, m.sats_max = 20;
      break;
    case GnssNoise::kRtk:
      m.white_h_m = m.reported_sigma_h_m = 0.02;
      m.white_v_m = m.reported_sigma_v_m = 0.04;
      m.quality = 4;  // RTK fixed
      m.hdop_min = 0.6, m.hdop_max = 0.9, m.sats_min = 14, m.sats_max = 20;
      break;
    case GnssNoise::kSpp:
      m.white_h_m = m.reported_sigma_h_m = 1.5;
      m.white_v_m = m.reported_sigma_v_m = 3.0;
      m.bias_m = 1.0;
      m.outlier_probability = 0.01;
      m.quality = 1;
      m.hdop_min = 0.8, m.hdop_max = 2.0, m.sats_min = 7, m.sats_max = 12;
      break;
  }
  return m;
}

void GnssErrorModel::validate() const {
  requireNonNegative(white_h_m, "white_h_m");
  requireNonNegative(white_v_m, "white_v_m");
  requireNonNegative(bias_m, "bias_m");
  requireNonNegative(outlier_min_m, "outlier_min_m");
  if (!std::isfinite(bias_tau_s) || bias_tau_s <= 0.0) {
    throw InvalidInput("GNSS noise model: bias_tau_s must be finite and > 0");
  }
  if (!(outlier_probability >= 0.0 && outlier_probability <= 1.0)) {
    throw InvalidInput("GNSS noise model: outlier_probability must be in [0, 1]");
  }
  if (!std::isfinite(outlier_max_m) || outlier_max_m < outlier_min_m) {
    throw InvalidInput("GNSS noise model: outlier_max_m must be finite and >= outlier_min_m");
  }
  for (const double sigma : {reported_sigma_h_m, reported_sigma_v_m}) {
    if (!std::isfinite(sigma) || sigma <= 0.0) {
      throw InvalidInput("GNSS noise model: reported_sigma_h_m and reported_sigma_v_m must be > 0");
    }
  }
}

GnssErrorProcess::GnssErrorProcess(const GnssErrorModel& model, std::uint64_t seed,
                                   std::int64_t t0_ns)
    : model_(model), rng_(seed), t_ns_(t0_ns) {
  // Draw order (phase, then bias) is part of the simulator's byte-identical output per seed.
  phase_ = rng_.uniform(0.0, 2.0 * std::numbers::pi);
  bias_ = model_.bias_m * rng_.normal3();  // the stationary distribution
}

Eigen::Vector3d GnssErrorProcess::draw(std::int64_t t_ns, bool& outlier) {
  Eigen::Vector3d error = Eigen::Vector3d::Zero();
  if (model_.bias_m > 0.0) {
    const double dt_s = static_cast<double>(t_ns - t_ns_) * 1e-9;
    bias_ = propagateBias(bias_, dt_s, model_, rng_);
    error += bias_;
  }
  t_ns_ = t_ns;
  if (model_.white_h_m > 0.0 || model_.white_v_m > 0.0) {
    const Eigen::Vector3d sigma(model_.white_h_m, model_.white_h_m, model_.white_v_m);
    error += rng_.normal3().cwiseProduct(sigma);
  }
  outlier = model_.outlier_probability > 0.0 && rng_.uniform() < model_.outlier_probability;
  if (outlier) error += outlierError(model_, rng_);
  return error;
}

void reportAs(GnssFix& fix, const fusion::Lla& lla, const GnssErrorModel& model) {
  fix.lat_deg = lla.lat_deg;
  fix.lon_deg = lla.lon_deg;
  fix.h_ellipsoid_m = lla.h_ellipsoid_m;
  fix.sigma_h_m = model.reported_sigma_h_m;
  fix.sigma_v_m = model.reported_sigma_v_m;
  fix.quality = model.quality;
}

DegradedFixes degradeFixes(const std::vector<GnssFix>& fixes, const GnssErrorModel& model,
                           std::uint64_t seed) {
  model.validate();
  DegradedFixes out;
  if (fixes.empty()) return out;
  const fusion::EnuFrame enu(
      {fixes.front().lat_deg, fixes.front().lon_deg, fixes.front().h_ellipsoid_m});
  GnssErrorProcess process(model, seed, fixes.front().t_ns);
  for (const GnssFix& fix : fixes) {
    bool outlier = false;
    const Eigen::Vector3d error = process.draw(fix.t_ns, outlier);
    const fusion::Lla lla =
        enu.toLla(enu.toEnu({fix.lat_deg, fix.lon_deg, fix.h_ellipsoid_m}) + error);
    GnssFix degraded = fix;
    reportAs(degraded, lla, model);
    out.fixes.push_back(degraded);
    out.added_error_enu.push_back(error);
    out.outliers += outlier ? 1 : 0;
  }
  return out;
}

}  // namespace gvio::sim
