#pragma once
// `gvio consistency --run MAP` for a `gvio merge` folder: the merged points against a reference
// mesh, overall and per drive (mapping/consistency.hpp's statistics). The mesh is given in a
// local ENU frame at `mesh_origin` (a simulated drive's world/world.ply: the simulator's origin);
// its vertices are carried into the map frame (UTM less the map origin) exactly, as the points
// were (fusion/enu_utm_grid.hpp).
#include <nlohmann/json.hpp>

#include "fleet/merged_map.hpp"
#include "fusion/geodesy.hpp"
#include "io/mesh_ply.hpp"
#include "mapping/consistency.hpp"

namespace gvio::fleet {

// Point-to-surface statistics as `gvio consistency --json` writes them, the median judged
// against `target_median_m` (a run's consistency and a merged map's).
nlohmann::json surfaceStatsJson(const mapping::SurfaceDistanceStats& s, double target_median_m);

// The mesh's vertices in the map's frame.
io::TriangleMesh meshInMapFrame(io::TriangleMesh mesh, const fusion::Lla& mesh_origin,
                                const MergedMap& map);

// {"dense": stats, "sparse": stats, "drives": [{point_source_id, name, dense: stats}]}, the
// statistics of mapping::cloudToSurface with `max_distance_m` as the search radius, the dense
// median judged against `dense_target_m` and the sparse one against `sparse_target_m`.
nlohmann::json mergedConsistency(const MergedMap& map, const io::TriangleMesh& mesh_in_map,
                                 double max_distance_m, double dense_target_m,
                                 double sparse_target_m);

}  // namespace gvio::fleet
