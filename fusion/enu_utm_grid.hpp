#pragma once
// Local ENU -> UTM (easting, northing, ellipsoidal height) for millions of map points: the exact
// conversion (EnuFrame::toLla, then GeographicLib's transverse Mercator in a fixed zone) costs
// about a microsecond a point, so it is evaluated only at the corners of a grid over the ENU
// plane (at up = 0 and up = kUpStepM) and interpolated bilinearly in east/north, linearly in up.
// The mapping is smooth at the grid's scale: the largest second derivative is the Earth's
// curvature in height (1/R), so a cell of c metres errs by at most c^2 / (8 R) = 0.2 mm for
// c = 100 m (the test checks 1 mm over +-5 km).
#include <climits>
#include <cstdint>
#include <unordered_map>

#include <Eigen/Core>

#include "fusion/geodesy.hpp"

namespace gvio::fusion {

class EnuToUtmGrid {
 public:
  // Points south of the equator in a northern-zone grid (or the reverse) keep the zone's false
  // northing (northing -/+ 10 000 km), as one LAS file of a whole map needs.
  EnuToUtmGrid(const Lla& enu_origin, int zone, bool north, double cell_m = 100.0);

  // Not const: corners are computed on first use and kept (a grid per thread). NaN for a
  // non-finite point.
  [[nodiscard]] Eigen::Vector3d toUtm(const Eigen::Vector3d& p_enu);
  // The exact conversion, for the corners and for tests.
  [[nodiscard]] Eigen::Vector3d exactUtm(const Eigen::Vector3d& p_enu) const;

  static constexpr double kUpStepM = 100.0;

 private:
  struct Corner {
    Eigen::Vector3d at0;     // UTM of (e, n, 0)
    Eigen::Vector3d per_up;  // d(UTM)/d(up), per metre
  };
  const Corner& corner(std::int64_t i, std::int64_t j);

  EnuFrame enu_;
  int zone_;
  bool north_;
  double cell_m_;
  std::unordered_map<std::uint64_t, Corner> corners_;
  // The previous point's cell and its four corners (neighbouring points mostly share a cell).
  std::int64_t last_i_ = INT64_MIN, last_j_ = INT64_MIN;
  const Corner* last_[4] = {nullptr, nullptr, nullptr, nullptr};
};

}  // namespace gvio::fusion
