#include "sim/gnss_replay.hpp"

#include <algorithm>

#include "odometry/error.hpp"

namespace gvio::sim {

RealGnssErrors realGnssErrors(const std::vector<GnssFix>& solution,
                              const std::vector<std::int64_t>& reference_t_ns,
                              const std::vector<Eigen::Vector3d>& reference_enu,
                              const fusion::EnuFrame& enu, std::int64_t max_reference_gap_ns) {
  if (reference_t_ns.size() != reference_enu.size() || reference_t_ns.size() < 2) {
    throw InvalidInput("real GNSS errors: the reference needs at least 2 epochs");
  }
  RealGnssErrors out;
  for (const GnssFix& fix : solution) {
    const auto after = std::lower_bound(reference_t_ns.begin(), reference_t_ns.end(), fix.t_ns);
    if (after == reference_t_ns.end() || (*after != fix.t_ns && after == reference_t_ns.begin())) {
      ++out.outside_reference;
      continue;
    }
    const auto i = static_cast<std::size_t>(after - reference_t_ns.begin());
    Eigen::Vector3d p_ref = reference_enu[i];
    if (*after != fix.t_ns) {
      const std::int64_t t0 = reference_t_ns[i - 1], t1 = reference_t_ns[i];
      if (t1 - t0 > max_reference_gap_ns) {
        ++out.in_reference_gap;
        continue;
      }
      const double a = static_cast<double>(fix.t_ns - t0) / static_cast<double>(t1 - t0);
      p_ref = (1.0 - a) * reference_enu[i - 1] + a * reference_enu[i];
    }
    const Eigen::Vector3d p_fix = enu.toEnu({fix.lat_deg, fix.lon_deg, fix.h_ellipsoid_m});
    out.errors.push_back({fix, p_fix - p_ref});
  }
  return out;
}

std::vector<GnssSimFix> replayGnss(const std::function<Eigen::Isometry3d(std::int64_t)>& T_w_b_at,
                                   std::int64_t t0_ns, std::int64_t t1_ns,
                                   const fusion::EnuFrame& enu, const GnssSimOptions& options,
                                   const RealGnssErrors& errors) {
  std::vector<GnssSimFix> fixes;
  for (const RealGnssError& e : errors.errors) {
    const std::int64_t t = e.fix.t_ns;
    if (t < t0_ns || t > t1_ns) continue;
    const bool out = std::any_of(options.outages_ns.begin(), options.outages_ns.end(),
                                 [&](const auto& o) { return t >= o.first && t <= o.second; });
    if (out) continue;
    GnssSimFix sim;
    sim.p_enu_true = T_w_b_at(t) * options.lever_arm_b;
    sim.error_enu = e.error_enu;
    sim.fix = e.fix;
    const fusion::Lla lla = enu.toLla(sim.p_enu_true + sim.error_enu);
    sim.fix.lat_deg = lla.lat_deg;
    sim.fix.lon_deg = lla.lon_deg;
    sim.fix.h_ellipsoid_m = lla.h_ellipsoid_m;
    fixes.push_back(sim);
  }
  return fixes;
}

}  // namespace gvio::sim
