#pragma once
// A procedural street world along a route, deterministic by seed: textured road with markings,
// sidewalks, facades with varied setbacks/heights and windows/bricks, trees, poles, parked cars.
// Everything is triangles + procedurally generated grey textures, in the route's ENU frame.
// World styles give the same route other looks, so tests and benchmarks do not reward one look.
#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

#include "render/scene.hpp"

namespace gvio::sim {

enum class WorldStyle {
  kStreet,         // rows of textured buildings, trees, hedges, poles and parked cars
  kOpenRoad,       // a country road: only sparse poles near it, structure beyond 30 m
  kSparseTexture,  // long plain low-contrast walls, plain sidewalks: few corners
  kRepetitive,     // identical buildings and furniture every kRepetitivePeriod_m
  kVegetation,     // trees, hedges and poles, no buildings
};
inline constexpr std::string_view kWorldStyleNames =
    "street, open_road, sparse_texture, repetitive, vegetation";
std::optional<WorldStyle> parseWorldStyle(std::string_view name);
const char* toString(WorldStyle style);

// The repetitive world's period along the road (m): on a straight road the view at arc length s
// and at s + kRepetitivePeriod_m is the same. Shorter than the loop search radius (10 m plus the
// drift allowance), so a place one period away is a candidate loop closure has to reject.
inline constexpr double kRepetitivePeriod_m = 12.0;
// Open road: nothing but the road surface, paint and poles within this distance of the route.
inline constexpr double kOpenRoadClearance_m = 30.0;

struct WorldOptions {
  std::uint64_t seed = 1;
  WorldStyle style = WorldStyle::kStreet;
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
// included, and a street driven twice is built once (both passes see the same objects).
World buildWorld(const std::vector<Eigen::Vector3d>& route_w, const WorldOptions& options);

}  // namespace gvio::sim
