#pragma once
// The GDAL/OGR pieces the exports share: driver registration, error capture (GDAL prints its
// errors to stderr by default; the CLI needs them as one-line exceptions), the OGC WKT of a UTM
// zone, and WGS 84 ellipsoidal -> EGM96 heights.
#include <span>
#include <string>
#include <vector>

#include "fusion/geodesy.hpp"

namespace gvio::exporter {

// GDALAllRegister(), once per process.
void registerGdal();

// While alive, GDAL/OGR errors are collected instead of printed.
class GdalErrorCapture {
 public:
  GdalErrorCapture();
  ~GdalErrorCapture();
  GdalErrorCapture(const GdalErrorCapture&) = delete;
  GdalErrorCapture& operator=(const GdalErrorCapture&) = delete;
  // The last error GDAL reported since construction ("" when none).
  [[nodiscard]] std::string lastMessage() const;
};

// OGC WKT (version 1, OGC 01-009, as LAS 1.4 requires) of an EPSG code, from GDAL's
// OGRSpatialReference. Throws InvalidInput for a code PROJ does not know.
std::string wktFromEpsg(int epsg);

// Heights above the EGM96 geoid (mean sea level, what KML altitudes and GPX <ele> mean) of WGS 84
// positions given with ellipsoidal heights: PROJ's EPSG:4979 -> EPSG:9707 (WGS 84 + EGM96 height)
// through its egm96_15 grid. Ballpark (grid-less) transformations are refused, so a missing grid
// is an error, never a silent 0 m geoid.
std::vector<double> egm96HeightsM(std::span<const fusion::Lla> points);

}  // namespace gvio::exporter
