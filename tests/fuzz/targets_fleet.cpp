// Fuzz targets of the fleet's inputs (issue 18): the drive list of `gvio fleet`, the plan a
// Slurm array task reads (`gvio fleet-task`), a merged map's tiles.json (`gvio render --run
// MAP`, with one tile beside it) and a run's keyframes.bin (gvio merge's joint alignment).
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "fleet/drive_list.hpp"
#include "fleet/drive_task.hpp"
#include "fleet/merged_map.hpp"
#include "fuzz/harness.hpp"
#include "fuzz/targets_list.hpp"
#include "io/place_database_io.hpp"
#include "io/run_dir.hpp"
#include "support/fixtures.hpp"

namespace gvio::fuzz {
namespace {

namespace fs = std::filesystem;

constexpr const char* kDriveList =
    "# drives\n"
    "kitti/2011_10_03_drive_0027_extract\n"
    "/data/morning.bag --calib camchain.yaml imu.yaml --gnss-file morning.pos\n"
    "'evening drive' --name evening --gnss kf --set vio.mode=stereo  # a comment\n";

constexpr const char* kPlan = R"({
  "common_args": ["--set", "loops.enabled=false"],
  "drives": [
    {"dataset": "/data/a", "line": 1, "name": "a", "run_args": ["--gnss", "off"]},
    {"dataset": "/data/b", "line": 2, "name": "b", "run_args": []}
  ],
  "gvio": "/usr/bin/gvio",
  "out_dir": "/fleet",
  "threads_per_drive": 2
})";

constexpr const char* kTilesJson = R"({
  "crs": {"epsg": 32632, "heights": "WGS 84 ellipsoidal", "north": true, "utm_zone": 32},
  "drives": [{"name": "a", "point_source_id": 1, "points": 2}],
  "map_frame": {"origin_easting_m": 455393.18, "origin_h_ellipsoid_m": 116.4,
                "origin_lat_deg": 48.98253, "origin_lon_deg": 8.39035,
                "origin_northing_m": 5425692.79},
  "points": 2,
  "tile_size_m": 50.0,
  "tiles": [{"files": {"pcd": "tiles/E455350_N5425650.pcd"}, "name": "E455350_N5425650",
             "points": 2, "sw_easting_m": 455350.0, "sw_northing_m": 5425650.0}]
})";

// Two points in the layout gvio merge writes (x y z intensity point_source_id source, 20 bytes).
constexpr const char* kTilePcd =
    "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\n"
    "FIELDS x y z intensity point_source_id source\nSIZE 4 4 4 4 2 1\nTYPE F F F F U U\n"
    "COUNT 1 1 1 1 1 1\nWIDTH 2\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\nDATA ascii\n"
    "1 2 0.5 100 1 1\n-3 4 0.25 50 1 0\n";

// Two keyframes of three keypoints (two with 3-D points), a fix and a loop.
void writeKeyframesBin(const fs::path& file) {
  mapping::PlaceDatabase db;
  db.has_imu = true;
  db.camera.width_px = 64;
  db.camera.height_px = 32;
  db.camera.fx = db.camera.fy = 50.0;
  db.camera.cx = 32.0;
  db.camera.cy = 16.0;
  for (int k = 0; k < 2; ++k) {
    mapping::LoopKeyframe kf;
    kf.t_ns = 1'000'000'000LL * (k + 1);
    kf.px = {{10.0F, 5.0F}, {20.0F, 8.0F}, {40.0F, 20.0F}};
    kf.descriptors = cv::Mat(3, 32, CV_8U, cv::Scalar(17 + k));
    kf.p_c = {{0.5F, 0.2F, 8.0F}, {-1.0F, 0.4F, 12.0F}};
    kf.points = 2;
    db.keyframes.push_back(kf);
    mapping::KeyframePrior p;
    p.t_ns = kf.t_ns;
    p.T_ref_b.translation() = Eigen::Vector3d(5.0 * k, 0.0, 0.0);
    p.sigma_m = 1.0;
    p.path_m = 5.0 * k;
    db.priors.push_back(p);
    db.T_vio.push_back(p.T_ref_b);
  }
  fusion::GraphFix f;
  f.node = 1;
  f.t_ns = 2'000'000'000;
  f.p_enu = Eigen::Vector3d(5.0, 0.1, 0.8);
  f.quality = 5;
  f.shape_en << 1.2, 0.3, 0.3, 0.8;  // a stated ellipse (keyframes.bin version 3)
  db.fixes.push_back(f);
  fusion::GraphLoop l;
  l.i = 0;
  l.j = 1;
  db.loops.push_back(l);
  io::writePlaceDatabase(file, db);
}

}  // namespace

void addFleetTargets(std::vector<Target>& out) {
  out.push_back(plain("drive_list", "drives.txt", kDriveList, [](const fs::path& d) {
    for (const auto& drive : fleet::readDriveList(d / "drives.txt")) {
      require(!drive.name.empty() && drive.name.find('/') == std::string::npos, "bad run name");
      require(drive.dataset.is_absolute(), "dataset not absolute");
    }
  }));
  out.push_back(plain("fleet_plan", "fleet_plan.json", kPlan, [](const fs::path& d) {
    const fs::path file = d / "fleet_plan.json";
    const fleet::FleetPlan plan = fleet::planFromJson(io::readJsonObject(file), file);
    for (std::size_t i = 0; i < plan.drives.size(); ++i) {
      require(plan.runDir(i).parent_path() == plan.out_dir / "runs", "run folder escapes");
      require(!plan.runArgv(i).empty(), "empty command");
    }
  }));
  Target tiles = plain("tiles_json", "tiles.json", kTilesJson, [](const fs::path& d) {
    const fleet::MergedMap map = fleet::readMergedMap(d, 1000);
    require(map.points.size() == map.point_source_id.size(), "points without drive");
    for (const auto& p : map.points) require(p.allFinite(), "non-finite point");
    require(map.tile_size_m > 0.0, "tile size not positive");
  });
  tiles.prepare = [](const fs::path& d) {
    test::writeText(d / "tiles.json", kTilesJson);
    test::writeText(d / "tiles" / "E455350_N5425650.pcd", kTilePcd);
  };
  out.push_back(std::move(tiles));
  out.push_back(Target{
      "keyframes_bin", "keyframes.bin",
      [](const fs::path& d) { writeKeyframesBin(d / "keyframes.bin"); },
      [](const fs::path& d) {
        const mapping::PlaceDatabase db = io::readPlaceDatabase(d / "keyframes.bin");
        require(db.priors.size() == db.keyframes.size() && db.T_vio.size() == db.keyframes.size(),
                "keyframe records out of step");
        for (const auto& kf : db.keyframes) {
          require(kf.points == kf.p_c.size() && kf.points <= kf.px.size() &&
                      kf.descriptors.rows == static_cast<int>(kf.px.size()),
                  "keyframe counts disagree");
        }
        for (const auto& f : db.fixes) {
          require(f.node < db.keyframes.size(), "fix off the keyframes");
          require(
              f.shape_en.allFinite() && f.shape_en(0, 0) > 0.0 && f.shape_en.determinant() > 0.0,
              "fix ellipse not positive definite");
        }
      },
      ""});
}

}  // namespace gvio::fuzz
