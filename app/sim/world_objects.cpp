// Buildings, trees, hedges, poles, signs and parked cars along both sides of the street. Every
// object is a footprint first: it is placed only if the footprint keeps its clearance from every
// route point (the road where the route crosses or revisits itself included) and does not overlap
// what is already there, so a street driven twice gets one row of buildings, not two.
#include <algorithm>
#include <cmath>
#include <numbers>

#include "sim/world_parts.hpp"

namespace gvio::sim::detail {
namespace {

double roadClearance(const Street& street) {  // minimum for anything above the road surface
  return street.options.road_half_width_m + 0.5;
}

double sidewalkClearance(const Street& street) {  // buildings stay behind the sidewalk
  return street.options.road_half_width_m + street.options.sidewalk_width_m + 0.3;
}

// Places f if it keeps `clearance` from the route and does not overlap what is placed (more than
// -margin when margin is negative: row buildings may touch).
bool claim(Street& street, const Footprint& f, double clearance, double margin) {
  if (!street.route.clear(f, clearance) || street.placed.overlaps(f, margin)) return false;
  street.placed.add(f);
  return true;
}

Footprint along(const Station& st, double side, double lateral, double half_l, double half_w) {
  return {st.p + side * lateral * st.n, st.t, half_l, half_w};
}

// Floors start at the street's height in front; the walls reach 1 m below the lowest corner, so
// no corner floats on a slope.
void buildingMesh(Street& street, Rng& rng, const Footprint& f, double height) {
  const double z_ground = street.route.roadHeight(f.c);
  double z_base = z_ground;
  for (const auto& c : f.corners()) z_base = std::min(z_base, street.route.roadHeight(c));
  const TextureLibrary& lib = street.lib;
  const auto style =
      static_cast<std::size_t>(rng.integer(0, static_cast<int>(lib.facade_front.size()) - 1));
  const BoxSkin walls{tiled(lib, lib.facade_front[style], rng.uniform(0.0, 1.0)),
                      tiled(lib, lib.facade_side[style], rng.uniform(0.0, 1.0)),
                      tiled(lib, lib.roof)};
  const double top = z_ground + height, cornice = rng.uniform(0.3, 0.6);
  street.mesh.box(f, z_base - 1.0, top - cornice, z_ground, walls);
  const BoxSkin roof{tiled(lib, lib.roof), tiled(lib, lib.roof), tiled(lib, lib.roof)};
  street.mesh.box(f.grown(0.25), top - cornice, top, z_ground, roof);
}

struct RowSpec {
  double lateral_lo, lateral_hi;  // front face from the centre line (m)
  double width_lo, width_hi, depth_lo, depth_hi, height_lo, height_hi;
  double gap_chance, gap_hi;  // chance of a gap between buildings, its largest size
  double margin;              // overlap allowance against placed footprints
};

// One row of buildings along one side. A building that does not fit is tried half and a quarter
// as wide (not under 6 m): bends and crossings leave short stretches.
void buildingRow(Street& street, Rng& rng, double side, const RowSpec& spec) {
  const double first = street.stations.front().s, last = street.stations.back().s;
  for (double s = first + rng.uniform(0.0, 10.0); s < last;) {
    const double width = rng.uniform(spec.width_lo, spec.width_hi);
    const double depth = rng.uniform(spec.depth_lo, spec.depth_hi);
    const double u = rng.uniform();
    const double height = spec.height_lo + (spec.height_hi - spec.height_lo) * u * u;
    const double front = rng.uniform(spec.lateral_lo, spec.lateral_hi);
    double used = 0.25 * width;  // how far the row moves on when nothing fits
    for (const double fraction : {1.0, 0.5, 0.25}) {
      const double wide = fraction * width;
      if (fraction < 1.0 && wide < 6.0) break;
      const Station st = stationAt(street.stations, s + wide / 2.0);
      const Footprint f = along(st, side, front + depth / 2.0, wide / 2.0, depth / 2.0);
      if (claim(street, f.grown(0.25), sidewalkClearance(street), spec.margin)) {
        buildingMesh(street, rng, f, height);
        used = wide;
        break;
      }
    }
    s += used + (rng.chance(spec.gap_chance) ? rng.uniform(2.0, spec.gap_hi) : 0.0);
  }
}

// Facades across the street beyond both extension ends close the view down the street.
void endWalls(Street& street, Rng& rng) {
  for (const Station* st : {&street.stations.front(), &street.stations.back()}) {
    const double dir = st == &street.stations.front() ? -1.0 : 1.0;
    const double depth = 12.0;
    const Footprint f{st->p + dir * (12.0 + depth / 2.0) * st->t, st->n, 30.0, depth / 2.0};
    if (claim(street, f.grown(0.25), sidewalkClearance(street), 0.0))
      buildingMesh(street, rng, f, rng.uniform(12.0, 20.0));
  }
}

void tree(Street& street, Rng& rng, const Station& st, double side) {
  const double w = street.options.road_half_width_m, sw = street.options.sidewalk_width_m;
  const double r = rng.uniform(1.4, 2.6), trunk_h = rng.uniform(2.2, 3.5);
  const double lateral = std::max(w + sw + rng.uniform(0.4, 1.5), roadClearance(street) + 1.2 * r);
  const Footprint crown = along(st, side, lateral, 1.2 * r, 1.2 * r);
  if (!claim(street, crown, roadClearance(street), 0.1)) return;
  const TextureLibrary& lib = street.lib;
  const Footprint trunk{crown.c, st.t, 0.15, 0.15};
  const BoxSkin bark{tiled(lib, lib.bark), tiled(lib, lib.bark), tiled(lib, lib.bark)};
  const double z = street.route.roadHeight(crown.c) + kCurbHeight;
  street.mesh.box(trunk, z - 0.3, z + trunk_h + 0.5 * r, z, bark);
  // Crown: a core and lumps around it, all inside the claimed footprint (1.2 r).
  const Eigen::Vector3d centre(crown.c.x(), crown.c.y(), z + trunk_h + 0.8 * r);
  street.mesh.blob(centre, Eigen::Vector3d(0.75 * r, 0.75 * r, 0.7 * r), rng, lib.foliage, 3.0);
  const int lumps = rng.integer(4, 6);
  for (int k = 0; k < lumps; ++k) {
    const double a = (k + rng.uniform(0.0, 0.6)) * 2.0 * std::numbers::pi / lumps;
    const double lump = rng.uniform(0.35, 0.5) * r, reach = 0.95 * r - 1.15 * lump;
    const Eigen::Vector3d offset(reach * std::cos(a), reach * std::sin(a),
                                 rng.uniform(-0.3, 0.5) * r);
    street.mesh.blob(centre + offset, Eigen::Vector3d::Constant(lump), rng, lib.foliage, 3.0);
  }
}

void hedge(Street& street, Rng& rng, double s, double side) {
  const double w = street.options.road_half_width_m, sw = street.options.sidewalk_width_m;
  const double length = rng.uniform(3.0, 10.0), depth = rng.uniform(0.6, 1.0);
  const Station st = stationAt(street.stations, s + length / 2.0);
  const Footprint f = along(st, side, w + sw + 0.2 + depth / 2.0, length / 2.0, depth / 2.0);
  if (!claim(street, f, roadClearance(street), 0.1)) return;
  const TextureLibrary& lib = street.lib;
  const BoxSkin leaves{tiled(lib, lib.foliage), tiled(lib, lib.foliage), tiled(lib, lib.foliage)};
  const double z = street.route.roadHeight(f.c) + kCurbHeight;
  street.mesh.box(f, z - 0.2, z + rng.uniform(0.8, 1.6), z, leaves);
}

// Street lamp (mast and a head reaching towards the road) or a traffic sign. `reach` covers
// both: its inner edge stays 0.05 m outside the road clearance.
void pole(Street& street, Rng& rng, const Station& st, double side) {
  const double lateral = roadClearance(street) + 0.8;
  const bool lamp = rng.chance(0.6);
  const Footprint reach = along(st, side, lateral - 0.3, 0.35, 0.45);
  if (!claim(street, reach, roadClearance(street), 0.1)) return;
  const TextureLibrary& lib = street.lib;
  const BoxSkin metal{tiled(lib, lib.metal), tiled(lib, lib.metal), tiled(lib, lib.metal)};
  const double z = street.route.roadHeight(reach.c) + kCurbHeight,
               height = lamp ? rng.uniform(6.0, 8.0) : 2.8;
  street.mesh.box(along(st, side, lateral, 0.08, 0.08), z - 0.2, z + height, z, metal);
  if (lamp) {
    street.mesh.box(along(st, side, lateral - 0.3, 0.15, 0.4), z + height - 0.2, z + height, z,
                    metal);
    return;
  }
  // Sign plate facing the traffic: a thin box across the street direction.
  const Footprint plate{st.p + side * lateral * st.n, st.n, 0.32, 0.03};
  const BoxSkin paint{stretched(lib.sign, 0.64, 0.64), tiled(lib, lib.metal),
                      tiled(lib, lib.metal)};
  street.mesh.box(plate, z + 2.0, z + 2.64, z + 2.0, paint);
}

void car(Street& street, Rng& rng, double s, double side) {
  const Station st = stationAt(street.stations, s);
  const double lateral = roadClearance(street) + 0.92 + rng.uniform(0.0, 0.3);
  Footprint body = along(st, side, lateral, 2.1, 0.9);
  const double yaw = rng.uniform(-0.04, 0.04);
  body.axis = Eigen::Vector2d(body.axis.x() * std::cos(yaw) - body.axis.y() * std::sin(yaw),
                              body.axis.x() * std::sin(yaw) + body.axis.y() * std::cos(yaw));
  if (!claim(street, body, roadClearance(street), 0.2)) return;
  const TextureLibrary& lib = street.lib;
  const double z = street.route.roadHeight(body.c) + kCurbHeight;
  const FaceSkin tyre = stretched(lib.tyre, 0.62, 0.62);
  for (const double axle : {-1.3, 1.3}) {
    const Footprint wheels{body.c + axle * body.axis, body.axis, 0.31, 0.85};
    street.mesh.box(wheels, z, z + 0.62, z, {tyre, tyre, tyre});
  }
  const std::size_t paint = lib.car_body[static_cast<std::size_t>(
      rng.integer(0, static_cast<int>(lib.car_body.size()) - 1))];
  const FaceSkin roof_paint{paint, 0.5, 0.0, 0.08, 0.0};
  street.mesh.box(
      body, z + 0.25, z + 1.0, z + 0.25,
      {stretched(paint, 4.2, 0.75), stretched(paint, 1.8, 0.75, 0.44, 0.56), roof_paint});
  const double cabin_l = rng.uniform(2.0, 2.5);
  const Footprint cabin{body.c - 0.2 * body.axis, body.axis, cabin_l / 2.0, 0.78};
  const FaceSkin cabin_roof{lib.cabin, 0.5, 0.0, 0.95, 0.0};
  street.mesh.box(
      cabin, z + 1.0, z + 1.45, z + 1.0,
      {stretched(lib.cabin, cabin_l, 0.45), stretched(lib.cabin, 1.56, 0.45), cabin_roof},
      0.35);  // raked windscreen and rear window
}

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

void addBuildings(Street& street, std::uint64_t seed) {
  Rng rng = Rng::derive(seed, 200);
  const double w = street.options.road_half_width_m, sw = street.options.sidewalk_width_m;
  const RowSpec front{w + sw + 1.0, w + sw + 6.0, 8.0, 30.0, 8.0, 16.0, 6.0, 25.0, 0.3, 12.0, -0.6};
  const RowSpec middle{17.0, 26.0, 10.0, 25.0, 8.0, 14.0, 8.0, 22.0, 0.4, 10.0, 0.5};
  const RowSpec far{30.0, 42.0, 15.0, 40.0, 10.0, 20.0, 8.0, 30.0, 0.3, 15.0, 0.5};
  endWalls(street, rng);
  for (const RowSpec* row : {&front, &middle, &far}) {  // nearer rows first: they matter more
    for (const double side : {1.0, -1.0}) buildingRow(street, rng, side, *row);
  }
}

void addStreetFurniture(Street& street, std::uint64_t seed) {
  Rng rng = Rng::derive(seed, 300);
  for (const double side : {1.0, -1.0}) furnitureSide(street, rng, side);
}

}  // namespace gvio::sim::detail
