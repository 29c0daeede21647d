#pragma once
// Geodetic position tracks for `gvio eval`: a GNSS solution (RTKLIB .pos, NMEA 0183, gvio's GNSS
// CSV "#timestamp [ns],lat_deg,lon_deg,height_m,...") or a GNSS/INS reference CSV
// (io/reference_csv.hpp), read as positions with times in UTC and, for solutions that state it,
// each epoch's quality flag. Evaluated in a local ENU frame: a receiver, an RTKLIB setting and
// gvio's own output compared against one reference.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "fusion/geodesy.hpp"
#include "io/reader_config.hpp"
#include "odometry/trajectory.hpp"

namespace gvio::io {

struct GeoTrack {
  std::vector<std::int64_t> t_ns;  // UTC ns since the Unix epoch, increasing
  std::vector<fusion::Lla> lla;    // ellipsoidal heights
  // NMEA GGA quality (1 single, 2 DGPS, 4 RTK fixed, 5 RTK float, ...) per epoch; empty when the
  // source states none (a reference CSV, gvio's GNSS CSV).
  std::vector<int> quality;
  std::string format;  // "nmea", "rtklib-pos", "gnss-csv" or "reference-csv"
  std::vector<std::string> warnings;
};

// The format `readGeoTrack` would read `file` as, or "" when it is none of them (a TUM, KITTI or
// EuRoC trajectory): an NMEA sentence ('$') or RTKLIB header ('%') first, a reference CSV's header,
// or a '#' header naming lat_deg.
std::string geoTrackFormat(const std::filesystem::path& file);

// Throws InputError (file and line) for bad input or a file of none of these formats.
GeoTrack readGeoTrack(const std::filesystem::path& file, const ReaderConfig& config);

// The track's positions in `enu` (orientations identity: a position-only trajectory).
Trajectory geoTrackPositions(const GeoTrack& track, const fusion::EnuFrame& enu);

// "single", "DGPS", "RTK fixed", ... of an NMEA GGA quality.
std::string qualityName(int quality);

}  // namespace gvio::io
