#include "view/view_scene.hpp"

#include <algorithm>
#include <cmath>

#include "export/georef.hpp"
#include "fleet/merged_map.hpp"
#include "fusion/vio_enu_alignment.hpp"
#include "io/input_error.hpp"
#include "io/place_database_io.hpp"
#include "io/run_dir.hpp"
#include "io/trajectory_io.hpp"
#include "view/view_plots.hpp"

namespace gvio::view {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// Positions to the millimetre and stamps to the microsecond: a third of the text at full
// precision, and below anything a view can show.
double mm(double v) {
  return std::round(v * 1e3) / 1e3;
}

void pushPoint(json& array, const Eigen::Vector3d& p) {
  for (int k = 0; k < 3; ++k) array.push_back(mm(p[k]));
}

json trajectoryJson(const std::string& name, const std::string& label, const Trajectory& traj,
                    const Eigen::Isometry3d& T_scene_traj = Eigen::Isometry3d::Identity()) {
  json t = json::array(), p = json::array();
  for (std::size_t k = 0; k < traj.size(); ++k) {
    if (traj.hasTimestamps())
      t.push_back(std::round(static_cast<double>(traj.t_ns[k]) / 1e3) / 1e6);
    pushPoint(p, T_scene_traj * traj.poses[k].translation());
  }
  return {{"name", name}, {"label", label}, {"t", std::move(t)}, {"p", std::move(p)}};
}

// georef.json's T_enu_w (VIO world to ENU), when the run recorded one.
std::optional<Eigen::Isometry3d> vioToEnu(const fs::path& georef_file) {
  if (!fs::exists(georef_file)) return std::nullopt;
  const json j = io::readJsonObject(georef_file);
  if (!j.contains("T_enu_w")) return std::nullopt;
  try {
    const auto& t = j.at("T_enu_w").at("translation_m");
    const auto& q = j.at("T_enu_w").at("quaternion_wxyz");
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::Quaterniond(q.at(0).get<double>(), q.at(1).get<double>(),
                                    q.at(2).get<double>(), q.at(3).get<double>())
                     .normalized()
                     .toRotationMatrix();
    T.translation() =
        Eigen::Vector3d(t.at(0).get<double>(), t.at(1).get<double>(), t.at(2).get<double>());
    return T;
  } catch (const json::exception& e) {
    throw io::InputError(georef_file, 0, std::string("bad T_enu_w: ") + e.what());
  }
}

json trajectoriesJson(const io::RunFiles& run, const std::optional<Eigen::Isometry3d>& T_enu_w) {
  json out = json::array();
  const bool georeferenced = T_enu_w.has_value();
  if (run.fused) {
    out.push_back(trajectoryJson(
        "fused", georeferenced ? "fused (trajectory.tum)" : "loop-closed (trajectory.tum)",
        *run.fused));
  }
  const fs::path online = run.dir / "trajectory_online.tum";
  if (fs::exists(online)) {
    out.push_back(trajectoryJson("online", "online (trajectory_online.tum)", io::readTum(online)));
  }
  // The VIO world is the scene frame only without GNSS; with it, georef.json maps it to ENU.
  if (run.vio) {
    out.push_back(trajectoryJson("vio", "VIO (trajectory_vio.tum)", *run.vio,
                                 T_enu_w.value_or(Eigen::Isometry3d::Identity())));
  }
  // The truth is in ENU: drawn only where the scene is.
  if (run.truth && georeferenced) {
    out.push_back(trajectoryJson("truth", "truth (groundtruth.tum)", *run.truth));
  }
  return out;
}

const char* statusName(io::FixStatus s) {
  switch (s) {
    case io::FixStatus::kUsed:
      return "used";
    case io::FixStatus::kRejected:
      return "rejected";
    case io::FixStatus::kSkipped:
      return "skipped";
    case io::FixStatus::kUnmatched:
      return "unmatched";
    case io::FixStatus::kUnaligned:
      return "unaligned";
  }
  return "unknown";
}

// Fixes with a position (a fix never fused may have none).
json fixesJson(const std::vector<io::GnssFixRecord>& fixes) {
  json t = json::array(), p = json::array(), status = json::array();
  for (const auto& f : fixes) {
    if (!f.p_enu.allFinite()) continue;
    t.push_back(f.t_s);
    pushPoint(p, f.p_enu);
    status.push_back(statusName(f.status));
  }
  return {{"t", std::move(t)}, {"p", std::move(p)}, {"status", std::move(status)}};
}

// Each loop candidate as an edge between the two keyframes' positions on `traj`.
json loopsJson(const std::vector<io::LoopCsvRow>& rows, const Trajectory& traj) {
  json a = json::array(), b = json::array(), accepted = json::array(), reason = json::array();
  for (const auto& r : rows) {
    const auto pa = fusion::interpolatePose(traj, r.query_t_ns);
    const auto pb = fusion::interpolatePose(traj, r.candidate_t_ns);
    if (!pa || !pb) continue;
    pushPoint(a, pa->translation());
    pushPoint(b, pb->translation());
    accepted.push_back(r.accepted);
    reason.push_back(r.reason);
  }
  return {{"a", std::move(a)},
          {"b", std::move(b)},
          {"accepted", std::move(accepted)},
          {"reason", std::move(reason)}};
}

void addCloud(const io::MapCloud& map, ViewCloud& cloud) {
  cloud.reserve(map.p_enu.size());
  for (std::size_t k = 0; k < map.p_enu.size(); ++k) {
    const float i = map.intensity.empty() ? 0.0F : map.intensity[k];
    cloud.push(
        map.p_enu[k].cast<double>(),
        static_cast<std::uint8_t>(std::isfinite(i) ? std::clamp(i, 0.0F, 255.0F) + 0.5F : 0.0F),
        map.source.empty() ? io::MapCloud::kDense : map.source[k], 0);
  }
}

void addVoxels(const io::OccupancyMap& occupancy, ViewInput& in) {
  for (const auto& v : occupancy.voxels) {
    for (int k = 0; k < 3; ++k) in.voxels.push_back(v.center_enu[k]);
    in.voxels.push_back(v.size_m);
    in.voxel_rgb.insert(in.voxel_rgb.end(), v.rgb.begin(), v.rgb.end());
  }
}

}  // namespace

json keyframesJson(const CameraModel& camera, const std::vector<KeyframeCamera>& keyframes) {
  json t = json::array(), pose = json::array();
  for (const auto& k : keyframes) {
    const Eigen::Quaterniond q(k.T_scene_c.rotation());
    t.push_back(static_cast<double>(k.t_ns) / 1e9);
    pushPoint(pose, k.T_scene_c.translation());
    for (const double v : {q.w(), q.x(), q.y(), q.z()}) pose.push_back(std::round(v * 1e6) / 1e6);
  }
  return {{"camera",
           {{"width", camera.width_px},
            {"height", camera.height_px},
            {"fx", camera.fx},
            {"fy", camera.fy},
            {"cx", camera.cx},
            {"cy", camera.cy}}},
          {"t", std::move(t)},
          {"pose", std::move(pose)}};
}

ViewInput readRunForView(const io::RunFiles& run) {
  const fs::path& run_dir = run.dir;
  ViewInput in;
  json& s = in.scene;
  s["kind"] = "run";
  s["title"] = fs::absolute(run_dir).lexically_normal().filename().string();
  const fs::path georef_file = run_dir / "georef.json";
  const std::optional<Eigen::Isometry3d> T_enu_w = vioToEnu(georef_file);
  std::optional<SceneGeo> geo;
  if (fs::exists(georef_file)) {
    const exporter::Georef g = exporter::readGeoref(georef_file);
    geo = SceneGeo{SceneGeo::Kind::kEnu, g.enu_origin, g.utm_zone, g.utm_north,
                   Eigen::Vector3d::Zero()};
    s["frame"] = {{"type", "enu"},
                  {"lat_deg", g.enu_origin.lat_deg},
                  {"lon_deg", g.enu_origin.lon_deg},
                  {"h_m", g.enu_origin.h_ellipsoid_m},
                  {"utm_zone", g.utm_zone},
                  {"utm_north", g.utm_north}};
  } else {
    s["frame"] = {{"type", "vio"}};
  }
  s["trajectories"] = trajectoriesJson(run, T_enu_w);
  if (geo) s["tracks2d"] = tracks2d(s["trajectories"], *geo);
  s["errors"] = horizontalErrors(s["trajectories"]);
  const fs::path scores = run_dir / "consistency_images" / "keyframes.csv";
  if (fs::exists(scores)) s["consistency"] = consistencyScores(scores);
  if (run.gnss_fixes) s["fixes"] = fixesJson(*run.gnss_fixes);
  const Trajectory& along = run.fused ? *run.fused : *run.vio;
  if (run.loops) s["loops"] = loopsJson(*run.loops, along);
  if (fs::exists(run_dir / "keyframes.bin")) {
    const mapping::PlaceDatabase db = io::readPlaceDatabase(run_dir / "keyframes.bin");
    std::vector<KeyframeCamera> cameras;
    for (const auto& prior : db.priors)
      cameras.push_back({prior.t_ns, prior.T_ref_b * db.camera.T_b_c});
    s["keyframes"] = keyframesJson(db.camera, cameras);
  }
  if (fs::exists(run_dir / "report.json"))
    s["report"] = io::readJsonObject(run_dir / "report.json");
  if (run.cloud) addCloud(*run.cloud, in.cloud);
  if (run.occupancy) addVoxels(*run.occupancy, in);
  return in;
}

ViewInput readMergedForView(const fs::path& map_dir) {
  const fleet::MergedMap map = fleet::readMergedMap(map_dir, 0);
  ViewInput in;
  json& s = in.scene;
  s["kind"] = "merge";
  s["title"] = fs::absolute(map_dir).lexically_normal().filename().string();
  s["frame"] = {{"type", "utm"},
                {"utm_zone", map.utm_zone},
                {"utm_north", map.utm_north},
                {"origin_easting_m", map.origin_utm.x()},
                {"origin_northing_m", map.origin_utm.y()},
                {"origin_h_m", map.origin_utm.z()}};
  json tracks = json::array();
  for (const auto& d : map.drives) {
    if (d.track_map.size() < 2) continue;  // no track in tiles.geojson
    json p = json::array();
    for (const auto& q : d.track_map) pushPoint(p, q);
    tracks.push_back({{"name", "drive " + std::to_string(d.point_source_id)},
                      {"label", d.name},
                      {"drive", d.point_source_id},
                      {"t", json::array()},
                      {"p", std::move(p)}});
  }
  s["trajectories"] = std::move(tracks);
  const SceneGeo geo{SceneGeo::Kind::kUtm, {}, map.utm_zone, map.utm_north, map.origin_utm};
  s["tracks2d"] = tracks2d(s["trajectories"], geo);
  in.cloud.reserve(map.points.size());
  for (std::size_t k = 0; k < map.points.size(); ++k) {
    in.cloud.push(map.points[k].cast<double>(), map.intensity[k], map.source[k],
                  map.point_source_id[k]);
  }
  return in;
}

}  // namespace gvio::view
