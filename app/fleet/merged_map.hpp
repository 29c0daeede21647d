#pragma once
// A `gvio merge` folder read back for drawing: tiles.json (tiles, drives, map frame),
// the tiles' PCD points (map frame) thinned to a budget, and the drives' tracks from
// tiles.geojson in the map frame.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace gvio::fleet {

struct MergedTile {
  std::string name;
  Eigen::Vector2d sw_map = Eigen::Vector2d::Zero();  // south-west corner in the map frame
  std::uint64_t points = 0;
};

struct MergedDrive {
  std::uint16_t point_source_id = 0;
  std::string name;
  std::vector<Eigen::Vector3d> track_map;  // map frame (empty without a track)
};

struct MergedMap {
  std::filesystem::path dir;
  double tile_size_m = 0.0;
  int utm_epsg = 0;
  std::vector<MergedTile> tiles;
  std::vector<MergedDrive> drives;
  std::vector<Eigen::Vector3f> points;         // map frame
  std::vector<std::uint16_t> point_source_id;  // one per point
  std::vector<std::uint8_t> source;            // one per point: 0 sparse landmark, 1 dense
  std::vector<std::uint8_t> intensity;         // one per point (0..255), 0 where tiles lack it
  int utm_zone = 0;
  bool utm_north = true;
  Eigen::Vector3d origin_utm = Eigen::Vector3d::Zero();  // the map frame's origin: E, N, h
  std::uint64_t total_points = 0;                        // before thinning
};

// Whether `dir` is a merged map (holds tiles.json).
bool isMergedMap(const std::filesystem::path& dir);

// Reads the map, keeping every k-th point of each tile so that at most about `max_points` remain.
// Throws InputError naming the file for a malformed tiles.json or tile, a missing tile file.
MergedMap readMergedMap(const std::filesystem::path& dir, std::size_t max_points);

}  // namespace gvio::fleet
