// gvio consistency: a run's map against a reference surface (a triangle mesh in the map's frame,
// e.g. a simulated drive's world/world.ply, or a survey mesh in the run's local ENU): distance of
// the dense points and of the sparse landmarks to the surface, and the share of occupied OctoMap
// voxels near it (mapping/consistency.hpp). The targets are reported beside each figure.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <octomap/OcTree.h>

#include <nlohmann/json.hpp>

#include "cli/app.hpp"
#include "cli/consistency_images.hpp"
#include "fleet/merged_consistency.hpp"
#include "io/atomic_write.hpp"
#include "io/input_error.hpp"
#include "io/mesh_ply.hpp"
#include "io/run_dir.hpp"
#include "mapping/consistency.hpp"

namespace gvio::cli {
namespace {
namespace fs = std::filesystem;

// Issue 8's bounds (median distance to the true surface; occupied voxels within 2 voxels).
constexpr double kDenseMedianM = 0.15;
constexpr double kSparseMedianM = 0.3;
constexpr double kOccupiedNearFraction = 0.9;
constexpr double kOccupancyWithinVoxels = 2.0;

struct ConsistencyOptions {
  std::string run, reference;
  std::optional<std::string> json;
  std::optional<std::string> reference_origin;  // merged maps: the mesh's ENU origin
  double max_distance_m = 2.0;
  bool images = false;  // against the recorded images instead of a mesh
  ImageConsistencyRequest image_check;
};

// Points of a merged map compared at most (thinned evenly per tile).
constexpr std::size_t kMergedMapPoints = 10'000'000;

fusion::Lla parseOrigin(const std::string& text) {
  const auto lla = fusion::parseLla(text);
  if (!lla) {
    throw InvalidInput("--reference-origin '" + text + "': expected lat,lon,h (degrees, metres)");
  }
  return *lla;
}

// A `gvio merge` folder: the tiles' points against the mesh, overall and per drive.
int runMergedConsistency(const ConsistencyOptions& o) {
  const fleet::MergedMap map = fleet::readMergedMap(o.run, kMergedMapPoints);
  const nlohmann::json index = io::readJsonObject(fs::path(o.run) / "tiles.json");
  const fusion::Lla map_origin{index["map_frame"]["origin_lat_deg"].get<double>(),
                               index["map_frame"]["origin_lon_deg"].get<double>(),
                               index["map_frame"]["origin_h_ellipsoid_m"].get<double>()};
  const fusion::Lla mesh_origin =
      o.reference_origin ? parseOrigin(*o.reference_origin) : map_origin;
  const io::TriangleMesh mesh =
      fleet::meshInMapFrame(io::readMeshPly(o.reference), mesh_origin, map);
  nlohmann::json j =
      fleet::mergedConsistency(map, mesh, o.max_distance_m, kDenseMedianM, kSparseMedianM);
  j["run"] = o.run;
  j["reference"] = {
      {"file", o.reference},
      {"triangles", mesh.triangles.size()},
      {"enu_origin", {mesh_origin.lat_deg, mesh_origin.lon_deg, mesh_origin.h_ellipsoid_m}}};
  spdlog::info("merged map: {} of {} points compared", map.points.size(), map.total_points);
  spdlog::info("dense points: {}, median {:.3f} m, p90 {:.3f} m to the reference (target <= {} m)",
               j["dense"]["n"].get<std::size_t>(), j["dense"]["median_m"].get<double>(),
               j["dense"]["p90_m"].get<double>(), kDenseMedianM);
  for (const auto& d : j["drives"]) {
    spdlog::info("  {} (point source ID {}): {} dense points, median {:.3f} m",
                 d["name"].get<std::string>(), d["point_source_id"].get<int>(),
                 d["dense"]["n"].get<std::size_t>(), d["dense"]["median_m"].get<double>());
  }
  if (o.json) io::writeTextAtomic(*o.json, j.dump(2) + "\n");
  return 0;
}

// map.bt (the maximum-likelihood OcTree); nullopt when the run wrote none.
std::unique_ptr<octomap::OcTree> readOcTree(const fs::path& file) {
  if (!fs::exists(file)) return nullptr;
  auto tree = std::make_unique<octomap::OcTree>(0.1);
  if (!tree->readBinary(file.string()) || tree->size() == 0) {
    throw io::InputError(file, 0, "not a readable OctoMap binary tree (.bt)");
  }
  return tree;
}

int runConsistency(const ConsistencyOptions& o, ProgressStyle progress) {
  if (!(o.max_distance_m > 0.0)) throw InvalidInput("--max-distance must be > 0");
  const fs::path run(o.run);
  if (!fs::is_directory(run)) throw io::InputError(run, 0, "run folder not found");
  if (o.images == !o.reference.empty()) {
    throw InvalidInput("give either --reference MESH.ply or --images");
  }
  if (o.images) {
    ImageConsistencyRequest r = o.image_check;
    r.run = run;
    if (o.json) r.json = *o.json;
    r.progress = progress;
    return runImageConsistency(r);
  }
  if (fleet::isMergedMap(run) && !fs::exists(run / "map.pcd")) return runMergedConsistency(o);
  if (o.reference_origin) {
    throw InvalidInput(
        "--reference-origin is for a merged map (gvio merge); a run's reference "
        "mesh is in its own ENU frame");
  }
  if (const auto warning = io::incompleteRunWarning(run)) spdlog::warn("{}", *warning);
  const fs::path pcd = run / "map.pcd";
  if (!fs::exists(pcd)) {
    throw io::InputError(pcd, 0, "no map in the run folder (gvio run writes it with map.enabled)");
  }
  const io::MapCloud cloud = io::readMapCloud(pcd);
  const io::TriangleMesh mesh = io::readMeshPly(o.reference);
  const mapping::TriangleMeshIndex surface(mesh.vertices, mesh.triangles);
  std::vector<Eigen::Vector3d> dense, sparse;
  for (std::size_t i = 0; i < cloud.p_enu.size(); ++i) {
    const bool is_sparse = !cloud.source.empty() && cloud.source[i] == io::MapCloud::kSparse;
    (is_sparse ? sparse : dense).push_back(cloud.p_enu[i].cast<double>());
  }
  nlohmann::json j;
  j["run"] = run.string();
  j["reference"] = {{"file", o.reference}, {"triangles", surface.triangleCount()}};
  const auto d = mapping::cloudToSurface(surface, dense, o.max_distance_m, kDenseMedianM);
  const auto s = mapping::cloudToSurface(surface, sparse, o.max_distance_m, kSparseMedianM);
  j["dense"] = fleet::surfaceStatsJson(d, kDenseMedianM);
  j["sparse"] = fleet::surfaceStatsJson(s, kSparseMedianM);
  spdlog::info("dense points: {}, median {:.3f} m, p90 {:.3f} m to the reference (target <= {} m)",
               d.n, d.median_m, d.p90_m, kDenseMedianM);
  spdlog::info("sparse landmarks: {}, median {:.3f} m, p90 {:.3f} m (target <= {} m)", s.n,
               s.median_m, s.p90_m, kSparseMedianM);
  if (const auto tree = readOcTree(run / "map.bt")) {
    const auto occ = mapping::occupancyNearSurface(surface, *tree, kOccupancyWithinVoxels);
    j["occupancy"] = {{"resolution_m", tree->getResolution()},
                      {"occupied_voxels", occ.occupied_voxels},
                      {"near_surface", occ.near_surface},
                      {"within_m", occ.within_m},
                      {"fraction_near", occ.fraction_near},
                      {"target_fraction", kOccupiedNearFraction},
                      {"meets_target", occ.fraction_near >= kOccupiedNearFraction}};
    spdlog::info("occupied voxels: {}, {:.1f} % within {:.2f} m of the reference (target >= {} %)",
                 occ.occupied_voxels, 100.0 * occ.fraction_near, occ.within_m,
                 100.0 * kOccupiedNearFraction);
  }
  if (o.json) io::writeTextAtomic(*o.json, j.dump(2) + "\n");
  return 0;
}

}  // namespace

Command addConsistencyCommand(CLI::App& app, const CommonOptions& common) {
  auto o = std::make_shared<ConsistencyOptions>();
  CLI::App* sub = app.add_subcommand(
      "consistency",
      "Compare a run's map (map.pcd, map.bt) or a merged map (tiles) with a reference mesh, or "
      "a run's map with its recorded images (--images)");
  sub->add_option("--run", o->run, "Run folder (the --out of gvio run)")->required();
  sub->add_option("--reference", o->reference,
                  "Reference triangle mesh (PLY) in the run's map frame (local ENU)");
  sub->add_flag("--images", o->images,
                "No reference: render the map into every keyframe's camera (leaving out the "
                "points of keyframes within --exclude s) and compare with its recorded image and "
                "stereo depth");
  ImageConsistencyRequest& ic = o->image_check;
  sub->add_option("--out", ic.out, "--images: report folder (default RUN/consistency_images)");
  sub->add_option("--dataset", ic.dataset,
                  "--images: the dataset, if it moved since the run (default: report.json's)");
  sub->add_option("--every", ic.every, "--images: check every n-th map keyframe")
      ->capture_default_str()
      ->check(countValidator());
  sub->add_option("--at", ic.at_s, "--images: check only the keyframe nearest T s into the drive");
  sub->add_option("--from", ic.from_s, "--images: check only keyframes from S s into the drive");
  sub->add_option("--to", ic.to_s, "--images: ... up to S s into the drive");
  sub->add_option("--exclude", ic.check.exclude_s,
                  "--images: leave out the points of keyframes closer than this in time (s)")
      ->capture_default_str();
  sub->add_option("--worst", ic.worst_images,
                  "--images: side-by-side images of this many worst keyframes")
      ->capture_default_str()
      ->check(countValidator());
  sub->add_option("--flag-sigmas", ic.check.score.flag_sigmas,
                  "--images: flag a keyframe whose ZNCC lies this many of its sigmas below what "
                  "is typical of its stretch of the drive")
      ->capture_default_str();
  sub->add_option("--depth-flag-sigmas", ic.check.score.depth_flag_sigmas,
                  "--images: ... whose depth agreement lies this many sigmas below")
      ->capture_default_str();
  sub->add_option("--similar-views", ic.check.score.similar_views,
                  "--images: judge a keyframe against this many keyframes whose map points in "
                  "view lie at the most similar depths (0: against the whole drive alike)")
      ->capture_default_str()
      ->check(countValidator());
  sub->add_flag("--no-revisits", ic.no_revisits,
                "--images: do not check keyframes at revisits against the other passes' map");
  sub->add_option("--json", o->json, "Write the metrics as JSON");
  sub->add_option("--reference-origin", o->reference_origin,
                  "Merged maps (gvio merge): the mesh's local ENU origin lat,lon,h (default: the "
                  "map origin, the first run's ENU origin)");
  sub->add_option("--max-distance", o->max_distance_m,
                  "Search radius (m): points farther from the surface count as this distance")
      ->capture_default_str();
  return {sub, [o, &common] { return runConsistency(*o, common.progressStyle()); }};
}

}  // namespace gvio::cli
