#pragma once
// Reads back the ENU origin and UTM zone that `gvio run` records in georef.json
// (run/gnss_run.cpp writeGeoreferencedOutputs; DESIGN.md section 4).
#include <filesystem>

#include "fusion/geodesy.hpp"

namespace gvio::exporter {

struct Georef {
  fusion::Lla enu_origin;  // "enu_origin": lat_deg, lon_deg, h_ellipsoid_m (EPSG:4979)
  int utm_zone = 0;        // "utm": zone (1..60) and north; the origin's standard zone if absent
  bool utm_north = true;
};

// Throws InputError naming `file` when it is missing, not JSON, or lacks a valid origin/zone.
Georef readGeoref(const std::filesystem::path& file);

}  // namespace gvio::exporter
