#include "fusion/geodesy.hpp"

#include <GeographicLib/Geocentric.hpp>
#include <GeographicLib/UTMUPS.hpp>

#include <cmath>
#include <cstdio>
#include <string>

#include "odometry/error.hpp"

namespace gvio::fusion {
namespace {

const GeographicLib::Geocentric& wgs84() {
  return GeographicLib::Geocentric::WGS84();
}

}  // namespace

Eigen::Vector3d llaToEcef(const Lla& lla) {
  Eigen::Vector3d p;
  wgs84().Forward(lla.lat_deg, lla.lon_deg, lla.h_ellipsoid_m, p.x(), p.y(), p.z());
  return p;
}

Lla ecefToLla(const Eigen::Vector3d& p_ecef) {
  Lla lla;
  wgs84().Reverse(p_ecef.x(), p_ecef.y(), p_ecef.z(), lla.lat_deg, lla.lon_deg, lla.h_ellipsoid_m);
  return lla;
}

EnuFrame::EnuFrame(const Lla& origin) : origin_(origin), origin_ecef_(llaToEcef(origin)) {
  // Rows are the east, north and up unit vectors expressed in ECEF.
  const double lat = origin.lat_deg * M_PI / 180.0;
  const double lon = origin.lon_deg * M_PI / 180.0;
  const double sl = std::sin(lat), cl = std::cos(lat), so = std::sin(lon), co = std::cos(lon);
  R_enu_ecef_ << -so, co, 0.0,  //
      -sl * co, -sl * so, cl,   //
      cl * co, cl * so, sl;
}

Eigen::Vector3d EnuFrame::toEnu(const Lla& lla) const {
  return R_enu_ecef_ * (llaToEcef(lla) - origin_ecef_);
}

Eigen::Vector3d EnuFrame::ecefToEnu(const Eigen::Vector3d& p_ecef) const {
  return R_enu_ecef_ * (p_ecef - origin_ecef_);
}

Lla EnuFrame::toLla(const Eigen::Vector3d& p_enu) const {
  return ecefToLla(origin_ecef_ + R_enu_ecef_.transpose() * p_enu);
}

bool isValidLla(const Lla& lla) {
  return std::isfinite(lla.lat_deg) && std::isfinite(lla.lon_deg) &&
         std::isfinite(lla.h_ellipsoid_m) && std::abs(lla.lat_deg) <= 90.0 &&
         std::abs(lla.lon_deg) <= 180.0;
}

std::optional<Lla> parseLla(std::string_view text) {
  const std::string copy(text);
  Lla lla;
  char tail = 0;
  if (std::sscanf(copy.c_str(), "%lf ,%lf ,%lf %c", &lla.lat_deg, &lla.lon_deg, &lla.h_ellipsoid_m,
                  &tail) != 3 ||
      !isValidLla(lla)) {
    return std::nullopt;
  }
  return lla;
}

Utm llaToUtm(const Lla& lla) {
  if (!isValidLla(lla) || lla.lat_deg < -80.0 || lla.lat_deg >= 84.0) {
    throw InvalidInput("UTM is defined for latitudes -80..84 deg (got " +
                       std::to_string(lla.lat_deg) + ")");
  }
  return llaToUtm(lla, GeographicLib::UTMUPS::StandardZone(lla.lat_deg, lla.lon_deg));
}

Utm llaToUtm(const Lla& lla, int zone) {
  if (zone < 1 || zone > 60)
    throw InvalidInput("UTM zone must be 1..60 (got " + std::to_string(zone) + ")");
  Utm utm;
  int used_zone = 0;
  double gamma = 0.0, k = 0.0;  // meridian convergence and scale: not needed here
  GeographicLib::UTMUPS::Forward(lla.lat_deg, lla.lon_deg, used_zone, utm.north, utm.easting_m,
                                 utm.northing_m, gamma, k, zone);
  utm.zone = used_zone;
  return utm;
}

Utm llaToUtm(const Lla& lla, int zone, bool north) {
  constexpr double kFalseNorthingSouthM = 10'000'000.0;
  Utm utm = llaToUtm(lla, zone);
  if (utm.north && !north) utm.northing_m += kFalseNorthingSouthM;
  if (!utm.north && north) utm.northing_m -= kFalseNorthingSouthM;
  utm.north = north;
  return utm;
}

Lla utmToLla(const Utm& utm, double h_ellipsoid_m) {
  Lla lla;
  lla.h_ellipsoid_m = h_ellipsoid_m;
  GeographicLib::UTMUPS::Reverse(utm.zone, utm.north, utm.easting_m, utm.northing_m, lla.lat_deg,
                                 lla.lon_deg);
  return lla;
}

}  // namespace gvio::fusion
