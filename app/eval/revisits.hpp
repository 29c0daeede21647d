#pragma once
// Revisit consistency: when the reference passes one place twice (at least min_separation apart
// in time, within radius_m of each other), the estimate should put the two passes at the same
// relative position. Its error there, |(p_est_j - p_est_i) - (p_ref_j - p_ref_i)|, is what doubles
// facades and leaves ghost walls in a map built from the estimate. Pure computation, no I/O.
#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include "eval/metrics.hpp"

namespace gvio::eval {

struct RevisitOptions {
  double radius_m = 0.0;                              // > 0, finite
  std::int64_t min_separation_ns = 30'000'000'000LL;  // >= 0
};

struct RevisitPair {
  std::size_t i = 0, j = 0;  // indices into the associated poses, i < j
  std::int64_t t_i_ns = 0, t_j_ns = 0;
  double ref_distance_m = 0.0;  // |p_ref_j - p_ref_i| <= radius_m
  double error_m = 0.0;         // |(p_est_j - p_est_i) - (p_ref_j - p_ref_i)|
};

struct RevisitStats {
  Stats stats;  // evo's statistics of the pair errors (computeStats)
  // 95th percentile with linear interpolation between order statistics, at rank (n - 1) * 0.95
  // (numpy.percentile's default; the same definition as `median`).
  double p95 = 0.0;
};

struct RevisitResult {
  RevisitOptions options;
  std::vector<RevisitPair> pairs;     // sorted by (i, j)
  std::optional<RevisitStats> stats;  // none when no pair qualifies
};

// Every index pair (i, j), i < j, with |t_j - t_i| >= min_separation_ns and
// |p_ref[j] - p_ref[i]| <= radius_m, sorted by (i, j). A uniform grid of cell size radius_m over
// the positions keeps it near O(n + pairs); with nondecreasing stamps (every associated
// trajectory) the poses closer in time than the separation are skipped by binary search too.
// Throws InvalidInput on a bad radius or separation, unequal lengths, a non-finite position, or
// positions too far out for the radius (more than 2^53 cells from the origin).
std::vector<std::pair<std::size_t, std::size_t>> revisitPairs(
    const std::vector<Eigen::Vector3d>& p_ref, const std::vector<std::int64_t>& t_ns,
    double radius_m, std::int64_t min_separation_ns);

// The revisit pairs of the associated reference poses `ref` with stamps `t_ns` and the errors of
// the (already aligned) estimate `est` on them, with their statistics.
RevisitResult computeRevisits(const std::vector<Eigen::Matrix4d>& ref,
                              const std::vector<Eigen::Matrix4d>& est,
                              const std::vector<std::int64_t>& t_ns, const RevisitOptions& options);

}  // namespace gvio::eval
