#pragma once
// Which VIO-ENU position pairs agree on one registration. A least-squares registration follows a
// burst of gross GNSS outliers (multipath in a street canyon, a receiver jumping by a kilometre,
// spoofing) wherever it goes, and the chi-square gate then rejects every good fix after it. So
// when the least-squares registration leaves a pair outside the gate, registrations are
// hypothesised from triples of pairs (RANSAC, Fischler & Bolles 1981, here exhaustive over the
// triples, so deterministic) and the largest set of pairs one of them explains is kept.
#include <Eigen/Geometry>
#include <cstddef>
#include <vector>

namespace gvio::fusion {

struct AlignmentSample {
  Eigen::Vector3d p_w;    // the antenna in the VIO world
  Eigen::Vector3d p_enu;  // the fix
  double sigma_h_m = 1.0, sigma_v_m = 1.0;
};

// Squared residual of `s` under T_enu_w, normalised per axis by the fix's sigma inflated in
// quadrature by `floor_m` (the VIO's own error over the registration span).
double registrationChi2(const Eigen::Isometry3d& T_enu_w, const AlignmentSample& s, double floor_m);

// The inlier flags of the largest consensus: over every triple among the last `max_samples`
// samples whose VIO positions span >= `min_span_m`, the yaw + translation registration of the
// triple, and the samples within `gate_chi2` of it. Ties go to the smaller sum of inlier chi2.
// Samples before the last `max_samples` are judged by the winning registration too. All false
// when no triple spans enough.
std::vector<bool> consensusInliers(const std::vector<AlignmentSample>& samples, double gate_chi2,
                                   double floor_m, double min_span_m = 2.0,
                                   std::size_t max_samples = 30);

}  // namespace gvio::fusion
