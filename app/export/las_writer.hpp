#pragma once
// LAS 1.4 point clouds (ASPRS LAS Specification 1.4 R15): public header (375 bytes), one OGC WKT
// coordinate-system VLR, point data record format 6. Written here because no Debian bookworm
// library writes LAS: liblas and PDAL are not packaged for bookworm, and GDAL 3.6 has no LAS
// driver. Coordinates are UTM easting/northing (one zone for the whole file, the zone of the ENU
// origin unless forced) and WGS 84 ellipsoidal height, in metres.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <span>

#include <Eigen/Core>

#include "fusion/geodesy.hpp"

namespace gvio::exporter {

struct LasPoint {
  Eigen::Vector3d p_enu = Eigen::Vector3d::Zero();
  std::uint16_t intensity = 0;        // normalised to the full 16-bit range (LAS 1.4, "Intensity")
  std::uint8_t classification = 0;    // ASPRS class; 0 = created, never classified
  std::uint16_t point_source_id = 0;  // the flight line (for gvio: the drive), 0 = none
};

// A point already in the file's UTM zone: easting, northing, ellipsoidal height.
struct LasUtmPoint {
  Eigen::Vector3d p_utm = Eigen::Vector3d::Zero();
  std::uint16_t intensity = 0;
  std::uint8_t classification = 0;
  std::uint16_t point_source_id = 0;
};

struct LasOptions {
  std::optional<int> utm_zone;    // default: the standard zone of the ENU origin
  std::optional<bool> utm_north;  // default: the hemisphere of the ENU origin
  double scale_m = 0.001;         // coordinate resolution (X, Y and Z)
};

struct LasSummary {
  fusion::Utm crs;  // zone and hemisphere of the file (easting/northing: the ENU origin's)
  std::uint64_t points = 0;
  Eigen::Vector3d min = Eigen::Vector3d::Zero(), max = Eigen::Vector3d::Zero();  // E, N, h
};

// The UTM (easting, northing) and ellipsoidal height of a local ENU point, in the given zone and
// hemisphere (a point across the equator from `north` keeps the file's false northing).
Eigen::Vector3d enuToUtm(const fusion::EnuFrame& enu, const Eigen::Vector3d& p_enu, int zone,
                         bool north);

// Point k (0 <= k < n) of a cloud, or nullopt for one the file leaves out: lets a large cloud be
// written without a copy of it (KITTI-00's 14 M-point map). Called twice per point.
using LasPointAt = std::function<std::optional<LasPoint>(std::size_t k)>;

// Point k of a cloud already in UTM, or nullopt for one left out; called twice per point.
using LasUtmPointAt = std::function<std::optional<LasUtmPoint>(std::size_t k)>;

// Writes points already in UTM zone `crs.zone` (hemisphere `crs.north`) to `file` atomically,
// streaming in two passes (bounds, then records). Throws as writeLas below.
LasSummary writeLasUtm(const std::filesystem::path& file, const fusion::Utm& crs, std::size_t n,
                       const LasUtmPointAt& point_at, double scale_m = 0.001);

// Writes the points (local ENU at `enu_origin`) to `file` atomically, streaming: a first pass
// finds the bounds (header, offsets), the second writes the records, so nothing per point is
// held. Throws InvalidInput when a coordinate does not fit the 32-bit integer grid (before
// anything is written) or the origin is outside UTM's latitude band, InputError (naming `file`)
// when it cannot be written.
LasSummary writeLas(const std::filesystem::path& file, const fusion::Lla& enu_origin, std::size_t n,
                    const LasPointAt& point_at, const LasOptions& options = {});
LasSummary writeLas(const std::filesystem::path& file, const fusion::Lla& enu_origin,
                    std::span<const LasPoint> points, const LasOptions& options = {});

}  // namespace gvio::exporter
