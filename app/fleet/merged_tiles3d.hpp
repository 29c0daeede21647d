#pragma once
// `gvio export --run MAP --to 3dtiles` for a merged map (a `gvio merge` folder): every tile's
// points as one OGC 3D Tiles tileset (export/tiles3d_writer.hpp), their drive (point source id)
// in each point's drive_id.
#include <filesystem>

#include "export/tiles3d_writer.hpp"

namespace gvio::fleet {

// The map frame (UTM less the map's origin) taken to the local ENU frame at the map's origin,
// exactly at the centre of each 100 m cell of the map and linearly around it (a cell's map is
// affine to 0.4 mm: the Earth's curvature at a cell's corner, 71 m from its centre). Throws
// InputError naming the map's files when they are malformed.
exporter::Tiles3dSummary exportMergedTiles3d(const std::filesystem::path& map_dir,
                                             const std::filesystem::path& out);

}  // namespace gvio::fleet
