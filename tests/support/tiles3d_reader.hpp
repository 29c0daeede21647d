#pragma once
// The tests' own reader of a 3D Tiles 1.0 point-cloud tileset (tileset.json + .pnts), written
// from the specification (OGC 18-053r2, "Point Cloud"), not from gvio's writer: every length,
// offset and 8-byte padding the specification requires is checked, and a violation throws
// std::runtime_error naming the file.
#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace gvio::test {

struct PntsTile {
  Eigen::Vector3d rtc_center = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> p_ecef;  // RTC_CENTER + POSITION
  std::vector<std::array<std::uint8_t, 3>> rgb;
  std::vector<std::uint16_t> intensity, drive_id;  // the batch table's properties
};

PntsTile readPnts(const std::filesystem::path& file);

struct TilesetTile {
  int parent = -1;               // index into the flattened list, -1 for the root
  std::array<double, 12> box{};  // boundingVolume.box: centre, then three half-axes
  double geometric_error = 0.0;
  std::string refine;  // as written on the tile ("" when inherited)
  std::string uri;     // "" without content
  PntsTile content;
};

struct Tileset {
  std::string version;
  double geometric_error = 0.0;
  std::vector<TilesetTile> tiles;  // depth first, the root first
};

Tileset readTileset(const std::filesystem::path& dir);

// Whether an ECEF point lies in a tile's box (within `slack_m` metres along each axis).
bool boxContains(const std::array<double, 12>& box, const Eigen::Vector3d& p, double slack_m);

}  // namespace gvio::test
