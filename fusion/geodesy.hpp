#pragma once
// WGS84 geodesy through GeographicLib: geodetic (lat, lon, ellipsoidal h) <-> ECEF <-> local ENU.
#include <Eigen/Core>
#include <optional>
#include <string_view>

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
  // ECEF position -> ENU, and the rotation of ECEF vectors into ENU (rows: east, north, up).
  [[nodiscard]] Eigen::Vector3d ecefToEnu(const Eigen::Vector3d& p_ecef) const;
  [[nodiscard]] const Eigen::Matrix3d& R_enu_ecef() const { return R_enu_ecef_; }

 private:
  Lla origin_;
  Eigen::Vector3d origin_ecef_;
  Eigen::Matrix3d R_enu_ecef_;
};

// True when lat/lon/h are finite and lat in [-90, 90], lon in [-180, 180].
bool isValidLla(const Lla& lla);

// "lat,lon,h" (degrees, degrees, ellipsoidal metres; spaces allowed around the numbers); nullopt
// when malformed or out of range.
std::optional<Lla> parseLla(std::string_view text);

// A position in the Universal Transverse Mercator grid (WGS84), for map exports (LAS, GIS).
struct Utm {
  int zone = 0;       // 1..60
  bool north = true;  // hemisphere
  double easting_m = 0.0, northing_m = 0.0;
  int epsg() const { return (north ? 32600 : 32700) + zone; }  // WGS 84 / UTM zone NN N|S
};

// The standard zone of the point (GeographicLib UTMUPS::StandardZone, Norway/Svalbard rules
// included); throws InvalidInput outside the UTM latitude band (-80..84 deg, i.e. UPS regions).
Utm llaToUtm(const Lla& lla);
// Forces a zone (e.g. one zone for a whole map that straddles a boundary).
Utm llaToUtm(const Lla& lla, int zone);
// Forces a zone and the grid of one hemisphere: a point across the equator keeps that grid's
// false northing (northing below 0, or above 10 000 km), so one map stays one continuous grid.
Utm llaToUtm(const Lla& lla, int zone, bool north);
Lla utmToLla(const Utm& utm, double h_ellipsoid_m);

}  // namespace gvio::fusion
