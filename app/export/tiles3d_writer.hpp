#pragma once
// OGC 3D Tiles 1.0 point clouds (https://docs.ogc.org/cs/18-053r2/18-053r2.html), which CesiumJS
// and QGIS (3.34+) stream: a folder with tileset.json and one .pnts tile per node of
// mapping::buildPointLod's octree (additive refinement: a tile adds its points to its parent's).
//   - tileset.json: asset 1.0, per tile a bounding volume "box" in ECEF (WGS 84, metres: the
//     tile's points' ENU bounds turned into ECEF, centre and three half-axes), a geometric error
//     (the tile's sampling spacing, 0 for a tile holding all its points) and its content uri;
//   - tiles/NAME.pnts: POINTS_LENGTH, RTC_CENTER (ECEF of the tile's centre), POSITION as float32
//     relative to it (sub-millimetre for a tile under 10 km), RGB (the intensity as grey); the
//     batch table holds per point "intensity" (UNSIGNED_SHORT, LAS's 16-bit scale) and "drive_id"
//     (UNSIGNED_SHORT, LAS's point source id: the drive of a merged map, 0 for one run).
// Every header and section is padded to 8 bytes as the specification requires.
#include <Eigen/Core>

#include <cstdint>
#include <filesystem>
#include <span>

#include "fusion/geodesy.hpp"
#include "mapping/point_lod.hpp"

namespace gvio::exporter {

struct TilesPoint {
  Eigen::Vector3d p_enu = Eigen::Vector3d::Zero();
  std::uint16_t intensity = 0;  // 0..65535 (LAS 1.4 scale)
  std::uint16_t drive_id = 0;
};

struct Tiles3dSummary {
  std::size_t points = 0;  // written (the finite ones)
  std::size_t tiles = 0;
  int depth = 0;  // the deepest tile's level (0: the root alone)
};

// Writes the tileset into the folder `dir` (made, or replaced when it holds an earlier
// tileset.json; any other existing folder is refused): built beside it and renamed into place,
// so a reader never sees half a tileset. Throws InputError naming `dir` when it cannot be
// written, InvalidInput when no point is finite.
Tiles3dSummary writeTiles3d(const std::filesystem::path& dir, const fusion::Lla& enu_origin,
                            std::span<const TilesPoint> points,
                            const mapping::PointLodConfig& lod = {});

}  // namespace gvio::exporter
