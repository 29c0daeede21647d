#include "eval/revisits.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <span>
#include <tuple>
#include <unordered_map>

#include "mapping/consistency.hpp"
#include "odometry/error.hpp"

namespace gvio::eval {
namespace {

// Cell coordinates beyond 2^53 would no longer be exact integers in double, and neighbours
// (+-1) could collapse onto one cell.
constexpr double kMaxCell = 9007199254740992.0;

struct Cell {
  std::int64_t x = 0, y = 0, z = 0;
  bool operator==(const Cell&) const = default;
};

struct CellHash {
  std::size_t operator()(const Cell& c) const {
    // Large odd multipliers (as in Teschner et al. 2003, widened to 64 bit) spread neighbouring
    // cells over the buckets.
    const auto ux = static_cast<std::uint64_t>(c.x), uy = static_cast<std::uint64_t>(c.y),
               uz = static_cast<std::uint64_t>(c.z);
    return static_cast<std::size_t>(ux * 73856093ULL ^ uy * 19349663ULL ^ uz * 83492791ULL);
  }
};

// Poses sorted by (cell, index): each cell is one run of increasing indices in `order`.
struct Grid {
  std::vector<std::size_t> order;
  std::unordered_map<Cell, std::pair<std::size_t, std::size_t>, CellHash> runs;  // [begin, end)

  [[nodiscard]] std::span<const std::size_t> at(const Cell& c) const {
    const auto it = runs.find(c);
    if (it == runs.end()) return {};
    return std::span(order).subspan(it->second.first, it->second.second - it->second.first);
  }
};

Cell cellOf(const Eigen::Vector3d& p, double radius_m, std::size_t index) {
  const Eigen::Vector3d c = (p / radius_m).array().floor();
  if (!c.allFinite() || c.cwiseAbs().maxCoeff() > kMaxCell) {
    throw InvalidInput(fmt::format(
        "revisits: reference position {} ({}, {}, {}) is not finite or too far out for a radius "
        "of {} m",
        index, p.x(), p.y(), p.z(), radius_m));
  }
  return {static_cast<std::int64_t>(c.x()), static_cast<std::int64_t>(c.y()),
          static_cast<std::int64_t>(c.z())};
}

Grid buildGrid(const std::vector<Cell>& cells) {
  Grid g;
  g.order.resize(cells.size());
  for (std::size_t k = 0; k < cells.size(); ++k) g.order[k] = k;
  const auto before = [&](std::size_t a, std::size_t b) {
    const Cell &ca = cells[a], &cb = cells[b];
    return std::tie(ca.x, ca.y, ca.z, a) < std::tie(cb.x, cb.y, cb.z, b);
  };
  std::sort(g.order.begin(), g.order.end(), before);
  g.runs.reserve(cells.size());
  for (std::size_t begin = 0; begin < g.order.size();) {
    std::size_t end = begin + 1;
    while (end < g.order.size() && cells[g.order[end]] == cells[g.order[begin]]) ++end;
    g.runs.emplace(cells[g.order[begin]], std::make_pair(begin, end));
    begin = end;
  }
  return g;
}

void validate(const std::vector<Eigen::Vector3d>& p_ref, const std::vector<std::int64_t>& t_ns,
              double radius_m, std::int64_t min_separation_ns) {
  if (!std::isfinite(radius_m) || !(radius_m > 0.0)) {
    throw InvalidInput(fmt::format("revisits: radius must be finite and > 0 (got {})", radius_m));
  }
  if (min_separation_ns < 0) {
    throw InvalidInput(
        fmt::format("revisits: minimum separation must be >= 0 (got {} ns)", min_separation_ns));
  }
  if (t_ns.size() != p_ref.size()) {
    throw InvalidInput(fmt::format(
        "revisits need a timestamp per reference pose ({} poses, {} stamps; a KITTI reference "
        "needs --ref-times)",
        p_ref.size(), t_ns.size()));
  }
}

}  // namespace

std::vector<std::pair<std::size_t, std::size_t>> revisitPairs(
    const std::vector<Eigen::Vector3d>& p_ref, const std::vector<std::int64_t>& t_ns,
    double radius_m, std::int64_t min_separation_ns) {
  validate(p_ref, t_ns, radius_m, min_separation_ns);
  std::vector<Cell> cells;
  cells.reserve(p_ref.size());
  for (std::size_t k = 0; k < p_ref.size(); ++k) cells.push_back(cellOf(p_ref[k], radius_m, k));
  const Grid grid = buildGrid(cells);
  // In a cell's run, indices increase, so with nondecreasing stamps so do the stamps: the poses
  // too close in time to i form a prefix that a binary search skips.
  const bool stamps_sorted = std::is_sorted(t_ns.begin(), t_ns.end());
  const double radius2 = radius_m * radius_m;

  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  std::vector<std::size_t> found;
  for (std::size_t i = 0; i < p_ref.size(); ++i) {
    found.clear();
    const std::int64_t t_i = t_ns[i];
    for (std::int64_t dx = -1; dx <= 1; ++dx) {
      for (std::int64_t dy = -1; dy <= 1; ++dy) {
        for (std::int64_t dz = -1; dz <= 1; ++dz) {
          const std::span<const std::size_t> run =
              grid.at({cells[i].x + dx, cells[i].y + dy, cells[i].z + dz});
          auto first = std::upper_bound(run.begin(), run.end(), i);
          if (stamps_sorted) {
            first = std::partition_point(
                first, run.end(), [&](std::size_t j) { return t_ns[j] - t_i < min_separation_ns; });
          }
          for (auto it = first; it != run.end(); ++it) {
            const std::size_t j = *it;
            if (!stamps_sorted && std::abs(t_ns[j] - t_i) < min_separation_ns) continue;
            if ((p_ref[j] - p_ref[i]).squaredNorm() <= radius2) found.push_back(j);
          }
        }
      }
    }
    std::sort(found.begin(), found.end());
    for (const std::size_t j : found) pairs.emplace_back(i, j);
  }
  return pairs;
}

RevisitResult computeRevisits(const std::vector<Eigen::Matrix4d>& ref,
                              const std::vector<Eigen::Matrix4d>& est,
                              const std::vector<std::int64_t>& t_ns,
                              const RevisitOptions& options) {
  if (est.size() != ref.size()) {
    throw InvalidInput(
        fmt::format("revisits: {} reference poses but {} estimated", ref.size(), est.size()));
  }
  std::vector<Eigen::Vector3d> p_ref, p_est;
  p_ref.reserve(ref.size());
  p_est.reserve(est.size());
  for (std::size_t k = 0; k < ref.size(); ++k) {
    p_ref.emplace_back(ref[k].topRightCorner<3, 1>());
    p_est.emplace_back(est[k].topRightCorner<3, 1>());
  }
  RevisitResult result;
  result.options = options;
  std::vector<double> errors;
  for (const auto& [i, j] :
       revisitPairs(p_ref, t_ns, options.radius_m, options.min_separation_ns)) {
    const Eigen::Vector3d d_ref = p_ref[j] - p_ref[i], d_est = p_est[j] - p_est[i];
    result.pairs.push_back({i, j, t_ns[i], t_ns[j], d_ref.norm(), (d_est - d_ref).norm()});
    errors.push_back(result.pairs.back().error_m);
  }
  if (!errors.empty()) {
    RevisitStats s;
    s.stats = computeStats(errors);
    s.p95 = mapping::percentile(errors, 0.95);  // reorders `errors`, used last
    result.stats = s;
  }
  return result;
}

}  // namespace gvio::eval
