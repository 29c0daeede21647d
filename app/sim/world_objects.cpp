// The street's layout: three rows of buildings on both sides (nearer rows first: they matter
// more), facades closing the view beyond both ends, and the street furniture: poles, parked cars
// in groups, trees and hedges (object primitives in world_props.cpp).
#include <algorithm>
#include <cmath>

#include "sim/world_parts.hpp"

namespace gvio::sim::detail {
namespace {

void furnitureSide(Street& street, Rng& rng, double side) {
  const double first = street.stations.front().s, last = street.stations.back().s;
  for (double s = first + rng.uniform(0.0, 20.0); s < last; s += rng.uniform(20.0, 45.0))
    pole(street, rng, stationAt(street.stations, s), side);
  for (double s = first + rng.uniform(0.0, 10.0); s < last;) {  // parked cars, in groups
    if (rng.chance(0.5)) {
      const int n = rng.integer(1, 5);
      for (int k = 0; k < n; ++k, s += rng.uniform(4.8, 6.5)) car(street, rng, s, side);
    }
    s += rng.uniform(8.0, 35.0);
  }
  for (double s = first + rng.uniform(0.0, 8.0); s < last; s += rng.uniform(7.0, 18.0)) {
    if (rng.chance(0.7)) tree(street, rng, stationAt(street.stations, s), side);
  }
  for (double s = first + rng.uniform(0.0, 30.0); s < last; s += rng.uniform(20.0, 60.0))
    hedge(street, rng, s, side);
}

}  // namespace

// A building that does not fit is tried half and a quarter as wide (not under 6 m): bends and
// crossings leave short stretches.
void buildingRow(Street& street, Rng& rng, double side, const RowSpec& spec, double clearance) {
  const double first = street.stations.front().s, last = street.stations.back().s;
  for (double s = first + rng.uniform(0.0, 10.0); s < last;) {
    const double width = rng.uniform(spec.width_lo, spec.width_hi);
    const double depth = rng.uniform(spec.depth_lo, spec.depth_hi);
    const double u = rng.uniform();
    const double height = spec.height_lo + (spec.height_hi - spec.height_lo) * u * u;
    const double front = rng.uniform(spec.lateral_lo, spec.lateral_hi);
    double used = 0.25 * width;  // how far the row moves on when nothing fits
    const bool skip = builtBefore(street, stationAt(street.stations, s));
    for (const double fraction : {1.0, 0.5, 0.25}) {
      if (skip) break;
      const double wide = fraction * width;
      if (fraction < 1.0 && wide < 6.0) break;
      const Station st = stationAt(street.stations, s + wide / 2.0);
      const Footprint f = along(st, side, front + depth / 2.0, wide / 2.0, depth / 2.0);
      if (claim(street, f.grown(0.25), clearance, spec.margin)) {
        buildingMesh(street, rng, f, height);
        used = wide;
        break;
      }
    }
    s += used + (rng.chance(spec.gap_chance) ? rng.uniform(2.0, spec.gap_hi) : 0.0);
  }
}

void endWalls(Street& street, Rng& rng) {
  for (const Station* st : {&street.stations.front(), &street.stations.back()}) {
    const double dir = st == &street.stations.front() ? -1.0 : 1.0;
    const double depth = 12.0;
    const Footprint f{st->p + dir * (12.0 + depth / 2.0) * st->t, st->n, 30.0, depth / 2.0};
    if (claim(street, f.grown(0.25), sidewalkClearance(street), 0.0))
      buildingMesh(street, rng, f, rng.uniform(12.0, 20.0));
  }
}

void addBuildings(Street& street, std::uint64_t seed) {
  Rng rng = Rng::derive(seed, 200);
  const double w = street.options.road_half_width_m, sw = street.options.sidewalk_width_m;
  const RowSpec front{w + sw + 1.0, w + sw + 6.0, 8.0, 30.0, 8.0, 16.0, 6.0, 25.0, 0.3, 12.0, -0.6};
  const RowSpec middle{17.0, 26.0, 10.0, 25.0, 8.0, 14.0, 8.0, 22.0, 0.4, 10.0, 0.5};
  const RowSpec far{30.0, 42.0, 15.0, 40.0, 10.0, 20.0, 8.0, 30.0, 0.3, 15.0, 0.5};
  endWalls(street, rng);
  for (const RowSpec* row : {&front, &middle, &far}) {
    for (const double side : {1.0, -1.0})
      buildingRow(street, rng, side, *row, sidewalkClearance(street));
  }
}

void addStreetFurniture(Street& street, std::uint64_t seed) {
  Rng rng = Rng::derive(seed, 300);
  for (const double side : {1.0, -1.0}) furnitureSide(street, rng, side);
}

}  // namespace gvio::sim::detail
