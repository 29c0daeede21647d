#include "fleet/merge_inputs.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <set>

#include "io/input_error.hpp"
#include "io/run_dir.hpp"

namespace gvio::fleet {
namespace {

namespace fs = std::filesystem;

MergeRun readRun(const fs::path& dir) {
  if (!fs::is_directory(dir)) throw io::InputError(dir, 0, "run folder not found");
  const fs::path georef = dir / "georef.json";
  if (!fs::exists(georef)) {
    throw io::InputError(georef, 0,
                         "not found: gvio merge needs georeferenced runs (gvio run with GNSS)");
  }
  if (!fs::exists(dir / "map.pcd")) {
    throw io::InputError(dir / "map.pcd", 0, "not found: the run has no map to merge");
  }
  MergeRun run;
  run.dir = fs::absolute(dir).lexically_normal();
  run.georef = exporter::readGeoref(georef);
  fs::path name = run.dir;  // lexically normal: "run/" -> "run"; "/" keeps no name
  if (name.filename().empty() && name.has_relative_path()) name = name.parent_path();
  run.name = name.filename().string();
  if (run.name.empty()) run.name = "run";
  return run;
}

std::vector<fs::path> fleetRuns(const fs::path& fleet_dir) {
  const fs::path summary = fleet_dir / "fleet.json";
  const nlohmann::json j = io::readJsonObject(summary);
  std::vector<fs::path> runs;
  try {
    for (const auto& d : j.at("drives")) {
      if (d.at("state").get<std::string>() == "complete") {
        runs.emplace_back(d.at("run_dir").get<std::string>());
      } else {
        spdlog::warn("merge: {}: drive {} is {}, left out", summary.string(),
                     d.at("name").get<std::string>(), d.at("state").get<std::string>());
      }
    }
  } catch (const nlohmann::json::exception& e) {
    throw io::InputError(summary, 0, std::string("not a fleet summary: ") + e.what());
  }
  if (runs.empty()) throw io::InputError(summary, 0, "the fleet has no complete drive to merge");
  return runs;
}

}  // namespace

std::vector<MergeRun> resolveMergeRuns(const std::vector<fs::path>& args) {
  std::vector<fs::path> dirs;
  for (const auto& a : args) {
    if (fs::exists(a / "fleet.json") && !fs::exists(a / "georef.json")) {
      for (const auto& r : fleetRuns(a)) dirs.push_back(r);
    } else {
      dirs.push_back(a);
    }
  }
  if (dirs.empty()) throw InvalidInput("--runs: no run folder given");
  if (dirs.size() > 65535) {
    throw InvalidInput(
        fmt::format("--runs: {} runs; a LAS point source ID holds 65535", dirs.size()));
  }
  std::vector<MergeRun> runs;
  std::set<fs::path> seen;
  std::set<std::string> names;
  for (const auto& d : dirs) {
    MergeRun run = readRun(d);
    if (!seen.insert(fs::weakly_canonical(run.dir)).second) {
      throw io::InputError(d, 0, "run given twice");
    }
    // Names label the drives in tiles.json and the GeoJSON: made unique by their position.
    if (!names.insert(run.name).second) run.name += fmt::format("#{}", runs.size() + 1);
    run.point_source_id = static_cast<std::uint16_t>(runs.size() + 1);
    runs.push_back(std::move(run));
  }
  return runs;
}

double kmOutsideZone(const fusion::Lla& lla, int zone) {
  const double central = -183.0 + 6.0 * zone;
  double dlon = std::fmod(std::abs(lla.lon_deg - central), 360.0);
  if (dlon > 180.0) dlon = 360.0 - dlon;
  const double outside_deg = std::max(0.0, dlon - 3.0);
  constexpr double kKmPerDegree = 111.32;  // at the equator; scaled by cos(lat) below
  return outside_deg * kKmPerDegree * std::cos(lla.lat_deg * M_PI / 180.0);
}

MergeFrame chooseMergeFrame(const std::vector<MergeRun>& runs, const MergeConfig& config) {
  const MergeRun& first = runs.front();
  MergeFrame frame;
  frame.map_origin = first.georef.enu_origin;
  frame.crs = fusion::llaToUtm(frame.map_origin, first.georef.utm_zone, first.georef.utm_north);
  for (const auto& run : runs) {
    if (run.georef.utm_zone == frame.crs.zone && run.georef.utm_north == frame.crs.north) continue;
    const double km = kmOutsideZone(run.georef.enu_origin, frame.crs.zone);
    if (km > config.max_zone_distance_km) {
      throw io::InputError(
          run.dir / "georef.json", 0,
          fmt::format("UTM zone {}{} lies {:.0f} km outside zone {}{} of the first run ({}); "
                      "merge.max_zone_distance_km is {:.0f}: merge these runs separately",
                      run.georef.utm_zone, run.georef.utm_north ? "N" : "S", km, frame.crs.zone,
                      frame.crs.north ? "N" : "S", first.name, config.max_zone_distance_km));
    }
    spdlog::info("merge: {} (UTM zone {}{}) reprojected into zone {}{} ({:.1f} km outside it)",
                 run.name, run.georef.utm_zone, run.georef.utm_north ? "N" : "S", frame.crs.zone,
                 frame.crs.north ? "N" : "S", km);
  }
  frame.origin_utm = {frame.crs.easting_m, frame.crs.northing_m, frame.map_origin.h_ellipsoid_m};
  return frame;
}

}  // namespace gvio::fleet
