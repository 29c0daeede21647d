#pragma once
// A trajectory as a GIS track, written through GDAL/OGR:
//  - GeoJSON (RFC 7946): one LineString Feature, [lon, lat, h] with h the WGS 84 ellipsoidal height
//    (RFC 7946 section 4), properties name, start/end time and the per-vertex times "t_s".
//  - KML: one Placemark LineString, altitudeMode absolute, altitudes above the EGM96 geoid (KML 2.2
//    altitudes are above sea level), TimeSpan begin/end (LIBKML driver when GDAL has it, else KML).
//  - GPX 1.1: one <trk> with one <trkseg>, per point <ele> (EGM96, mean sea level) and <time>.
// Times: t_ns read as UNIX time (UTC), which is what the dataset clock is for KITTI raw drives.
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>

#include "fusion/geodesy.hpp"

namespace gvio::exporter {

struct TrackPoint {
  std::int64_t t_ns = 0;
  fusion::Lla lla;
};

enum class TrackFormat { kGeoJson, kKml, kGpx };

// Replaces `file` atomically (written to a temporary sibling with the format's extension, then
// renamed). Throws InvalidInput for an empty track or invalid coordinates, InputError naming
// `file` when it cannot be written.
void writeTrack(const std::filesystem::path& file, std::span<const TrackPoint> track,
                TrackFormat format, const std::string& name = "gvio trajectory");

}  // namespace gvio::exporter
