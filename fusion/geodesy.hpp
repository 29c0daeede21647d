#pragma once
// WGS84 geodesy through GeographicLib: geodetic (lat, lon, ellipsoidal h) <-> ECEF <-> local ENU.
#include <Eigen/Core>

namespace gvio::fusion {

struct Lla {
  double lat_deg = 0.0;
  double lon_deg = 0.0;
  double h_ellipsoid_m = 0.0;
};

Eigen::Vector3d llaToEcef(const Lla& lla);
Lla ecefToLla(const Eigen::Vector3d& p_ecef);

// A local east-north-up frame tangent to the ellipsoid at `origin` (GeographicLib::LocalCartesian,
// exact, not a flat-earth approximation).
class EnuFrame {
 public:
  explicit EnuFrame(const Lla& origin);

  [[nodiscard]] const Lla& origin() const { return origin_; }
  [[nodiscard]] Eigen::Vector3d toEnu(const Lla& lla) const;
  [[nodiscard]] Lla toLla(const Eigen::Vector3d& p_enu) const;

 private:
  Lla origin_;
  Eigen::Vector3d origin_ecef_;
  Eigen::Matrix3d R_enu_ecef_;
};

// True when lat/lon/h are finite and lat in [-90, 90], lon in [-180, 180].
bool isValidLla(const Lla& lla);

}  // namespace gvio::fusion
