#pragma once
// A procedural street world along a route, deterministic by seed: textured road with markings,
// sidewalks, facades with varied setbacks/heights and windows/bricks, trees, poles, parked cars.
// Everything is triangles + procedurally generated grey textures, in the route's ENU frame.
#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "render/scene.hpp"

namespace gvio::sim {

struct WorldOptions {
  std::uint64_t seed = 1;
  double road_half_width_m = 4.5;
  double sidewalk_width_m = 2.5;
  double body_height_m = 0.93;  // height of the body (IMU) origin above the road surface (KITTI)
  int texture_size_px = 512;
};

struct World {
  render::Scene scene;  // meshes + textures only
  std::size_t triangles = 0;
};

// `route_w` are body positions along the drive (e.g. every 0.5-2 m, ENU); the road surface runs
// body_height_m below them. Nothing is placed on the road itself, where the route crosses itself
// included.
World buildWorld(const std::vector<Eigen::Vector3d>& route_w, const WorldOptions& options);

}  // namespace gvio::sim
