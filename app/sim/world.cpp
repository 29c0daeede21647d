// buildWorld: the route cleaned, indexed (clearance and the shared height field) and resampled
// into stations every ~2 m, extended past its ends; then street surfaces (world_surfaces.cpp) and
// the style's objects along it (world_objects.cpp, world_styles.cpp, world_repetitive.cpp).
#include "sim/world.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

#include "odometry/error.hpp"
#include "sim/world_parts.hpp"

namespace gvio::sim {
namespace {

using detail::Station;
using detail::Street;

constexpr std::array<std::pair<std::string_view, WorldStyle>, 5> kStyles{{
    {"street", WorldStyle::kStreet},
    {"open_road", WorldStyle::kOpenRoad},
    {"sparse_texture", WorldStyle::kSparseTexture},
    {"repetitive", WorldStyle::kRepetitive},
    {"vegetation", WorldStyle::kVegetation},
}};

constexpr double kStationSpacing = 2.0;  // m
constexpr double kExtension = 60.0;      // street continues this far past the route ends (m)

// The route in 2-D without standstill duplicates, with arc length.
struct Polyline {
  std::vector<Eigen::Vector3d> p;
  std::vector<double> s;
};

Polyline cleanRoute(const std::vector<Eigen::Vector3d>& route_w) {
  Polyline r;
  for (const auto& p : route_w) {
    if (!p.allFinite()) throw InvalidInput("world: route point is not finite");
    if (!r.p.empty() && (p - r.p.back()).head<2>().norm() < 1e-3) continue;
    r.s.push_back(r.p.empty() ? 0.0 : r.s.back() + (p - r.p.back()).head<2>().norm());
    r.p.push_back(p);
  }
  if (r.p.size() < 2) throw InvalidInput("world: the route needs at least two distinct points");
  return r;
}

Eigen::Vector3d pointAt(const Polyline& r, double s) {
  const auto it = std::upper_bound(r.s.begin(), r.s.end(), s);
  if (it == r.s.begin()) return r.p.front();
  if (it == r.s.end()) return r.p.back();
  const auto i = static_cast<std::size_t>(it - r.s.begin());
  const double f = (s - r.s[i - 1]) / (r.s[i] - r.s[i - 1]);
  return r.p[i - 1] + f * (r.p[i] - r.p[i - 1]);
}

// Stations every ~2 m along the route, tangents from neighbours.
std::vector<Station> resample(const Polyline& r, double body_height) {
  const double length = r.s.back();
  const int n = std::max(1, static_cast<int>(std::ceil(length / kStationSpacing)));
  std::vector<Station> stations;
  for (int i = 0; i <= n; ++i) {
    Station st;
    st.s = length * i / n;
    const Eigen::Vector3d p = pointAt(r, st.s);
    st.p = p.head<2>();
    st.z_road = p.z() - body_height;
    stations.push_back(st);
  }
  for (std::size_t i = 0; i < stations.size(); ++i) {
    const Eigen::Vector2d d =
        stations[std::min(i + 1, stations.size() - 1)].p - stations[i == 0 ? 0 : i - 1].p;
    stations[i].t = d.normalized();
    stations[i].n = Eigen::Vector2d(-stations[i].t.y(), stations[i].t.x());
  }
  return stations;
}

// Every route point and every 0.5 m between them: the clearance reference.
void indexRoute(const Polyline& r, double body_height, detail::RouteIndex& index) {
  for (std::size_t i = 0; i + 1 < r.p.size(); ++i) {
    const Eigen::Vector2d d = (r.p[i + 1] - r.p[i]).head<2>();
    const int steps = std::max(1, static_cast<int>(std::ceil(d.norm() / 0.5)));
    for (int k = 0; k < steps; ++k) {
      const double f = static_cast<double>(k) / steps;
      const Eigen::Vector3d p = r.p[i] + f * (r.p[i + 1] - r.p[i]);
      index.add({p.head<2>(), d.normalized(), r.s[i] + f * d.norm(), p.z() - body_height});
    }
  }
  const Eigen::Vector2d last = (r.p.back() - r.p[r.p.size() - 2]).head<2>().normalized();
  index.add({r.p.back().head<2>(), last, r.s.back(), r.p.back().z() - body_height});
}

// The street goes on straight past both route ends (so the last views look down a street), up to
// kExtension or until it would run into another part of the route (KITTI 00 ends where it began,
// at another height). Extension points join the clearance reference.
void extendEnds(Street& street) {
  auto& stations = street.stations;
  const double reach = street.options.road_half_width_m + street.options.sidewalk_width_m + 1.0;
  auto extension = [&](const Station& end, double dir) {
    std::vector<Station> out;
    for (int k = 1; k <= static_cast<int>(kExtension / kStationSpacing); ++k) {
      Station st = end;
      st.p += dir * k * kStationSpacing * st.t;
      st.s += dir * k * kStationSpacing;
      for (const auto& r : street.route.near(st.p, reach)) {
        if (std::abs(r.s - end.s) > 30.0) return out;
      }
      out.push_back(st);
    }
    return out;
  };
  const std::vector<Station> before = extension(stations.front(), -1.0);
  const std::vector<Station> after = extension(stations.back(), 1.0);
  stations.insert(stations.begin(), before.rbegin(), before.rend());
  stations.insert(stations.end(), after.begin(), after.end());
  for (const auto* part : {&before, &after}) {
    for (const auto& st : *part) street.route.add({st.p, st.t, st.s, st.z_road});
  }
}

void checkOptions(const WorldOptions& o) {
  if (!(o.road_half_width_m > 0.5) || !(o.sidewalk_width_m > 0.3) ||
      !std::isfinite(o.body_height_m))
    throw InvalidInput(
        "world: needs road half width > 0.5 m, sidewalk width > 0.3 m and a finite "
        "body height");
}

void addObjects(Street& street, std::uint64_t seed) {
  switch (street.options.style) {
    case WorldStyle::kStreet:
      detail::addBuildings(street, seed);
      detail::addStreetFurniture(street, seed);
      break;
    case WorldStyle::kOpenRoad:
      detail::addOpenRoadObjects(street, seed);
      break;
    case WorldStyle::kSparseTexture:
      detail::addSparseObjects(street, seed);
      break;
    case WorldStyle::kRepetitive:
      detail::addRepetitiveObjects(street, seed);
      break;
    case WorldStyle::kVegetation:
      detail::addVegetationObjects(street, seed);
      break;
  }
}

}  // namespace

std::optional<WorldStyle> parseWorldStyle(std::string_view name) {
  for (const auto& [text, style] : kStyles) {
    if (text == name) return style;
  }
  return std::nullopt;
}

const char* toString(WorldStyle style) {
  for (const auto& [text, s] : kStyles) {
    if (s == style) return text.data();
  }
  return "street";
}

namespace detail {

bool revisited(const Street& street, const Station& st) {
  const double w = street.options.road_half_width_m;
  for (const auto& r : street.route.near(st.p, w)) {
    if (r.s < st.s - (3.0 * w + 10.0)) return true;  // beyond this pass's own neighbourhood
  }
  return false;
}

bool builtBefore(const Street& street, const Station& st) {
  return street.options.style != WorldStyle::kStreet && revisited(street, st);
}

}  // namespace detail

World buildWorld(const std::vector<Eigen::Vector3d>& route_w, const WorldOptions& options) {
  checkOptions(options);
  const Polyline route = cleanRoute(route_w);
  TextureLibrary lib = makeTextureLibrary(options.seed, options.texture_size_px);
  detail::restyleTextures(lib, options.style, options.seed, options.texture_size_px);
  Street street{.options = options,
                .lib = lib,
                .stations = resample(route, options.body_height_m),
                .route = {},
                .placed = {},
                .mesh = detail::MeshBuilder(lib.textures.size())};
  indexRoute(route, options.body_height_m, street.route);
  extendEnds(street);
  // Stations (and what stands along them) sit on the height field shared by all passes.
  for (auto& st : street.stations) st.z_road = street.route.roadHeight(st.p);
  detail::addStreetSurfaces(street, options.seed);
  addObjects(street, options.seed);
  World world;
  world.triangles = street.mesh.triangles();
  world.scene.meshes = street.mesh.take();
  world.scene.textures = std::move(lib.textures);
  world.scene.background = render::Color(0.82F, 0.84F, 0.86F, 1.0F);  // overcast sky
  return world;
}

}  // namespace gvio::sim
