// Layouts of the open_road, sparse_texture and vegetation worlds, from the street's object
// primitives (world_props.cpp) and its building rows (world_objects.cpp).
#include <algorithm>
#include <cmath>

#include "sim/world_parts.hpp"

namespace gvio::sim::detail {
namespace {

// A reflector post at the road's edge (1 m), as country roads have every 50 m.
void delineator(Street& street, const Station& st, double side) {
  const Footprint f = along(st, side, roadClearance(street) + 0.3, 0.06, 0.06);
  if (builtBefore(street, st) || !claim(street, f, roadClearance(street), 0.1)) return;
  const TextureLibrary& lib = street.lib;
  const BoxSkin metal{tiled(lib, lib.metal), tiled(lib, lib.metal), tiled(lib, lib.metal)};
  const double z = street.route.roadHeight(f.c);
  street.mesh.box(f, z - 0.3, z + 1.0, z, metal);
}

// Lines of trees along field edges, 30-150 m long with long gaps, all beyond the clearance.
void treeLines(Street& street, Rng& rng, double side) {
  const double first = street.stations.front().s, last = street.stations.back().s;
  for (double s = first + rng.uniform(0.0, 80.0); s < last;) {
    const double length = rng.uniform(30.0, 150.0), lateral = rng.uniform(35.0, 50.0);
    for (double t = s; t < std::min(s + length, last); t += rng.uniform(3.5, 7.0)) {
      treeAt(street, rng, stationAt(street.stations, t), side, lateral + rng.uniform(-1.0, 1.0),
             kOpenRoadClearance_m);
    }
    s += length + rng.uniform(40.0, 200.0);
  }
}

// Wooded or grassy hills up to 35 m high, their foot beyond the clearance and inside the terrain
// (230 m). They are terrain: they keep the clearance but take no part in the footprints, so trees
// and farms may stand on their slopes.
void hills(Street& street, Rng& rng, double side) {
  const double first = street.stations.front().s, last = street.stations.back().s;
  for (double s = first + rng.uniform(0.0, 100.0); s < last; s += rng.uniform(60.0, 150.0)) {
    const double radius = rng.uniform(20.0, 45.0), height = rng.uniform(12.0, 35.0);
    const double lateral =
        rng.uniform(kOpenRoadClearance_m + 10.0 + 1.2 * radius, 225.0 - 1.15 * radius);
    const Station st = stationAt(street.stations, s);
    const Footprint f = along(st, side, lateral, 1.2 * radius, 1.2 * radius);
    const bool wooded = rng.chance(0.5);
    if (builtBefore(street, st) || !street.route.clear(f, kOpenRoadClearance_m)) continue;
    const Eigen::Vector3d centre(f.c.x(), f.c.y(), street.route.roadHeight(f.c) - 0.3 * height);
    street.mesh.blob(centre, Eigen::Vector3d(radius, radius, height), rng,
                     wooded ? street.lib.foliage : street.lib.ground, 12.0);
  }
}

// Trees across the street beyond both ends close the view down the street.
void endGroves(Street& street, Rng& rng) {
  for (const Station* end : {&street.stations.front(), &street.stations.back()}) {
    const double dir = end == &street.stations.front() ? -1.0 : 1.0;
    for (const double ahead : {14.0, 20.0}) {
      for (double across = -24.0; across <= 24.0; across += rng.uniform(3.5, 5.5)) {
        Station st = *end;
        st.p += dir * (ahead + rng.uniform(-1.0, 1.0)) * st.t;
        treeAt(street, rng, st, 1.0, across, sidewalkClearance(street));
      }
    }
  }
}

}  // namespace

// Nothing but sparse poles and reflector posts within kOpenRoadClearance_m of the route: tree
// lines, a few farm buildings and hills beyond it.
void addOpenRoadObjects(Street& street, std::uint64_t seed) {
  Rng rng = Rng::derive(seed, 500);
  const double first = street.stations.front().s, last = street.stations.back().s;
  const RowSpec farms{36.0, 60.0, 10.0, 30.0, 8.0, 20.0, 5.0, 12.0, 0.85, 160.0, 0.5};
  for (const double side : {1.0, -1.0}) {
    for (double s = first + rng.uniform(0.0, 60.0); s < last; s += rng.uniform(60.0, 140.0))
      pole(street, rng, stationAt(street.stations, s), side);
    for (double s = first + rng.uniform(0.0, 50.0); s < last; s += 50.0)
      delineator(street, stationAt(street.stations, s), side);
    treeLines(street, rng, side);
    buildingRow(street, rng, side, farms, kOpenRoadClearance_m);
  }
  for (const double side : {1.0, -1.0}) hills(street, rng, side);
}

// Long plain blocks right behind the sidewalk with few gaps, a far row above them, poles now and
// then; the textures are the plain ones (restyleTextures).
void addSparseObjects(Street& street, std::uint64_t seed) {
  Rng rng = Rng::derive(seed, 700);
  const double w = street.options.road_half_width_m, sw = street.options.sidewalk_width_m;
  const double first = street.stations.front().s, last = street.stations.back().s;
  const RowSpec front{w + sw + 0.5, w + sw + 1.5, 30.0, 70.0, 12.0, 20.0,
                      10.0,         24.0,         0.15, 8.0,  -0.6};
  const RowSpec far{28.0, 40.0, 40.0, 80.0, 15.0, 25.0, 14.0, 30.0, 0.2, 15.0, 0.5};
  endWalls(street, rng);
  for (const RowSpec* row : {&front, &far}) {
    for (const double side : {1.0, -1.0})
      buildingRow(street, rng, side, *row, sidewalkClearance(street));
  }
  for (const double side : {1.0, -1.0}) {
    for (double s = first + rng.uniform(0.0, 40.0); s < last; s += rng.uniform(40.0, 80.0))
      pole(street, rng, stationAt(street.stations, s), side);
  }
}

// A leafy road without buildings: hedges along the sidewalk, street trees where they leave room, a
// row of trees behind them and woods further back, poles; groves close the view beyond the ends.
void addVegetationObjects(Street& street, std::uint64_t seed) {
  Rng rng = Rng::derive(seed, 600);
  const double first = street.stations.front().s, last = street.stations.back().s;
  endGroves(street, rng);
  for (const double side : {1.0, -1.0}) {
    for (double s = first + rng.uniform(0.0, 20.0); s < last; s += rng.uniform(20.0, 40.0))
      pole(street, rng, stationAt(street.stations, s), side);
    for (double s = first + rng.uniform(0.0, 10.0); s < last; s += rng.uniform(4.0, 12.0))
      hedge(street, rng, s, side);
    for (double s = first + rng.uniform(0.0, 6.0); s < last; s += rng.uniform(5.0, 10.0))
      tree(street, rng, stationAt(street.stations, s), side);
    for (double s = first + rng.uniform(0.0, 8.0); s < last; s += rng.uniform(4.0, 9.0)) {
      treeAt(street, rng, stationAt(street.stations, s), side, rng.uniform(10.5, 14.0),
             sidewalkClearance(street));
    }
    for (double s = first + rng.uniform(0.0, 8.0); s < last; s += rng.uniform(4.0, 9.0)) {
      treeAt(street, rng, stationAt(street.stations, s), side, rng.uniform(17.0, 45.0),
             sidewalkClearance(street));
    }
  }
}

}  // namespace gvio::sim::detail
