#pragma once
// The 2-D part of `gvio view`'s scene: each trajectory as a track in WGS 84 and in UTM (for a map
// background or an offline UTM grid), the horizontal error along the drive against the truth, and
// the image check's per-keyframe scores (`gvio consistency --images`' keyframes.csv).
#include <filesystem>

#include <nlohmann/json.hpp>

#include "fusion/geodesy.hpp"

namespace gvio::view {

// Where the scene frame lies on the Earth.
struct SceneGeo {
  enum class Kind { kEnu, kUtm } kind = Kind::kEnu;
  fusion::Lla enu_origin;  // kEnu
  int utm_zone = 0;        // both: the grid the tracks are given in
  bool utm_north = true;
  Eigen::Vector3d utm_origin = Eigen::Vector3d::Zero();  // kUtm: easting, northing, height
};

// scene["tracks2d"]: per trajectory of scene["trajectories"] (same order) {"name", "lat_lon":
// [lat, lon, ...], "utm": [e, n, ...]}, at most `max_points` each (evenly thinned).
nlohmann::json tracks2d(const nlohmann::json& trajectories, const SceneGeo& geo,
                        std::size_t max_points = 2000);

// scene["errors"]: {"t": [s from the truth's start], "series": [{"name", "horizontal_m": [...]}]}
// for each trajectory with stamps against "truth" (linearly interpolated at each stamp), null
// when there is no truth.
nlohmann::json horizontalErrors(const nlohmann::json& trajectories, std::size_t max_points = 3000);

// scene["consistency"] from `csv` (keyframes.csv): {"t": [s from start], "p": [x y z ...],
// "ncc": [...], "depth_agreement": [...], "flagged": [...]} (NaN scores as null). Throws
// InputError naming the file and line when it is not that file.
nlohmann::json consistencyScores(const std::filesystem::path& csv);

}  // namespace gvio::view
