#pragma once
// Position errors split the way GNSS users read them: horizontal (east-north) and vertical, over
// all associated epochs and per quality flag of the estimate's epochs (RTK fixed, float, DGPS,
// single, ...). Needs the evaluation's frame to be local ENU (z up): `gvio eval` computes these
// when either side is a geodetic track.
#include <map>
#include <optional>
#include <vector>

#include "eval/evaluate.hpp"

namespace gvio::eval {

struct AxisStats {
  Stats stats;
  double p95 = 0.0;  // numpy.percentile's default (linear between order statistics)
};

struct PositionErrors {
  std::vector<double> horizontal_m, vertical_m;  // per associated pose; vertical signed est - ref
  AxisStats horizontal, vertical;                // vertical of |est - ref|
};

PositionErrors positionErrors(const EvalResult& r);

// quality -> the errors of the associated poses whose estimate epoch has that quality; empty when
// `est_quality` is (the estimate states none). `est_quality` is indexed like the estimate.
std::map<int, PositionErrors> positionErrorsByQuality(const EvalResult& r,
                                                      const std::vector<int>& est_quality);

}  // namespace gvio::eval
