// Street surfaces along the stations: asphalt in three lanes, paint, manholes and drains, curbs
// and sidewalks, ground out to 62 m and a coarse terrain below. Where the route crosses or
// revisits itself, surfaces are layered so nothing z-fights: every vertex lies on one shared
// height field, ground below the road, asphalt and ground mapped in world coordinates (two passes
// draw the same texels), sidewalks and paint dropped where they would lie on another pass's road.
// The world style varies the layout (SurfaceSpec); `street` is the reference.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <set>

#include "sim/world_parts.hpp"

namespace gvio::sim::detail {
namespace {

constexpr double kGroundDrop = 0.06;   // ground below the road: the road wins at crossings
constexpr double kMarkingLift = 0.02;  // paint above the asphalt
constexpr double kDecalLift = 0.015;   // manholes and drains above the asphalt

// What the style changes about the surfaces.
struct SurfaceSpec {
  bool sidewalks = true;
  // A later pass along a street already driven adds no sidewalk of its own (street: it does, and
  // the two coincide).
  bool dedupe_sidewalks = false;
  // World-mapped textures are turned by this angle, so their repeats do not line up with streets
  // (which mostly run along the axes of a planned city); the repetitive world wants them to.
  double uv_angle_rad = 0.41;
  double dash_m = 3.0, dash_period_m = 9.0;                                     // centre line
  enum class Details { kRandom, kNone, kPeriodic } details = Details::kRandom;  // manholes, drains
  double ground_reach_m = 62.0, ground_piece_m = 6.0;  // lateral extent of the ground strips
  double terrain_cell_m = 10.0, terrain_reach_m = 80.0, terrain_drop_m = 1.0;
};

SurfaceSpec surfaceSpec(WorldStyle style) {
  SurfaceSpec spec;
  if (style != WorldStyle::kStreet) spec.dedupe_sidewalks = true;
  switch (style) {
    case WorldStyle::kStreet:
    case WorldStyle::kVegetation:
      break;
    case WorldStyle::kOpenRoad:  // a country road: grass to the asphalt, fields to the hills
      spec.sidewalks = false;
      spec.details = SurfaceSpec::Details::kNone;
      spec.ground_reach_m = 150.0;
      spec.ground_piece_m = 12.0;
      spec.terrain_cell_m = 20.0;
      spec.terrain_reach_m = 230.0;
      spec.terrain_drop_m = 0.5;
      break;
    case WorldStyle::kSparseTexture:
      spec.details = SurfaceSpec::Details::kNone;
      break;
    case WorldStyle::kRepetitive:  // every repeat and piece divides the period
      spec.uv_angle_rad = 0.0;
      spec.dash_m = 4.0;
      spec.dash_period_m = kRepetitivePeriod_m;
      spec.details = SurfaceSpec::Details::kPeriodic;
      spec.terrain_cell_m = kRepetitivePeriod_m;
      break;
  }
  return spec;
}

// A point across the street at a station, on the shared height field (not the station's own
// height): wherever two passes' surfaces overlap they coincide.
Eigen::Vector3d at(const Street& street, const Station& st, double lateral, double dz) {
  const Eigen::Vector2d p = st.p + lateral * st.n;
  return {p.x(), p.y(), street.route.roadHeight(p) + dz};
}

// Texture coordinates from world x-y, turned by the spec's angle.
Eigen::Vector2d worldUv(const Eigen::Vector2d& p, const Eigen::Vector2d& tile, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  return Eigen::Vector2d(c * p.x() - s * p.y(), s * p.x() + c * p.y()).cwiseQuotient(tile);
}

// Horizontal strip between two stations over [l0, l1], texture in world coordinates.
void worldStrip(Street& street, std::size_t tex, const Station& a, const Station& b, double l0,
                double l1, double dz, double uv_angle) {
  const Eigen::Vector2d tile = street.lib.tile_m[tex];
  const std::array<Eigen::Vector3d, 4> p{at(street, a, l0, dz), at(street, a, l1, dz),
                                         at(street, b, l1, dz), at(street, b, l0, dz)};
  std::array<Eigen::Vector2d, 4> uv;
  for (std::size_t i = 0; i < 4; ++i) uv[i] = worldUv(p[i].head<2>(), tile, uv_angle);
  street.mesh.quad(tex, p, uv);
}

// Strip with texture along the street: u across (from l_ref), v along the arc length.
void streetStrip(Street& street, std::size_t tex, const Station& a, const Station& b, double l0,
                 double l1, double dz0, double dz1, double l_ref, double v_scale) {
  const Eigen::Vector2d tile = street.lib.tile_m[tex];
  const double u0 = std::abs(l0 - l_ref) / tile.x(), u1 = std::abs(l1 - l_ref) / tile.x();
  const double va = a.s / (v_scale * tile.y()), vb = b.s / (v_scale * tile.y());
  street.mesh.quad(tex,
                   {at(street, a, l0, dz0), at(street, a, l1, dz1), at(street, b, l1, dz1),
                    at(street, b, l0, dz0)},
                   {Eigen::Vector2d(u0, va), Eigen::Vector2d(u1, va), Eigen::Vector2d(u1, vb),
                    Eigen::Vector2d(u0, vb)});
}

// Vertical face at lateral l between two stations (curbs), texture along the street.
void curbFace(Street& street, const Station& a, const Station& b, double l, double z0, double z1) {
  const std::size_t tex = street.lib.curb;
  const Eigen::Vector2d tile = street.lib.tile_m[tex];
  const double ua = a.s / tile.x(), ub = b.s / tile.x();
  street.mesh.quad(
      tex, {at(street, a, l, z0), at(street, b, l, z0), at(street, b, l, z1), at(street, a, l, z1)},
      {Eigen::Vector2d(ua, 1.0), Eigen::Vector2d(ub, 1.0),
       Eigen::Vector2d(ub, 1.0 - (z1 - z0) / tile.y()),
       Eigen::Vector2d(ua, 1.0 - (z1 - z0) / tile.y())});
}

// A sidewalk piece lies on another pass's road if any corner is well inside its half width.
bool onOtherRoad(const Street& street, const Station& a, const Station& b, double l0, double l1) {
  const double r = street.options.road_half_width_m - 0.25;
  for (const auto* st : {&a, &b}) {
    for (const double l : {l0, l1}) {
      if (street.route.anyWithin(st->p + l * st->n, r)) return true;
    }
  }
  return false;
}

// Curb stone, paving and both curb faces of one side between two stations.
void sidewalkPiece(Street& street, const Station& a, const Station& b, double side) {
  const double w = street.options.road_half_width_m, sw = street.options.sidewalk_width_m;
  const double edge = w + std::min(0.2, 0.3 * sw), outer = w + sw;
  streetStrip(street, street.lib.curb, a, b, side * w, side * edge, kCurbHeight, kCurbHeight,
              side * w, 0.5);
  streetStrip(street, street.lib.paving, a, b, side * edge, side * outer, kCurbHeight, kCurbHeight,
              side * w, 1.0);
  curbFace(street, a, b, side * w, 0.0, kCurbHeight);
  curbFace(street, a, b, side * outer, -kGroundDrop, kCurbHeight);
}

// End face of a sidewalk run (at a crossing or where a run resumes).
void sidewalkEnd(Street& street, const Station& st, double side) {
  const double w = street.options.road_half_width_m, outer = w + street.options.sidewalk_width_m;
  const std::size_t tex = street.lib.curb;
  const double len = outer - w;
  street.mesh.quad(
      tex,
      {at(street, st, side * w, -kGroundDrop), at(street, st, side * outer, -kGroundDrop),
       at(street, st, side * outer, kCurbHeight), at(street, st, side * w, kCurbHeight)},
      {Eigen::Vector2d(0, 1), Eigen::Vector2d(len / 2.0, 1), Eigen::Vector2d(len / 2.0, 0.6),
       Eigen::Vector2d(0, 0.6)});
}

void addSidewalks(Street& street, const SurfaceSpec& spec, double side) {
  const double w = street.options.road_half_width_m, outer = w + street.options.sidewalk_width_m;
  bool open = false;  // inside a run of kept pieces
  for (std::size_t i = 0; i + 1 < street.stations.size(); ++i) {
    const Station &a = street.stations[i], &b = street.stations[i + 1];
    const bool keep = !onOtherRoad(street, a, b, side * w, side * outer) &&
                      !(spec.dedupe_sidewalks && (revisited(street, a) || revisited(street, b)));
    if (keep != open) sidewalkEnd(street, a, side);
    if (keep) sidewalkPiece(street, a, b, side);
    open = keep;
  }
  if (open) sidewalkEnd(street, street.stations.back(), side);
}

// Paint yields where another pass's road is: dropped at crossings, and along a street driven
// twice only the earlier pass paints (the two centre lines would z-fight).
bool paintAllowed(const Street& street, const Station& st, double lateral) {
  const Eigen::Vector2d q = st.p + lateral * st.n;
  const double w = street.options.road_half_width_m;
  for (const auto& r : street.route.near(q, w + 0.3)) {
    if (std::abs(r.s - st.s) < 3.0 * w + 10.0) continue;  // this pass
    if (std::abs(r.t.dot(st.t)) < 0.9 || r.s < st.s) return false;
  }
  return true;
}

// A painted line [lateral +- width/2] from arc length s0 to s1 (1 m pieces follow curves).
void paintLine(Street& street, double s0, double s1, double lateral, double width) {
  const std::size_t tex = street.lib.marking;
  const double len = s1 - s0;
  const int pieces = std::max(1, static_cast<int>(std::ceil(len)));
  for (int k = 0; k < pieces; ++k) {
    const Station a = stationAt(street.stations, s0 + len * k / pieces);
    const Station b = stationAt(street.stations, s0 + len * (k + 1) / pieces);
    if (!paintAllowed(street, a, lateral) || !paintAllowed(street, b, lateral)) continue;
    const double va = (a.s - s0) / 3.0, vb = (b.s - s0) / 3.0;
    street.mesh.quad(tex,
                     {at(street, a, lateral - width / 2, kMarkingLift),
                      at(street, a, lateral + width / 2, kMarkingLift),
                      at(street, b, lateral + width / 2, kMarkingLift),
                      at(street, b, lateral - width / 2, kMarkingLift)},
                     {Eigen::Vector2d(0, va), Eigen::Vector2d(1, va), Eigen::Vector2d(1, vb),
                      Eigen::Vector2d(0, vb)});
  }
}

// Dashed centre line left of the driven lane (street: 3 m dashes, 6 m gaps), solid edge lines.
void addMarkings(Street& street, const SurfaceSpec& spec, Rng& rng) {
  const double w = street.options.road_half_width_m;
  const double first = street.stations.front().s, last = street.stations.back().s;
  const double centre = std::min(1.6, 0.35 * w);
  for (double s = first + rng.uniform(0.0, spec.dash_period_m); s + spec.dash_m < last;
       s += spec.dash_period_m)
    paintLine(street, s, s + spec.dash_m, centre, 0.12);
  for (double s = first; s < last; s += 6.0) {
    paintLine(street, s, std::min(s + 6.0, last), w - 0.3, 0.12);
    paintLine(street, s, std::min(s + 6.0, last), -(w - 0.3), 0.12);
  }
}

// How far the ground may reach out from a station before it would cover another road (the route
// passing by again, or this pass beyond a bend): the ground of each pass stops there.
double groundReach(const Street& street, const SurfaceSpec& spec, const Station& st, double side) {
  const double w = street.options.road_half_width_m;
  double reach = w + street.options.sidewalk_width_m;
  while (reach < spec.ground_reach_m &&
         !street.route.anyWithin(st.p + side * (reach + 2.0) * st.n, w + 1.0)) {
    reach += 2.0;
  }
  return reach;
}

// Manhole covers and gutter drains: flat, sparse, irregularly spaced road features of a few
// decimetres, which stay visible (and trackable) where the mipmapped asphalt is a blur.
void manhole(Street& street, const Eigen::Vector2d& c) {
  const double z = street.route.roadHeight(c) + kDecalLift, r = 0.34;
  for (int k = 0; k < 8; ++k) {
    const double a0 = k * std::numbers::pi / 4.0, a1 = (k + 1) * std::numbers::pi / 4.0;
    street.mesh.triangle(street.lib.manhole,
                         {Eigen::Vector3d(c.x(), c.y(), z),
                          Eigen::Vector3d(c.x() + r * std::cos(a0), c.y() + r * std::sin(a0), z),
                          Eigen::Vector3d(c.x() + r * std::cos(a1), c.y() + r * std::sin(a1), z)},
                         {Eigen::Vector2d(0.5, 0.5),
                          Eigen::Vector2d(0.5 + 0.5 * std::cos(a0), 0.5 + 0.5 * std::sin(a0)),
                          Eigen::Vector2d(0.5 + 0.5 * std::cos(a1), 0.5 + 0.5 * std::sin(a1))});
  }
}

void drain(Street& street, double s, double side) {
  const double w = street.options.road_half_width_m;
  const Station a = stationAt(street.stations, s);
  const Station b = stationAt(street.stations, s + 0.5);
  const double l0 = side * (w - 0.05), l1 = side * (w - 0.4);
  street.mesh.quad(
      street.lib.grate,
      {at(street, a, l0, kDecalLift), at(street, a, l1, kDecalLift), at(street, b, l1, kDecalLift),
       at(street, b, l0, kDecalLift)},
      {Eigen::Vector2d(0, 0), Eigen::Vector2d(1, 0), Eigen::Vector2d(1, 1), Eigen::Vector2d(0, 1)});
}

void addRoadDetails(Street& street, Rng& rng) {
  const double w = street.options.road_half_width_m;
  const double first = street.stations.front().s, last = street.stations.back().s;
  for (double s = first + rng.uniform(0.0, 40.0); s < last; s += rng.uniform(25.0, 60.0)) {
    const Station st = stationAt(street.stations, s);
    manhole(street, st.p + rng.uniform(-0.4, 0.4) * w * st.n);
  }
  for (double s = first + rng.uniform(0.0, 20.0); s < last; s += rng.uniform(15.0, 40.0))
    drain(street, s, rng.chance(0.5) ? 1.0 : -1.0);
}

// One manhole and a drain on each side per period, at the same places in every period (arc length
// from the route's start), built by the first pass along a street only.
void addPeriodicRoadDetails(Street& street) {
  const double w = street.options.road_half_width_m, period = kRepetitivePeriod_m;
  const double first = street.stations.front().s, last = street.stations.back().s;
  for (double s = std::ceil(first / period) * period; s + period < last; s += period) {
    const Station st = stationAt(street.stations, s + 7.0);
    if (revisited(street, st)) continue;
    manhole(street, st.p - 0.2 * w * st.n);
    if (!revisited(street, stationAt(street.stations, s + 2.0))) {
      drain(street, s + 2.0, 1.0);
      drain(street, s + 2.0, -1.0);
    }
  }
}

// Road in three lanes and ground in pieces of <= 6 m across: every vertex sits on the shared
// height field, so surfaces of different passes follow it closely where they overlap.
void addRoadAndGround(Street& street, const SurfaceSpec& spec) {
  const double w = street.options.road_half_width_m;
  std::vector<std::array<double, 2>> reach;  // per station: left, right
  for (const auto& st : street.stations)
    reach.push_back({groundReach(street, spec, st, 1.0), groundReach(street, spec, st, -1.0)});
  for (std::size_t i = 0; i + 1 < street.stations.size(); ++i) {
    const Station &a = street.stations[i], &b = street.stations[i + 1];
    for (int lane = 0; lane < 3; ++lane)
      worldStrip(street, street.lib.asphalt, a, b, -w + lane * 2.0 * w / 3.0,
                 -w + (lane + 1) * 2.0 * w / 3.0, 0.0, spec.uv_angle_rad);
    for (std::size_t k = 0; k < 2; ++k) {
      const double side = k == 0 ? 1.0 : -1.0, outer = std::min(reach[i][k], reach[i + 1][k]);
      const int pieces = static_cast<int>(std::ceil((outer - w) / spec.ground_piece_m));
      for (int j = 0; j < pieces; ++j) {
        const double l0 = w - 0.2 + (outer - w + 0.2) * j / pieces;
        const double l1 = w - 0.2 + (outer - w + 0.2) * (j + 1) / pieces;
        worldStrip(street, street.lib.ground, a, b, side * l0, side * l1, -kGroundDrop,
                   spec.uv_angle_rad);
      }
    }
  }
}

// Coarse terrain under the street surfaces (street: 1 m under, out to 80 m from the route):
// wherever the strips leave a gap (crossings, beyond the buildings), the view still ends on ground.
void addTerrain(Street& street, const SurfaceSpec& spec) {
  const double cell = spec.terrain_cell_m, reach = spec.terrain_reach_m;
  std::set<std::pair<long, long>> cells;  // ordered: the mesh does not depend on hashing
  const long span = static_cast<long>(reach / cell) + 1;
  for (const auto& st : street.stations) {
    const long cx = std::lround(st.p.x() / cell), cy = std::lround(st.p.y() / cell);
    for (long dx = -span; dx <= span; ++dx) {
      for (long dy = -span; dy <= span; ++dy) {
        if ((dx * dx + dy * dy) * cell * cell <= reach * reach) cells.insert({cx + dx, cy + dy});
      }
    }
  }
  const std::size_t tex = street.lib.ground;
  const Eigen::Vector2d tile = street.lib.tile_m[tex];
  for (const auto& [cx, cy] : cells) {
    std::array<Eigen::Vector3d, 4> p;
    std::array<Eigen::Vector2d, 4> uv;
    const std::array<std::pair<int, int>, 4> corner{{{0, 0}, {1, 0}, {1, 1}, {0, 1}}};
    for (std::size_t i = 0; i < 4; ++i) {
      const Eigen::Vector2d q(static_cast<double>(cx + corner[i].first) * cell,
                              static_cast<double>(cy + corner[i].second) * cell);
      p[i] = Eigen::Vector3d(q.x(), q.y(), street.route.roadHeight(q) - spec.terrain_drop_m);
      uv[i] = worldUv(q, tile, spec.uv_angle_rad);
    }
    street.mesh.quad(tex, p, uv);
  }
}

}  // namespace

void addStreetSurfaces(Street& street, std::uint64_t seed) {
  const SurfaceSpec spec = surfaceSpec(street.options.style);
  Rng rng = Rng::derive(seed, 100);
  addRoadAndGround(street, spec);
  addTerrain(street, spec);
  if (spec.sidewalks) {
    addSidewalks(street, spec, 1.0);
    addSidewalks(street, spec, -1.0);
  }
  addMarkings(street, spec, rng);
  if (spec.details == SurfaceSpec::Details::kRandom) addRoadDetails(street, rng);
  if (spec.details == SurfaceSpec::Details::kPeriodic) addPeriodicRoadDetails(street);
}

}  // namespace gvio::sim::detail
