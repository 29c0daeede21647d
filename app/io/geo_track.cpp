#include "io/geo_track.hpp"

#include <cctype>

#include "io/gnss_file.hpp"
#include "io/input_error.hpp"
#include "io/reference_csv.hpp"
#include "io/text.hpp"

namespace gvio::io {
namespace {

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

GeoTrack fromFixes(const std::vector<GnssFix>& fixes, bool with_quality) {
  GeoTrack track;
  for (const GnssFix& f : fixes) {
    track.t_ns.push_back(f.t_ns);
    track.lla.push_back({f.lat_deg, f.lon_deg, f.h_ellipsoid_m});
    if (with_quality) track.quality.push_back(f.quality);
  }
  return track;
}

}  // namespace

std::string geoTrackFormat(const std::filesystem::path& file) {
  LineReader in(file);
  std::string line;
  while (in.next(line)) {
    const std::string_view text = trim(line);
    if (text.empty()) continue;
    if (text.front() == '$') return "nmea";
    if (text.front() == '%') return "rtklib-pos";
    if (text.front() == '#')
      return lower(text).find("lat_deg") != std::string::npos ? "gnss-csv" : "";
    break;
  }
  return looksLikeReferenceCsv(file) ? "reference-csv" : "";
}

GeoTrack readGeoTrack(const std::filesystem::path& file, const ReaderConfig& config) {
  const std::string format = geoTrackFormat(file);
  GeoTrack track;
  if (format == "reference-csv") {
    for (const ReferenceEpoch& e : readReferenceCsv(file).epochs) {
      track.t_ns.push_back(e.t_ns);
      track.lla.push_back(e.lla);
    }
  } else if (!format.empty()) {  // the GNSS solution readers, as --gnss-file reads them
    GnssFileData data = readGnssFile(file, config);
    track = fromFixes(data.fixes, format != "gnss-csv");  // the CSV states no quality
    track.warnings = std::move(data.warnings);
  } else {
    throw InputError(file, 0,
                     "not a GNSS solution (NMEA, RTKLIB .pos, GNSS CSV) nor a reference CSV");
  }
  if (track.t_ns.empty()) throw InputError(file, 0, "no positions");
  track.format = format;
  return track;
}

Trajectory geoTrackPositions(const GeoTrack& track, const fusion::EnuFrame& enu) {
  Trajectory out;
  out.t_ns = track.t_ns;
  for (const fusion::Lla& p : track.lla) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = enu.toEnu(p);
    out.poses.push_back(T);
  }
  return out;
}

std::string qualityName(int quality) {
  switch (quality) {
    case 1:
      return "single";
    case 2:
      return "DGPS";
    case 3:
      return "PPS";
    case 4:
      return "RTK fixed";
    case 5:
      return "RTK float";
    case 6:
      return "dead reckoning";
    case 9:
      return "SBAS";
    default:
      return "quality " + std::to_string(quality);
  }
}

}  // namespace gvio::io
