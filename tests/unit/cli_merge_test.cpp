// gvio merge (issue 18): two georeferenced runs of the same streets as one grid of UTM tiles, each
// tile a LAS 1.4 file (CRS, point source ID = drive), a PCD in the map frame and an OctoMap; the
// Autoware and GeoJSON indexes; and the runs it refuses, each in one line.
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <octomap/OcTree.h>
#include <pcl/PCLPointCloud2.h>
#include <pcl/io/pcd_io.h>
#include <yaml-cpp/yaml.h>

#include <cstring>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <set>

#include "export/georef.hpp"
#include "fusion/geodesy.hpp"
#include "io/quiet_stderr.hpp"
#include "io/run_dir.hpp"
#include "support/fixtures.hpp"
#include "support/las_reader.hpp"
#include "viz/merged_view.hpp"

namespace gvio::test {
namespace {
using testing::HasSubstr;
namespace fs = std::filesystem;

class CliMerge : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new TempDir("cli_merge");
    for (const int seed : {21, 22}) {
      const fs::path sim = cachedSimulation(fmt::format(
          "--trajectory {}/assets/demo/drive.tum --seconds 10 --seed {} --gnss-noise rtk",
          GVIO_SOURCE_DIR, seed));
      const CommandResult r = runGvio(fmt::format("run --dataset {} --out {} --no-progress {}",
                                                  quoted(sim), quoted(run(seed)), kSimGeo));
      ASSERT_EQ(r.exit_code, 0) << r.err;
    }
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  static fs::path run(int seed) { return dir_->path() / fmt::format("run{}", seed); }
  static fs::path map() { return dir_->path() / "map"; }
  static inline TempDir* dir_ = nullptr;
};

TEST_F(CliMerge, TilesTwoDrivesAsLasPcdAndOctomapWithTheirDrives) {
  const CommandResult r = runGvio(fmt::format("merge --runs {} {} --out {} --tile-size 25",
                                              quoted(run(21)), quoted(run(22)), quoted(map())));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json index = io::readJsonObject(map() / "tiles.json");
  EXPECT_EQ(index["crs"]["epsg"], 32632);
  EXPECT_EQ(index["tile_size_m"], 25.0);
  const double e0 = index["map_frame"]["origin_easting_m"];
  const double n0 = index["map_frame"]["origin_northing_m"];
  const double h0 = index["map_frame"]["origin_h_ellipsoid_m"];

  // Every map point of both runs is in exactly one tile.
  std::uint64_t expected = 0;
  for (const int seed : {21, 22}) {
    for (const auto& p : io::readMapCloud(run(seed) / "map.pcd").p_enu) expected += p.allFinite();
  }
  EXPECT_EQ(index["points"], expected);

  std::uint64_t total = 0;
  std::map<std::uint16_t, std::uint64_t> per_drive;
  const YAML::Node metadata = YAML::LoadFile((map() / "pointcloud_map_metadata.yaml").string());
  EXPECT_EQ(metadata["x_resolution"].as<double>(), 25.0);
  ASSERT_GE(index["tiles"].size(), 3U);
  for (const auto& tile : index["tiles"]) {
    const std::string name = tile["name"];
    const double sw_e = tile["sw_easting_m"], sw_n = tile["sw_northing_m"];
    EXPECT_EQ(name, fmt::format("E{}_N{}", sw_e, sw_n));
    const LasFile las = readLas(map() / tile["files"]["las"].get<std::string>());
    EXPECT_EQ(las.version_minor, 4);
    EXPECT_THAT(las.wkt(), HasSubstr("UTM zone 32N"));
    ASSERT_EQ(las.point_count, tile["points"].get<std::uint64_t>());
    std::map<std::uint16_t, std::uint64_t> ids;
    for (const LasRecord& p : las.points) {
      ASSERT_GE(p.xyz.x(), sw_e - 1e-3);  // inside its own tile
      ASSERT_LT(p.xyz.x(), sw_e + 25.0 + 1e-3);
      ASSERT_GE(p.xyz.y(), sw_n - 1e-3);
      ASSERT_LT(p.xyz.y(), sw_n + 25.0 + 1e-3);
      ++ids[p.point_source_id];
    }
    for (const auto& [id, n] : ids) {
      EXPECT_EQ(tile["points_per_drive"][std::to_string(id)], n);
      per_drive[id] += n;
    }
    total += las.point_count;

    // The PCD holds the same points in the same order, in the map frame.
    pcl::PCLPointCloud2 cloud;
    ASSERT_EQ(
        pcl::io::loadPCDFile((map() / tile["files"]["pcd"].get<std::string>()).string(), cloud), 0);
    ASSERT_EQ(cloud.width * cloud.height, las.point_count);
    std::vector<std::string> fields;
    for (const auto& f : cloud.fields) fields.push_back(f.name);
    EXPECT_THAT(fields,
                testing::IsSupersetOf({"x", "y", "z", "intensity", "point_source_id", "source"}));
    ASSERT_EQ(cloud.point_step, 20U);
    float xyz[3];
    std::uint16_t id = 0;
    std::memcpy(xyz, cloud.data.data(), sizeof xyz);
    std::memcpy(&id, cloud.data.data() + 16, 2);
    EXPECT_NEAR(xyz[0], las.points[0].xyz.x() - e0, 2e-3);
    EXPECT_NEAR(xyz[1], las.points[0].xyz.y() - n0, 2e-3);
    EXPECT_NEAR(xyz[2], las.points[0].xyz.z() - h0, 2e-3);
    EXPECT_EQ(id, las.points[0].point_source_id);
    const auto corner = metadata[name + ".pcd"].as<std::vector<double>>();
    EXPECT_NEAR(corner[0], sw_e - e0, 1e-6);
    EXPECT_NEAR(corner[1], sw_n - n0, 1e-6);

    // The OctoMap marks the voxel of every point occupied.
    octomap::OcTree tree(0.1);
    {
      const io::QuietStderr quiet;
      ASSERT_TRUE(tree.readBinary((map() / tile["files"]["bt"].get<std::string>()).string()));
    }
    EXPECT_DOUBLE_EQ(tree.getResolution(), 0.2);
    const octomap::OcTreeNode* node = tree.search(xyz[0], xyz[1], xyz[2]);
    ASSERT_NE(node, nullptr);
    EXPECT_TRUE(tree.isNodeOccupied(node));
  }
  EXPECT_EQ(total, expected);
  EXPECT_EQ(per_drive.size(), 2U);
  for (const auto& d : index["drives"]) {
    const auto id = d["point_source_id"].get<std::uint16_t>();
    EXPECT_EQ(d["points"], per_drive[id]);
  }
  // Both drives mapped the same street: the second one's dense points overlap the first one's
  // (compared with it, the reference drive).
  EXPECT_FALSE(index["drives"][0].contains("agreement"));
  const nlohmann::json agreement = index["drives"][1]["agreement"];
  EXPECT_GT(agreement["overlap_points"].get<std::uint64_t>(), 200U) << agreement.dump();
  EXPECT_GT(agreement["within_percent"].get<double>(), 10.0) << agreement.dump();
  EXPECT_LT(agreement["median_m"].get<double>(), 1.0) << agreement.dump();

  // A LAS point is the exact UTM coordinate of its map point (the grid interpolation errs < 1 mm).
  const exporter::Georef georef = exporter::readGeoref(run(21) / "georef.json");
  const fusion::EnuFrame enu(georef.enu_origin);
  const io::MapCloud cloud = io::readMapCloud(run(21) / "map.pcd");
  const fusion::Lla lla = enu.toLla(cloud.p_enu[0].cast<double>());
  const fusion::Utm utm = fusion::llaToUtm(lla, 32);
  const std::string name = fmt::format("E{}_N{}", std::floor(utm.easting_m / 25) * 25,
                                       std::floor(utm.northing_m / 25) * 25);
  const LasFile las = readLas(map() / "tiles" / (name + ".las"));
  double nearest = 1e9;
  for (const LasRecord& p : las.points) {
    nearest = std::min(
        nearest,
        (p.xyz - Eigen::Vector3d(utm.easting_m, utm.northing_m, lla.h_ellipsoid_m)).norm());
  }
  EXPECT_LT(nearest, 2e-3);

  const nlohmann::json geo = io::readJsonObject(map() / "tiles.geojson");
  std::size_t polygons = 0, tracks = 0;
  for (const auto& f : geo["features"]) {
    const std::string type = f["geometry"]["type"];
    polygons += type == "Polygon";
    if (type == "LineString") {
      ++tracks;
      EXPECT_GT(f["geometry"]["coordinates"].size(), 10U);
      EXPECT_NEAR(f["geometry"]["coordinates"][0][0].get<double>(), 8.39, 0.01);  // lon first
    }
  }
  EXPECT_EQ(polygons, index["tiles"].size());
  EXPECT_EQ(tracks, 2U);
  const YAML::Node projector = YAML::LoadFile((map() / "map_projector_info.yaml").string());
  EXPECT_EQ(projector["projector_type"].as<std::string>(), "LocalCartesianUTM");
  EXPECT_NEAR(projector["map_origin"]["latitude"].as<double>(), georef.enu_origin.lat_deg, 1e-9);

  // gvio render draws the merged map from above, each drive in its colour.
  const fs::path png = dir_->path() / "merged.png";
  const CommandResult drawn =
      runGvio(fmt::format("render --run {} --out {} --size 800x600", quoted(map()), quoted(png)));
  ASSERT_EQ(drawn.exit_code, 0) << drawn.err;
  const cv::Mat image = cv::imread(png.string(), cv::IMREAD_COLOR);
  ASSERT_EQ(image.cols, 800);
  for (const std::uint16_t id : {1, 2}) {
    const render::Rgb c = viz::driveColour(id);
    const cv::Vec3b bgr(static_cast<std::uint8_t>(std::lround(c.b * 255)),
                        static_cast<std::uint8_t>(std::lround(c.g * 255)),
                        static_cast<std::uint8_t>(std::lround(c.r * 255)));
    int count = 0;
    for (int row = 0; row < image.rows; ++row) {
      for (int col = 0; col < image.cols; ++col) {
        const cv::Vec3b p = image.at<cv::Vec3b>(row, col);
        count += std::abs(p[0] - bgr[0]) + std::abs(p[1] - bgr[1]) + std::abs(p[2] - bgr[2]) < 12;
      }
    }
    EXPECT_GT(count, 500) << "drive " << id;
  }
  const CommandResult perspective = runGvio(
      fmt::format("render --run {} --view perspective --out {}", quoted(map()), quoted(png)));
  EXPECT_EQ(perspective.exit_code, 2);
  EXPECT_THAT(perspective.err,
              HasSubstr("is a merged map (tiles.json): it draws --view topdown only"));

  // gvio consistency: the merged points against the simulator's world of the second drive (in
  // the ENU frame of the simulator's origin, the runs' origin: the default), overall and per
  // drive. That drive's points lie as close to it as its run's own map.pcd does; the same mesh
  // 3 m higher is farther.
  const fs::path world =
      cachedSimulation(fmt::format(
          "--trajectory {}/assets/demo/drive.tum --seconds 10 --seed 22 --gnss-noise rtk",
          GVIO_SOURCE_DIR)) /
      "world/world.ply";
  const auto consistency = [&](const fs::path& run_or_map, const std::string& extra) {
    const fs::path json = dir_->path() / "consistency.json";
    const CommandResult c =
        runGvio(fmt::format("consistency --run {} --reference {} --json {} {}", quoted(run_or_map),
                            quoted(world), quoted(json), extra));
    EXPECT_EQ(c.exit_code, 0) << c.err;
    return io::readJsonObject(json);
  };
  const nlohmann::json fit = consistency(map(), "");
  EXPECT_EQ(fit["points_read"], expected);
  ASSERT_EQ(fit["drives"].size(), 2U);
  EXPECT_GT(fit["dense"]["n"].get<std::size_t>(), expected / 2);
  const double second = fit["drives"][1]["dense"]["median_m"].get<double>();
  const double own = consistency(run(22), "")["dense"]["median_m"].get<double>();
  EXPECT_NEAR(second, own, 0.01);
  EXPECT_LT(second, 1.0);
  const nlohmann::json moved = consistency(map(), "--reference-origin 48.98253,8.39035,119.4");
  EXPECT_GT(moved["drives"][1]["dense"]["median_m"].get<double>(), second + 0.3);

  // Merged again with larger tiles: the smaller tiles of the first merge are gone.
  ASSERT_EQ(runGvio(fmt::format("merge --runs {} {} --out {} --tile-size 100", quoted(run(21)),
                                quoted(run(22)), quoted(map())))
                .exit_code,
            0);
  const nlohmann::json again = io::readJsonObject(map() / "tiles.json");
  std::set<std::string> listed;
  for (const auto& tile : again["tiles"]) {
    for (const auto& [kind, file] : tile["files"].items()) listed.insert(file.get<std::string>());
  }
  std::set<std::string> present;
  for (const auto& f : fs::directory_iterator(map() / "tiles")) {
    present.insert("tiles/" + f.path().filename().string());
  }
  EXPECT_EQ(present, listed);
}

TEST_F(CliMerge, RefusesWhatItCannotMergeInOneLine) {
  const fs::path bad = dir_->path() / "bad";
  fs::create_directories(bad / "no_georef");
  writeText(bad / "no_georef/map.pcd", "");
  fs::create_directories(bad / "no_map");
  fs::copy_file(run(21) / "georef.json", bad / "no_map/georef.json");
  fs::create_directories(bad / "far");
  writeText(bad / "far/georef.json",
            R"({"enu_origin": {"lat_deg": 48.98, "lon_deg": 20.0, "h_ellipsoid_m": 100}})");
  writeText(bad / "far/map.pcd", "");
  const auto merge = [&](const std::string& runs) {
    return runGvio(fmt::format("merge --runs {} --out {}", runs, quoted(bad / "out")));
  };
  const std::vector<std::pair<std::string, std::string>> cases{
      {quoted(bad / "nowhere"), "nowhere: run folder not found"},
      {quoted(bad / "no_georef"), "georef.json: not found: gvio merge needs georeferenced runs"},
      {quoted(bad / "no_map"), "map.pcd: not found: the run has no map to merge"},
      {quoted(run(21)) + " " + quoted(run(21)), "run given twice"},
      {quoted(run(21)) + " " + quoted(bad / "far"), "UTM zone 34N lies 584 km outside zone 32N"},
  };
  for (const auto& [runs, message] : cases) {
    const CommandResult r = merge(runs);
    EXPECT_EQ(r.exit_code, 2) << runs;
    EXPECT_THAT(r.err, HasSubstr(message));
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
  EXPECT_FALSE(fs::exists(bad / "out/tiles.json"));
}

}  // namespace
}  // namespace gvio::test
