#pragma once
// Routes and checks shared by the sim/world tests (sim_world_test, sim_world_styles_test).
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <numbers>
#include <opencv2/core.hpp>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "render/renderer.hpp"
#include "sim/world.hpp"

namespace gvio::sim::world_fixture {

constexpr double kBodyHeight = 0.93;    // route points are body positions above the road
constexpr double kCameraHeight = 1.65;  // KITTI's camera above the road

// A drive of legs {length m, turn rad spread over the leg}, a point every 0.5 m, on flat ground.
inline std::vector<Eigen::Vector3d> drive(const std::vector<std::pair<double, double>>& legs) {
  std::vector<Eigen::Vector3d> route{Eigen::Vector3d(0, 0, kBodyHeight)};
  double heading = 0.0;
  for (const auto& [length, turn] : legs) {
    const int steps = static_cast<int>(std::lround(length / 0.5));
    for (int k = 0; k < steps; ++k) {
      heading += turn / steps;
      route.push_back(route.back() +
                      0.5 * Eigen::Vector3d(std::cos(heading), std::sin(heading), 0));
    }
  }
  return route;
}

// 400 m: 150 m east, a left turn, 80 m north, a right turn, on east. Turn radius 25 m: 1 m along
// it turns the camera 2.3 deg, about what KITTI's 10 Hz frames turn at street corners.
inline std::vector<Eigen::Vector3d> twoTurns() {
  const double q = std::numbers::pi / 2, arc = 25.0 * q;
  return drive({{150.0, 0.0}, {arc, q}, {80.0, 0.0}, {arc, -q}, {400.0 - 230.0 - 2 * arc, 0.0}});
}

// Lemniscate of Gerono: crosses itself at right angles in the middle.
inline std::vector<Eigen::Vector3d> figureEight() {
  std::vector<Eigen::Vector3d> route;
  const double a = 150.0;
  for (int i = 0; i <= 1200; ++i) {
    const double t = 2.0 * std::numbers::pi * i / 1200.0;
    route.emplace_back(a * std::sin(t), a * std::sin(t) * std::cos(t), kBodyHeight);
  }
  return route;
}

// A 200 x 150 m block with 20 m corners, driven `laps` times.
inline std::vector<Eigen::Vector3d> block(int laps) {
  const double q = std::numbers::pi / 2;
  std::vector<std::pair<double, double>> legs;
  for (int lap = 0; lap < laps; ++lap) {
    for (const double straight : {200.0, 150.0, 200.0, 150.0}) {
      legs.emplace_back(straight, 0.0);
      legs.emplace_back(20.0, q);
    }
  }
  return drive(legs);
}

// Route points in 10 m cells: the searches stay local.
class RouteGrid {
 public:
  static constexpr double kCell = 10.0;
  explicit RouteGrid(const std::vector<Eigen::Vector3d>& route) {
    for (const auto& p : route) grid_[cell(p)].push_back(p);
  }
  // Calls f(p) for every route point in the cells within `reach` cells of q.
  template <typename F>
  void visit(const Eigen::Vector3d& q, long reach, F&& f) const {
    const auto [x, y] = cell(q);
    for (long cx = x - reach; cx <= x + reach; ++cx) {
      for (long cy = y - reach; cy <= y + reach; ++cy) {
        const auto it = grid_.find({cx, cy});
        if (it == grid_.end()) continue;
        for (const auto& p : it->second) f(p);
      }
    }
  }

 private:
  static std::pair<long, long> cell(const Eigen::Vector3d& p) {
    return {static_cast<long>(std::floor(p.x() / kCell)),
            static_cast<long>(std::floor(p.y() / kCell))};
  }
  std::map<std::pair<long, long>, std::vector<Eigen::Vector3d>> grid_;
};

// Vertices closer than `radius` (2-D) to a route point and higher than 0.2 m above the road there:
// the highest road height (route height - body height) within radius + 1 m, since where passes
// cross at different recorded heights the world's road lies between them.
inline std::size_t verticesOnRoad(const World& world, const std::vector<Eigen::Vector3d>& route,
                                  double radius, double body_height,
                                  const std::vector<std::size_t>& skip_textures = {}) {
  const RouteGrid grid(route);
  std::size_t bad = 0;
  for (const auto& mesh : world.scene.meshes) {
    if (std::find(skip_textures.begin(), skip_textures.end(), mesh.texture) != skip_textures.end())
      continue;
    for (const auto& v : mesh.vertices) {
      double nearest = radius + RouteGrid::kCell, road_z = -1e9;
      grid.visit(v, 1, [&](const Eigen::Vector3d& p) {
        const double d = (p - v).head<2>().norm();
        nearest = std::min(nearest, d);
        if (d < radius + 1.0) road_z = std::max(road_z, p.z() - body_height);
      });
      if (nearest < radius && v.z() > road_z + 0.2) {
        if (bad < 10 && std::getenv("GVIO_SIM_DEBUG") != nullptr)
          std::cout << "    on road: texture " << mesh.texture << " at " << v.transpose() << "\n";
        ++bad;
      }
    }
  }
  return bad;
}

using Rect = std::array<Eigen::Vector2d, 4>;

// Building footprints, read back from the mesh: a building's two long walls carry its facade
// texture and are stored one after the other; their bottom edges are two sides of the footprint.
inline std::vector<Rect> buildingFootprints(const World& world,
                                            const std::vector<std::size_t>& facades) {
  std::vector<Rect> out;
  for (const auto& m : world.scene.meshes) {
    if (std::find(facades.begin(), facades.end(), m.texture) == facades.end()) continue;
    for (std::size_t i = 0; i + 7 < m.vertices.size(); i += 8) {
      out.push_back({m.vertices[i].head<2>(), m.vertices[i + 1].head<2>(),
                     m.vertices[i + 4].head<2>(), m.vertices[i + 5].head<2>()});
    }
  }
  return out;
}

// How deep two convex quadrilaterals overlap (separating axes; 0 when apart).
inline double overlapDepth(const Rect& a, const Rect& b) {
  double depth = 1e9;
  for (const Rect* r : {&a, &b}) {
    for (std::size_t i = 0; i < 4; ++i) {
      const Eigen::Vector2d e = ((*r)[(i + 1) % 4] - (*r)[i]).normalized();
      const Eigen::Vector2d axis(-e.y(), e.x());
      double a0 = 1e9, a1 = -1e9, b0 = 1e9, b1 = -1e9;
      for (const auto& p : a) a0 = std::min(a0, p.dot(axis)), a1 = std::max(a1, p.dot(axis));
      for (const auto& p : b) b0 = std::min(b0, p.dot(axis)), b1 = std::max(b1, p.dot(axis));
      depth = std::min(depth, std::min(a1, b1) - std::max(a0, b0));
    }
  }
  return std::max(depth, 0.0);
}

inline double deepestBuildingOverlap(const std::vector<Rect>& rects) {
  double worst = 0.0;
  for (std::size_t i = 0; i < rects.size(); ++i) {
    for (std::size_t j = i + 1; j < rects.size(); ++j) {
      if ((rects[i][0] - rects[j][0]).norm() < 120.0)  // footprints are < 45 m across
        worst = std::max(worst, overlapDepth(rects[i], rects[j]));
    }
  }
  return worst;
}

// Camera 1.65 m above the road at arc length s, looking along the route (z forward, y down).
inline Eigen::Isometry3d cameraAt(const std::vector<Eigen::Vector3d>& route, double s) {
  auto at = [&](double arc) {
    double acc = 0.0;
    for (std::size_t i = 0; i + 1 < route.size(); ++i) {
      const double len = (route[i + 1] - route[i]).head<2>().norm();
      if (acc + len >= arc)
        return Eigen::Vector3d(route[i] + (arc - acc) / len * (route[i + 1] - route[i]));
      acc += len;
    }
    return route.back();
  };
  const Eigen::Vector3d p = at(s);
  const Eigen::Vector3d t = Eigen::Vector3d(at(s + 1.0) - at(s - 1.0)).normalized();
  Eigen::Matrix3d R;
  R.col(2) = t;                                    // forward
  R.col(0) = Eigen::Vector3d(t.y(), -t.x(), 0.0);  // right
  R.col(1) = Eigen::Vector3d(0, 0, -1);            // down
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R;
  T.translation() = Eigen::Vector3d(p.x(), p.y(), p.z() - kBodyHeight + kCameraHeight);
  return T;
}

inline cv::Mat greyOf(const render::ImageRgba& img) {  // grey textures: R = G = B
  cv::Mat grey;
  cv::extractChannel(
      cv::Mat(img.height, img.width, CV_8UC4, const_cast<std::uint8_t*>(img.rgba.data())), grey, 0);
  return grey;
}

// KITTI odometry ground truth (cam0 poses; world x right, y down, z forward at the first frame)
// as camera poses in an ENU-like frame: east = x, north = z, up = -y.
inline std::vector<Eigen::Isometry3d> kittiCameraPoses(const std::filesystem::path& file) {
  Eigen::Matrix3d M;
  M << 1, 0, 0, 0, 0, 1, 0, -1, 0;
  std::vector<Eigen::Isometry3d> poses;
  std::ifstream in(file);
  for (std::string line; std::getline(in, line);) {
    std::istringstream ls(line);
    Eigen::Matrix<double, 3, 4> m;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 4; ++c) ls >> m(r, c);
    }
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = M * m.leftCols<3>();
    T.translation() = M * m.col(3);
    poses.push_back(T);
  }
  return poses;
}

// Body positions along KITTI 00 (the camera is 1.65 m above the road); empty without the data.
inline std::vector<Eigen::Vector3d> kitti00Route() {
  const std::filesystem::path gt = std::string(GVIO_SHARED_DATA_DIR) + "/kitti00/KITTI_00_gt.txt";
  std::vector<Eigen::Vector3d> route;
  if (!std::filesystem::exists(gt)) return route;
  for (const auto& T : kittiCameraPoses(gt))
    route.push_back(T.translation() - Eigen::Vector3d(0, 0, kCameraHeight - kBodyHeight));
  return route;
}

}  // namespace gvio::sim::world_fixture
