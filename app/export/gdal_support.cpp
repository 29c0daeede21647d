#include "export/gdal_support.hpp"

#include <cpl_error.h>
#include <gdal.h>
#include <ogr_spatialref.h>

#include <memory>
#include <mutex>

#include "odometry/error.hpp"

namespace gvio::exporter {

void registerGdal() {
  static std::once_flag once;
  std::call_once(once, [] { GDALAllRegister(); });
}

GdalErrorCapture::GdalErrorCapture() {
  CPLPushErrorHandler(CPLQuietErrorHandler);
  CPLErrorReset();
}

GdalErrorCapture::~GdalErrorCapture() {
  CPLPopErrorHandler();
}

std::string GdalErrorCapture::lastMessage() const {
  return CPLGetLastErrorMsg();
}

std::string wktFromEpsg(int epsg) {
  const GdalErrorCapture errors;
  OGRSpatialReference srs;
  if (srs.importFromEPSG(epsg) != OGRERR_NONE) {
    throw InvalidInput("EPSG:" + std::to_string(epsg) +
                       " unknown to PROJ: " + errors.lastMessage());
  }
  char* wkt = nullptr;
  const char* const options[] = {"FORMAT=WKT1", nullptr};
  const OGRErr err = srs.exportToWkt(&wkt, options);
  const std::unique_ptr<char, decltype(&CPLFree)> owned(wkt, &CPLFree);
  if (err != OGRERR_NONE || wkt == nullptr) {
    throw InvalidInput("EPSG:" + std::to_string(epsg) +
                       " has no WKT1 form: " + errors.lastMessage());
  }
  return wkt;
}

std::vector<double> egm96HeightsM(std::span<const fusion::Lla> points) {
  const GdalErrorCapture errors;
  OGRSpatialReference wgs84_3d, wgs84_egm96;
  wgs84_3d.importFromEPSG(4979);
  wgs84_egm96.importFromEPSG(9707);
  // x = longitude, y = latitude whatever the EPSG axis order says.
  wgs84_3d.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  wgs84_egm96.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  OGRCoordinateTransformationOptions options;
  options.SetBallparkAllowed(false);
  const std::unique_ptr<OGRCoordinateTransformation> transform(
      OGRCreateCoordinateTransformation(&wgs84_3d, &wgs84_egm96, options));
  if (!transform) {
    throw InvalidInput("no EGM96 geoid transformation (is PROJ's egm96_15 grid installed?): " +
                       errors.lastMessage());
  }
  std::vector<double> lon(points.size()), lat(points.size()), h(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    lon[i] = points[i].lon_deg;
    lat[i] = points[i].lat_deg;
    h[i] = points[i].h_ellipsoid_m;
  }
  std::vector<int> ok(points.size(), 0);
  if (!points.empty() &&
      !transform->Transform(points.size(), lon.data(), lat.data(), h.data(), nullptr, ok.data())) {
    throw InvalidInput("EGM96 height conversion failed: " + errors.lastMessage());
  }
  return h;
}

}  // namespace gvio::exporter
