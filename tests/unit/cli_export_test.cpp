// gvio export through the built binary: every format re-imported with its own library (PCL,
// OctoMap, OGR, the tests' LAS reader, the trajectory readers), and bad input exits 2 in one line.
#include <gdal_priv.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <octomap/ColorOcTree.h>
#include <octomap/OcTree.h>
#include <ogrsf_frmts.h>
#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>
#include <pcl/point_types.h>
#include <GeographicLib/Geocentric.hpp>
#include <GeographicLib/LocalCartesian.hpp>
#include <GeographicLib/UTMUPS.hpp>

#include "export/gdal_support.hpp"
#include "io/trajectory_io.hpp"
#include "run/gnss_run.hpp"
#include "support/fixtures.hpp"
#include "support/las_reader.hpp"
#include "support/tiles3d_reader.hpp"

namespace gvio::test {
namespace {
namespace fs = std::filesystem;
using testing::HasSubstr;

const fusion::Lla kOrigin{49.011, 8.4, 112.5};

pcl::PointCloud<pcl::PointXYZI> cloud() {
  pcl::PointCloud<pcl::PointXYZI> c;
  for (int i = 0; i < 300; ++i) {
    pcl::PointXYZI p;
    p.x = static_cast<float>(-60.0 + 0.4 * i);
    p.y = static_cast<float>(40.0 * std::sin(0.05 * i));
    p.z = static_cast<float>(0.03 * i);
    p.intensity = static_cast<float>(i % 256);
    c.push_back(p);
  }
  return c;
}

Eigen::Vector3d lla(const Eigen::Vector3d& p_enu) {  // lon, lat, h straight from GeographicLib
  const GeographicLib::LocalCartesian enu(kOrigin.lat_deg, kOrigin.lon_deg, kOrigin.h_ellipsoid_m);
  double lat = 0, lon = 0, h = 0;
  enu.Reverse(p_enu.x(), p_enu.y(), p_enu.z(), lat, lon, h);
  return {lon, lat, h};
}

class CliExport : public ::testing::Test {
 protected:
  void SetUp() override {
    fs::create_directories(run_);
    run::GnssRunResult r;  // trajectory.tum and georef.json exactly as gvio run writes them
    r.origin = kOrigin;
    r.fused = ellipseDrive();
    r.T_enu_w = Eigen::Isometry3d::Identity();
    run::writeGeoreferencedOutputs(run_, r);
    io::writeTum(run_ / "trajectory_vio.tum", ellipseDrive());
    ASSERT_EQ(pcl::io::savePCDFileBinaryCompressed((run_ / "map.pcd").string(), cloud()), 0);
    octomap::OcTree tree(0.2);
    octomap::ColorOcTree color(0.2);
    for (const auto& p : cloud()) {
      tree.updateNode(octomap::point3d(p.x, p.y, p.z), true);
      color.updateNode(octomap::point3d(p.x, p.y, p.z), true);
      color.setNodeColor(p.x, p.y, p.z, 10, 200, static_cast<std::uint8_t>(p.intensity));
    }
    ASSERT_TRUE(tree.writeBinary((run_ / "map.bt").string()));
    ASSERT_TRUE(color.write((run_ / "map.ot").string()));
    bt_nodes_ = tree.size();
    ot_nodes_ = color.size();
  }
  [[nodiscard]] fs::path out(const std::string& name) const { return dir_.path() / name; }
  CommandResult exportTo(const std::string& format, const fs::path& file) const {
    return runGvio("export --run " + run_.string() + " --to " + format + " --out " + file.string());
  }

  TempDir dir_{"cliexport"};
  fs::path run_ = dir_.path() / "run";
  std::size_t bt_nodes_ = 0, ot_nodes_ = 0;
};

TEST_F(CliExport, PcdAndPlyReimportWithEveryPoint) {
  for (const std::string format : {"pcd", "ply"}) {
    const auto r = exportTo(format, out("m." + format));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    pcl::PointCloud<pcl::PointXYZI> back;
    const int rc = format == "pcd" ? pcl::io::loadPCDFile(out("m.pcd").string(), back)
                                   : pcl::io::loadPLYFile(out("m.ply").string(), back);
    ASSERT_EQ(rc, 0) << format;
    const auto expected = cloud();
    ASSERT_EQ(back.size(), expected.size()) << format;
    for (std::size_t i = 0; i < back.size(); ++i) {
      EXPECT_EQ(back[i].getVector3fMap(), expected[i].getVector3fMap()) << format << " " << i;
      EXPECT_EQ(back[i].intensity, expected[i].intensity);
    }
  }
  EXPECT_THAT(readText(out("m.pcd")), HasSubstr("DATA binary_compressed"));
  EXPECT_THAT(readText(out("m.ply")), HasSubstr("format binary_little_endian 1.0"));
}

TEST_F(CliExport, LasHoldsTheMapInUtmWithinAMillimetre) {
  const auto r = exportTo("las", out("m.las"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const LasFile las = readLas(out("m.las"));
  const auto expected = cloud();
  ASSERT_EQ(las.point_count, expected.size());
  EXPECT_THAT(las.wkt(), HasSubstr("UTM zone 32N"));
  for (std::size_t i = 0; i < expected.size(); ++i) {
    const Eigen::Vector3d g = lla(expected[i].getVector3fMap().cast<double>());
    int zone = 0;
    bool north = true;
    double e = 0, n = 0;
    GeographicLib::UTMUPS::Forward(g.y(), g.x(), zone, north, e, n, 32);
    EXPECT_LT((las.points[i].xyz - Eigen::Vector3d(e, n, g.z())).cwiseAbs().maxCoeff(), 0.001);
    EXPECT_EQ(las.points[i].intensity, static_cast<int>(expected[i].intensity) * 257);
  }
}

// 3D Tiles into the run's 3dtiles/ by default: the map's 300 points in ECEF, to a millimetre of
// where GeographicLib puts them, with their intensity on LAS's 16-bit scale.
TEST_F(CliExport, ThreeDTilesHoldTheMapInEcef) {
  const auto r = runGvio("export --run " + run_.string() + " --to 3dtiles");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("300 points in 1 tiles"));
  const Tileset ts = readTileset(run_ / "3dtiles");
  ASSERT_EQ(ts.tiles.size(), 1u);
  const PntsTile& tile = ts.tiles[0].content;
  const auto expected = cloud();
  ASSERT_EQ(tile.p_ecef.size(), expected.size());
  const GeographicLib::LocalCartesian enu(kOrigin.lat_deg, kOrigin.lon_deg, kOrigin.h_ellipsoid_m);
  const GeographicLib::Geocentric& earth = GeographicLib::Geocentric::WGS84();
  for (std::size_t i = 0; i < expected.size(); ++i) {
    const Eigen::Vector3d g = lla(expected[i].getVector3fMap().cast<double>());
    Eigen::Vector3d ecef;
    earth.Forward(g.y(), g.x(), g.z(), ecef.x(), ecef.y(), ecef.z());
    EXPECT_LT((tile.p_ecef[i] - ecef).norm(), 0.001) << i;
    EXPECT_EQ(tile.intensity[i], static_cast<int>(expected[i].intensity) * 257);
    EXPECT_EQ(tile.drive_id[i], 0);
  }
  // Again over the same folder, named with a slash: replaced. A folder that is not a tileset:
  // refused, kept.
  const auto again = exportTo("3dtiles", run_ / "3dtiles/");
  ASSERT_EQ(again.exit_code, 0) << again.err;
  fs::create_directories(out("mine"));
  writeText(out("mine") / "keep.txt", "x");
  const auto refused = exportTo("3dtiles", out("mine"));
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_THAT(refused.err, HasSubstr("is not a tileset folder"));
  EXPECT_TRUE(fs::exists(out("mine") / "keep.txt"));
}

TEST_F(CliExport, OctomapFilesRoundTrip) {
  const auto bt = exportTo("bt", out("m.bt"));
  ASSERT_EQ(bt.exit_code, 0) << bt.err;
  EXPECT_THAT(bt.err, testing::Not(HasSubstr("octree"))) << "OctoMap's own chatter on stderr";
  octomap::OcTree tree(0.1);
  ASSERT_TRUE(tree.readBinary(out("m.bt").string()));
  EXPECT_EQ(tree.size(), bt_nodes_);
  EXPECT_DOUBLE_EQ(tree.getResolution(), 0.2);
  for (const auto& p : cloud()) {
    const auto* node = tree.search(p.x, p.y, p.z);
    ASSERT_NE(node, nullptr);
    EXPECT_TRUE(tree.isNodeOccupied(node));
  }

  const auto ot = exportTo("ot", out("m.ot"));
  ASSERT_EQ(ot.exit_code, 0) << ot.err;
  EXPECT_THAT(ot.err, testing::Not(HasSubstr("octree"))) << "OctoMap's own chatter on stderr";
  std::unique_ptr<octomap::AbstractOcTree> any(octomap::AbstractOcTree::read(out("m.ot").string()));
  auto* color = dynamic_cast<octomap::ColorOcTree*>(any.get());
  ASSERT_NE(color, nullptr);
  EXPECT_EQ(color->size(), ot_nodes_);
  const auto p = cloud()[77];
  const auto* node = color->search(p.x, p.y, p.z);
  ASSERT_NE(node, nullptr);
  EXPECT_EQ(node->getColor(), octomap::ColorOcTreeNode::Color(10, 200, 77));
}

TEST_F(CliExport, TrajectoryFormatsReimport) {
  const Trajectory expected = ellipseDrive();
  for (const auto& [format, name] :
       {std::pair{"tum", "t.tum"}, {"kitti", "t.txt"}, {"euroc", "t.csv"}}) {
    const auto r = exportTo(format, out(name));
    ASSERT_EQ(r.exit_code, 0) << format << ": " << r.err;
    const auto f = *io::parseTrajectoryFormat(format);
    const Trajectory back = f == io::TrajectoryFormat::kKitti
                                ? io::readKitti(out(name), out("t_times.txt"))
                                : io::readTrajectory(out(name), f);
    ASSERT_EQ(back.size(), expected.size()) << format;
    ASSERT_EQ(back.t_ns.size(), expected.size()) << format;
    for (std::size_t i = 0; i < back.size(); ++i) {
      EXPECT_LT((back.poses[i].translation() - expected.poses[i].translation()).norm(), 1e-6);
      EXPECT_NEAR(static_cast<double>(back.t_ns[i] - expected.t_ns[i]), 0.0, 1e3) << format;
    }
  }
}

TEST_F(CliExport, GeoFormatsPlaceTheTrajectoryOnTheEarth) {
  const Trajectory expected = ellipseDrive();
  exporter::registerGdal();
  for (const std::string format : {"geojson", "kml", "gpx"}) {
    const auto r = exportTo(format, out("t." + format));
    ASSERT_EQ(r.exit_code, 0) << format << ": " << r.err;
    std::unique_ptr<GDALDataset> ds(
        GDALDataset::Open(out("t." + format).c_str(), GDAL_OF_VECTOR | GDAL_OF_READONLY));
    ASSERT_TRUE(ds) << format;
    std::vector<Eigen::Vector2d> lon_lat;
    if (format == "gpx") {
      for (auto& f : *ds->GetLayerByName("track_points")) {
        const OGRPoint* p = f->GetGeometryRef()->toPoint();
        lon_lat.emplace_back(p->getX(), p->getY());
      }
    } else {
      std::unique_ptr<OGRFeature> f(ds->GetLayer(0)->GetNextFeature());
      ASSERT_TRUE(f);
      const OGRLineString* line = f->GetGeometryRef()->toLineString();
      for (int i = 0; i < line->getNumPoints(); ++i)
        lon_lat.emplace_back(line->getX(i), line->getY(i));
    }
    ASSERT_EQ(lon_lat.size(), expected.size()) << format;
    for (std::size_t i = 0; i < expected.size(); ++i) {
      const Eigen::Vector3d g = lla(expected.poses[i].translation());
      EXPECT_LT((lon_lat[i] - g.head<2>()).cwiseAbs().maxCoeff(), 1e-8) << format << " " << i;
    }
  }
}

TEST_F(CliExport, DefaultOutputAndVioFallback) {
  auto r = runGvio("export --run " + run_.string() + " --to las");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(run_ / "export.las"));

  const fs::path vio_only = dir_.path() / "vio_only";
  fs::create_directories(vio_only);
  io::writeTum(vio_only / "trajectory_vio.tum", ellipseDrive());
  r = runGvio("export --run " + vio_only.string() + " --to kitti");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("not georeferenced"));
  EXPECT_EQ(io::readKitti(vio_only / "export.txt", vio_only / "export_times.txt").size(), 100U);
}

TEST_F(CliExport, BadInputIsOneLineExit2) {
  const fs::path bare = dir_.path() / "bare", nogeo = dir_.path() / "nogeo",
                 badgeo = dir_.path() / "badgeo", keyless = dir_.path() / "keyless",
                 broken = dir_.path() / "broken";
  for (const auto& d : {bare, nogeo, badgeo, keyless, broken}) fs::create_directories(d);
  io::writeTum(bare / "trajectory_vio.tum", ellipseDrive());
  for (const auto& d : {nogeo, badgeo, keyless, broken})
    io::writeTum(d / "trajectory.tum", ellipseDrive());
  writeText(badgeo / "georef.json", "{\"enu_origin\": ");
  writeText(keyless / "georef.json", R"({"enu_origin": {"lat_deg": 49.0, "lon_deg": 8.4}})");
  for (const auto& d : {badgeo, keyless}) fs::copy_file(run_ / "map.pcd", d / "map.pcd");
  writeText(broken / "map.pcd",
            "VERSION .7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
            "WIDTH 0\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 0\nDATA ascii\n");
  writeText(broken / "map.bt", "# Octomap OcTree binary file\nid OcTree\nsize 9\nres 0.1\ndata\n");
  writeText(broken / "map.ply", "not a ply");

  auto cmd = [](const fs::path& run, const std::string& to, const std::string& extra = "") {
    return "export --run " + run.string() + " --to " + to + extra;
  };
  const std::vector<std::pair<std::string, std::string>> cases = {
      {cmd(run_, "xyz"),
       "unknown format; one of pcd, ply, las, 3dtiles, bt, ot, tum, kitti, euroc"},
      {cmd(dir_.path() / "missing", "pcd"), "run folder not found"},
      {cmd(bare, "pcd"), "map.pcd: not found"},
      {cmd(bare, "bt"), "map.bt: not found"},
      {cmd(bare, "ot"), "map.ot: not found"},
      {cmd(bare, "gpx"), "trajectory.tum: not found"},
      {cmd(nogeo, "geojson"), "georef.json: not found"},
      {cmd(badgeo, "kml"), "georef.json: not valid JSON"},
      {cmd(badgeo, "las"), "georef.json: not valid JSON"},
      {cmd(keyless, "las"), "georef.json: malformed georef"},
      {cmd(broken, "pcd"), "map is empty (0 points)"},
      {cmd(broken, "bt"), "map.bt"},
      {cmd(run_, "las", " --out /nonexistent/dir/x.las"), "/nonexistent/dir/x.las"},
      {cmd(run_, "gpx", " --out " + dir_.path().string()), "is a folder"},
  };
  for (const auto& [args, needle] : cases) {
    const auto r = runGvio(args);
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << "\n" << r.err;
    EXPECT_THAT(r.err, HasSubstr(needle)) << args;
  }
}

}  // namespace
}  // namespace gvio::test
