#include "eval/position_errors.hpp"

#include <cmath>

#include "mapping/consistency.hpp"

namespace gvio::eval {
namespace {

AxisStats axisStats(std::vector<double> errors) {
  AxisStats s;
  s.stats = computeStats(errors);
  s.p95 = mapping::percentile(errors, 0.95);  // reorders `errors`: its own copy
  return s;
}

PositionErrors fromIndices(const EvalResult& r, const std::vector<std::size_t>& indices) {
  PositionErrors e;
  std::vector<double> vertical_abs;
  for (const std::size_t i : indices) {
    const Eigen::Vector3d d = r.est[i].topRightCorner<3, 1>() - r.ref[i].topRightCorner<3, 1>();
    e.horizontal_m.push_back(std::hypot(d.x(), d.y()));
    e.vertical_m.push_back(d.z());
    vertical_abs.push_back(std::abs(d.z()));
  }
  e.horizontal = axisStats(e.horizontal_m);
  e.vertical = axisStats(vertical_abs);
  return e;
}

}  // namespace

PositionErrors positionErrors(const EvalResult& r) {
  std::vector<std::size_t> all(r.ref.size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
  return fromIndices(r, all);
}

std::map<int, PositionErrors> positionErrorsByQuality(const EvalResult& r,
                                                      const std::vector<int>& est_quality) {
  std::map<int, std::vector<std::size_t>> groups;
  if (est_quality.empty()) return {};
  for (std::size_t i = 0; i < r.est_index.size(); ++i) {
    groups[est_quality.at(r.est_index[i])].push_back(i);
  }
  std::map<int, PositionErrors> out;
  for (const auto& [quality, indices] : groups) out.emplace(quality, fromIndices(r, indices));
  return out;
}

}  // namespace gvio::eval
