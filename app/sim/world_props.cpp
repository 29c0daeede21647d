// Object primitives of the world: buildings, trees, hedges, poles, signs and parked cars. Every
// object is a footprint first: it is placed only if the footprint keeps its clearance from every
// route point (the road where the route crosses or revisits itself included) and does not overlap
// what is already there, so a street driven twice gets one row of buildings, not two.
#include <algorithm>
#include <cmath>
#include <numbers>

#include "sim/world_parts.hpp"

namespace gvio::sim::detail {

double roadClearance(const Street& street) {
  return street.options.road_half_width_m + 0.5;
}

double sidewalkClearance(const Street& street) {
  return street.options.road_half_width_m + street.options.sidewalk_width_m + 0.3;
}

bool claim(Street& street, const Footprint& f, double clearance, double margin) {
  if (!street.route.clear(f, clearance) || street.placed.overlaps(f, margin)) return false;
  street.placed.add(f);
  return true;
}

Footprint along(const Station& st, double side, double lateral, double half_l, double half_w) {
  return {st.p + side * lateral * st.n, st.t, half_l, half_w};
}

BuildingSkin randomSkin(const TextureLibrary& lib, Rng& rng) {
  BuildingSkin skin;
  skin.style =
      static_cast<std::size_t>(rng.integer(0, static_cast<int>(lib.facade_front.size()) - 1));
  skin.u_front = rng.uniform(0.0, 1.0);
  skin.u_side = rng.uniform(0.0, 1.0);
  skin.cornice_m = rng.uniform(0.3, 0.6);
  return skin;
}

// Floors start at the street's height in front; the walls reach 1 m below the lowest corner, so
// no corner floats on a slope.
void buildingMesh(Street& street, const Footprint& f, double height, const BuildingSkin& skin) {
  const double z_ground = street.route.roadHeight(f.c);
  double z_base = z_ground;
  for (const auto& c : f.corners()) z_base = std::min(z_base, street.route.roadHeight(c));
  const TextureLibrary& lib = street.lib;
  const BoxSkin walls{tiled(lib, lib.facade_front[skin.style], skin.u_front),
                      tiled(lib, lib.facade_side[skin.style], skin.u_side), tiled(lib, lib.roof)};
  const double top = z_ground + height;
  street.mesh.box(f, z_base - 1.0, top - skin.cornice_m, z_ground, walls);
  const BoxSkin roof{tiled(lib, lib.roof), tiled(lib, lib.roof), tiled(lib, lib.roof)};
  street.mesh.box(f.grown(0.25), top - skin.cornice_m, top, z_ground, roof);
}

void buildingMesh(Street& street, Rng& rng, const Footprint& f, double height) {
  buildingMesh(street, f, height, randomSkin(street.lib, rng));
}

void treeMesh(Street& street, Rng& rng, const Eigen::Vector2d& c, const Eigen::Vector2d& axis,
              double r, double trunk_h) {
  const TextureLibrary& lib = street.lib;
  const Footprint trunk{c, axis, 0.15, 0.15};
  const BoxSkin bark{tiled(lib, lib.bark), tiled(lib, lib.bark), tiled(lib, lib.bark)};
  const double z = street.route.roadHeight(c) + kCurbHeight;
  street.mesh.box(trunk, z - 0.3, z + trunk_h + 0.5 * r, z, bark);
  // Crown: a core and lumps around it, all inside the claimed footprint (1.2 r).
  const Eigen::Vector3d centre(c.x(), c.y(), z + trunk_h + 0.8 * r);
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

void tree(Street& street, Rng& rng, const Station& st, double side) {
  if (builtBefore(street, st)) return;
  const double w = street.options.road_half_width_m, sw = street.options.sidewalk_width_m;
  const double r = rng.uniform(1.4, 2.6), trunk_h = rng.uniform(2.2, 3.5);
  const double lateral = std::max(w + sw + rng.uniform(0.4, 1.5), roadClearance(street) + 1.2 * r);
  const Footprint crown = along(st, side, lateral, 1.2 * r, 1.2 * r);
  if (!claim(street, crown, roadClearance(street), 0.1)) return;
  treeMesh(street, rng, crown.c, st.t, r, trunk_h);
}

void treeAt(Street& street, Rng& rng, const Station& st, double side, double lateral,
            double clearance) {
  if (builtBefore(street, st)) return;
  const double r = rng.uniform(1.4, 2.8), trunk_h = rng.uniform(2.0, 4.0);
  const Footprint crown = along(st, side, lateral, 1.2 * r, 1.2 * r);
  if (!claim(street, crown, clearance, 0.1)) return;
  treeMesh(street, rng, crown.c, st.t, r, trunk_h);
}

void hedge(Street& street, Rng& rng, double s, double side) {
  const double w = street.options.road_half_width_m, sw = street.options.sidewalk_width_m;
  const double length = rng.uniform(3.0, 10.0), depth = rng.uniform(0.6, 1.0);
  const Station st = stationAt(street.stations, s + length / 2.0);
  const Footprint f = along(st, side, w + sw + 0.2 + depth / 2.0, length / 2.0, depth / 2.0);
  if (builtBefore(street, st) || !claim(street, f, roadClearance(street), 0.1)) return;
  const TextureLibrary& lib = street.lib;
  const BoxSkin leaves{tiled(lib, lib.foliage), tiled(lib, lib.foliage), tiled(lib, lib.foliage)};
  const double z = street.route.roadHeight(f.c) + kCurbHeight;
  street.mesh.box(f, z - 0.2, z + rng.uniform(0.8, 1.6), z, leaves);
}

// Street lamp (mast and a head reaching towards the road) or a traffic sign. The claimed `reach`
// covers both: its inner edge stays 0.05 m outside the road clearance.
bool claimPole(Street& street, const Station& st, double side) {
  if (builtBefore(street, st)) return false;
  const double lateral = roadClearance(street) + 0.8;
  return claim(street, along(st, side, lateral - 0.3, 0.35, 0.45), roadClearance(street), 0.1);
}

void poleMesh(Street& street, const Station& st, double side, bool lamp, double height) {
  const double lateral = roadClearance(street) + 0.8;
  const TextureLibrary& lib = street.lib;
  const BoxSkin metal{tiled(lib, lib.metal), tiled(lib, lib.metal), tiled(lib, lib.metal)};
  const double z =
      street.route.roadHeight(along(st, side, lateral - 0.3, 0.35, 0.45).c) + kCurbHeight;
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

void pole(Street& street, Rng& rng, const Station& st, double side) {
  const bool lamp = rng.chance(0.6);
  if (!claimPole(street, st, side)) return;
  poleMesh(street, st, side, lamp, lamp ? rng.uniform(6.0, 8.0) : 2.8);
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

}  // namespace gvio::sim::detail
