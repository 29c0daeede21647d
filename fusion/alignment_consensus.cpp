#include "fusion/alignment_consensus.hpp"

#include <algorithm>
#include <limits>
#include <optional>

#include "fusion/vio_enu_alignment.hpp"

namespace gvio::fusion {

double registrationChi2(const Eigen::Isometry3d& T_enu_w, const AlignmentSample& s,
                        double floor_m) {
  const Eigen::Vector3d r = s.p_enu - T_enu_w * s.p_w;
  const double floor2 = floor_m * floor_m;
  const double var_h = s.sigma_h_m * s.sigma_h_m + floor2;
  const double var_v = s.sigma_v_m * s.sigma_v_m + floor2;
  return r.head<2>().squaredNorm() / var_h + r.z() * r.z() / var_v;
}

std::vector<bool> consensusInliers(const std::vector<AlignmentSample>& samples, double gate_chi2,
                                   double floor_m, double min_span_m, std::size_t max_samples) {
  const std::size_t n = samples.size();
  const std::size_t first = n > max_samples ? n - max_samples : 0;
  std::vector<bool> best(n, false);
  std::size_t best_count = 0;
  double best_cost = std::numeric_limits<double>::infinity();
  std::vector<bool> inlier(n);
  for (std::size_t i = first; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      for (std::size_t k = j + 1; k < n; ++k) {
        const std::vector<Eigen::Vector3d> p_w = {samples[i].p_w, samples[j].p_w, samples[k].p_w};
        const std::vector<Eigen::Vector3d> p_enu = {samples[i].p_enu, samples[j].p_enu,
                                                    samples[k].p_enu};
        // A triple whose VIO positions lie within min_span_m of their centre fixes no yaw.
        const std::optional<Eigen::Isometry3d> T =
            alignVioToEnu(p_w, p_enu, AlignmentDof::kYawTranslation, min_span_m / 2.0);
        if (!T) continue;
        std::size_t count = 0;
        double cost = 0.0;
        for (std::size_t m = 0; m < n; ++m) {
          const double chi2 = registrationChi2(*T, samples[m], floor_m);
          inlier[m] = chi2 <= gate_chi2;
          if (inlier[m]) {
            ++count;
            cost += chi2;
          }
        }
        if (count > best_count || (count == best_count && cost < best_cost)) {
          best = inlier;
          best_count = count;
          best_cost = cost;
        }
      }
    }
  }
  return best;
}

}  // namespace gvio::fusion
