#pragma once
// A small synthetic run folder with every map file `gvio render` reads, written with the same
// libraries the mapping writes them with (PCL, OctoMap), at known places:
//  - drive: straight along +x (heading east) from x = 2 to 38 m at y = 0, z = 1, 1 m/s from t = 0;
//  - map.pcd: ground z = 0 over x 0..40, y -10..10 (0.5 m); a wall x = 42, y -10..10, z 0..6
//    (0.25 m); all dense stereo points with intensity 255; 10 sparse landmarks floating at
//    (20, 9, 10) that a dense view leaves out;
//  - map.ot: ColorOcTree, 0.5 m: a red 2x2x2 block at x 6..7, y -4..-3, z 0..1 and a blue slab
//    x 20..24, y 6..6.5, z 0..4;
//  - gnss_fixes.csv: 3 used fixes at y = -3, one rejected at (20, 4), one skipped (nan);
//  - report.json: one outage 20..28 s (x 22..30 of the drive).
#include <octomap/ColorOcTree.h>
#include <octomap/OcTree.h>
#include <pcl/PCLPointCloud2.h>
#include <pcl/io/pcd_io.h>

#include <cstring>
#include <filesystem>
#include <vector>

#include "io/trajectory_io.hpp"
#include "support/fixtures.hpp"

namespace gvio::test {

struct MapPoint {
  float x, y, z, intensity;
  std::uint8_t source;
};

inline std::vector<MapPoint> syntheticMapPoints() {
  std::vector<MapPoint> p;
  for (int i = 0; i <= 80; ++i) {
    for (int j = 0; j <= 40; ++j) p.push_back({0.5F * i, -10.0F + 0.5F * j, 0.0F, 255.0F, 1});
  }
  for (int j = 0; j <= 80; ++j) {
    for (int k = 0; k <= 24; ++k) p.push_back({42.0F, -10.0F + 0.25F * j, 0.25F * k, 255.0F, 1});
  }
  for (int i = 0; i < 10; ++i) p.push_back({20.0F + 0.1F * i, 9.0F, 10.0F, 128.0F, 0});
  return p;
}

// Binary-compressed PCD with fields x y z intensity (float32) and source (uint8).
inline void writeMapPcd(const std::filesystem::path& file, const std::vector<MapPoint>& points) {
  pcl::PCLPointCloud2 c;
  c.height = 1;
  c.width = static_cast<std::uint32_t>(points.size());
  auto field = [&](const char* name, std::uint32_t offset, std::uint8_t type) {
    pcl::PCLPointField f;
    f.name = name;
    f.offset = offset;
    f.datatype = type;
    f.count = 1;
    c.fields.push_back(f);
  };
  field("x", 0, pcl::PCLPointField::FLOAT32);
  field("y", 4, pcl::PCLPointField::FLOAT32);
  field("z", 8, pcl::PCLPointField::FLOAT32);
  field("intensity", 12, pcl::PCLPointField::FLOAT32);
  field("source", 16, pcl::PCLPointField::UINT8);
  c.point_step = 17;
  c.row_step = c.point_step * c.width;
  c.is_dense = 1;
  c.data.resize(c.row_step);
  for (std::size_t i = 0; i < points.size(); ++i) {
    std::uint8_t* d = c.data.data() + i * c.point_step;
    std::memcpy(d, &points[i].x, 4);
    std::memcpy(d + 4, &points[i].y, 4);
    std::memcpy(d + 8, &points[i].z, 4);
    std::memcpy(d + 12, &points[i].intensity, 4);
    d[16] = points[i].source;
  }
  pcl::PCDWriter().writeBinaryCompressed(file.string(), c);
}

struct ColouredBlock {
  Eigen::Vector3d min_m, max_m;  // voxel centres from min to max in 0.5 m steps
  std::uint8_t r, g, b;
};

inline std::vector<ColouredBlock> syntheticBlocks() {
  return {{{6.25, -3.75, 0.25}, {6.75, -3.25, 0.75}, 220, 30, 20},
          {{20.25, 6.25, 0.25}, {23.75, 6.25, 3.75}, 20, 40, 230}};
}

template <typename Visit>
void forEachBlockVoxel(const ColouredBlock& b, Visit visit) {
  for (double x = b.min_m.x(); x <= b.max_m.x() + 1e-9; x += 0.5) {
    for (double y = b.min_m.y(); y <= b.max_m.y() + 1e-9; y += 0.5) {
      for (double z = b.min_m.z(); z <= b.max_m.z() + 1e-9; z += 0.5) visit(x, y, z);
    }
  }
}

inline void writeColorOcTree(const std::filesystem::path& file) {
  octomap::ColorOcTree tree(0.5);
  for (const auto& b : syntheticBlocks()) {
    forEachBlockVoxel(b, [&](double x, double y, double z) {
      const auto fx = static_cast<float>(x), fy = static_cast<float>(y), fz = static_cast<float>(z);
      tree.updateNode(octomap::point3d(fx, fy, fz), true);
      tree.setNodeColor(fx, fy, fz, b.r, b.g, b.b);
    });
  }
  tree.updateInnerOccupancy();
  tree.write(file.string());
}

inline void writeOcTreeBinary(const std::filesystem::path& file) {
  octomap::OcTree tree(0.5);
  for (const auto& b : syntheticBlocks()) {
    forEachBlockVoxel(b, [&](double x, double y, double z) {
      tree.updateNode(
          octomap::point3d(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z)),
          true);
    });
  }
  tree.writeBinary(file.string());
}

inline Trajectory syntheticDrive() {
  Trajectory t;
  for (int i = 0; i <= 36; ++i) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = Eigen::Vector3d(2.0 + i, 0.0, 1.0);
    t.poses.push_back(T);
    t.t_ns.push_back(static_cast<std::int64_t>(i) * 1'000'000'000LL);
  }
  return t;
}

// Writes the whole run folder (creating it).
inline void writeSyntheticMapRun(const std::filesystem::path& run) {
  std::filesystem::create_directories(run);
  io::writeTum(run / "trajectory.tum", syntheticDrive());
  writeMapPcd(run / "map.pcd", syntheticMapPoints());
  writeColorOcTree(run / "map.ot");
  writeText(run / "gnss_fixes.csv",
            "t_s,e_m,n_m,u_m,status\n"
            "3.0,5.0,-3.0,1.0,used\n"
            "13.0,15.0,-3.0,1.0,used\n"
            "18.0,20.0,4.0,1.0,rejected\n"
            "19.0,nan,nan,nan,skipped\n"
            "30.0,32.0,-3.0,1.0,used\n");
  writeText(run / "report.json",
            R"({"frames": 37, "outages": [{"t0": 20.0, "t1": 28.0, "duration_s": 8.0}]})");
}

}  // namespace gvio::test
