#pragma once
// Internals of buildWorld shared by world.cpp (route), world_surfaces.cpp (road, sidewalks,
// ground), world_props.cpp (buildings, trees, poles, cars), world_objects.cpp (the street's
// layout) and the other styles' layouts (world_styles.cpp, world_repetitive.cpp): the resampled
// centre line, spatial hashes of route points (clearance, shared height field) and of placed
// footprints, and a mesh builder that batches triangles per texture.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "render/scene.hpp"
#include "sim/procedural.hpp"
#include "sim/textures.hpp"
#include "sim/world.hpp"

namespace gvio::sim::detail {

// A sample of the street's centre line every ~2 m. Stations before the first and after the last
// route point extend the street straight on, so the view at the ends is a street.
struct Station {
  Eigen::Vector2d p = Eigen::Vector2d::Zero();
  Eigen::Vector2d t = Eigen::Vector2d::UnitX();  // unit tangent
  Eigen::Vector2d n = Eigen::Vector2d::UnitY();  // unit left normal
  double z_road = 0.0;                           // road surface height (shared field)
  double s = 0.0;                                // arc length along the route (m)
};
Station stationAt(const std::vector<Station>& stations, double s);  // interpolated, clamped

struct RoutePoint {
  Eigen::Vector2d p = Eigen::Vector2d::Zero();
  Eigen::Vector2d t = Eigen::Vector2d::UnitX();
  double s = 0.0, z_road = 0.0;
};

// Uniform grid of cells -> items; lookups only, so hashing order never reaches the output.
class CellGrid {
 public:
  explicit CellGrid(double cell_m) : cell_m_(cell_m) {}
  void insert(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi, std::uint32_t item);
  // Items of every cell that overlaps [lo, hi] (an item may come more than once).
  void collect(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi,
               std::vector<std::uint32_t>& out) const;

 private:
  [[nodiscard]] std::int64_t key(std::int64_t cx, std::int64_t cy) const;
  [[nodiscard]] std::int64_t cell(double v) const;
  double cell_m_;
  std::unordered_map<std::int64_t, std::vector<std::uint32_t>> cells_;
};

// Oriented rectangle on the ground: centre, unit axis along its length, half extents.
struct Footprint {
  Eigen::Vector2d c = Eigen::Vector2d::Zero();
  Eigen::Vector2d axis = Eigen::Vector2d::UnitX();
  double half_l = 0.5, half_w = 0.5;

  [[nodiscard]] double distanceTo(const Eigen::Vector2d& q) const;  // 0 inside
  [[nodiscard]] Eigen::Vector2d lo() const;                         // bounding box
  [[nodiscard]] Eigen::Vector2d hi() const;
  [[nodiscard]] std::array<Eigen::Vector2d, 4> corners() const;
  [[nodiscard]] Footprint grown(double margin) const;
};

class RouteIndex {  // every route point, densified to <= 0.5 m
 public:
  RouteIndex() : grid_(10.0) {}
  void add(const RoutePoint& point);
  [[nodiscard]] bool anyWithin(const Eigen::Vector2d& q, double radius) const;
  [[nodiscard]] bool clear(const Footprint& f, double clearance) const;  // no point that close
  // Road surface height at q: a smooth kernel-weighted mean of the route's road heights nearby.
  // Where passes cross or revisit a street at different recorded heights (KITTI's ground truth
  // differs by 1-2 m between some passes), all surfaces share this one field, so they meet.
  [[nodiscard]] double roadHeight(const Eigen::Vector2d& q) const;
  // Points within radius of q.
  [[nodiscard]] std::vector<RoutePoint> near(const Eigen::Vector2d& q, double radius) const;

 private:
  CellGrid grid_;
  std::vector<RoutePoint> points_;
  mutable std::vector<std::uint32_t> scratch_;
};

class FootprintIndex {  // everything placed so far
 public:
  FootprintIndex() : grid_(10.0) {}
  [[nodiscard]] bool overlaps(const Footprint& f, double margin) const;
  void add(const Footprint& f);

 private:
  CellGrid grid_;
  std::vector<Footprint> placed_;
  mutable std::vector<std::uint32_t> scratch_;
};

// Texture mapping of a box face: u = u0 + du * (metres along the face), v = v0 - dv * (metres up
// from the box's reference height); top faces: u = u0 + du * x, v = v0 + dv * y (local metres).
struct FaceSkin {
  std::size_t texture = 0;
  double u0 = 0.0, du = 1.0, v0 = 1.0, dv = 1.0;
};
// Metric tiling with the texture's own repeat size.
FaceSkin tiled(const TextureLibrary& lib, std::size_t texture, double u0 = 0.0);
// The whole texture (or the u range [u_lo, u_hi]) stretched over a face of length x height.
FaceSkin stretched(std::size_t texture, double length, double height, double u_lo = 0.0,
                   double u_hi = 1.0);

struct BoxSkin {
  FaceSkin long_faces, short_faces, top;
};

class MeshBuilder {  // triangles batched per texture: one draw call each
 public:
  explicit MeshBuilder(std::size_t textures) : meshes_(textures) {}
  void quad(std::size_t texture, const std::array<Eigen::Vector3d, 4>& p,
            const std::array<Eigen::Vector2d, 4>& uv);
  void triangle(std::size_t texture, const std::array<Eigen::Vector3d, 3>& p,
                const std::array<Eigen::Vector2d, 3>& uv);
  // Walls and top of the prism footprint x [z0, z1]; z_ref anchors the vertical texture (floors).
  // top_inset_l shortens the top along the footprint's length (sloped ends: car cabins).
  void box(const Footprint& f, double z0, double z1, double z_ref, const BoxSkin& skin,
           double top_inset_l = 0.0);
  // A lumpy closed blob (jittered icosahedron) with planar-projected texture of tile_m repeats.
  void blob(const Eigen::Vector3d& centre, const Eigen::Vector3d& radii, Rng& rng,
            std::size_t texture, double tile_m);
  [[nodiscard]] std::size_t triangles() const;
  std::vector<render::TexturedMesh> take();  // non-empty meshes, in texture order

 private:
  std::vector<render::TexturedMesh> meshes_;
};

// Everything the builders share while the world is assembled.
struct Street {
  const WorldOptions& options;
  const TextureLibrary& lib;
  std::vector<Station> stations;
  RouteIndex route;
  FootprintIndex placed;
  MeshBuilder mesh;
};

constexpr double kCurbHeight = 0.15;  // sidewalk above the road (m)

// The style's textures (textures_styles.cpp): sparse_texture swaps the library's textures in place
// for plain low-contrast ones; repetitive fits the ground's repeat to the period.
void restyleTextures(TextureLibrary& lib, WorldStyle style, std::uint64_t seed, int size_px);

// An earlier pass of the route drove along this station's street (a route point within the road
// half width, from further back than this pass's own neighbourhood): that pass has built it.
[[nodiscard]] bool revisited(const Street& street, const Station& st);
// Objects at this station are the earlier pass's business: in every style but the street (which
// keeps the world it always had, where a later pass fills gaps the first one left), a street is
// furnished by the first pass along it only, so more laps do not make it denser.
[[nodiscard]] bool builtBefore(const Street& street, const Station& st);

void addStreetSurfaces(Street& street, std::uint64_t seed);  // road, paint, sidewalks, ground

// Object primitives (world_props.cpp), shared by the layouts.
[[nodiscard]] double roadClearance(const Street& street);      // anything above the road surface
[[nodiscard]] double sidewalkClearance(const Street& street);  // buildings: behind the sidewalk
// Places f if it keeps `clearance` from the route and does not overlap what is placed (more than
// -margin when margin is negative: row buildings may touch).
bool claim(Street& street, const Footprint& f, double clearance, double margin);
Footprint along(const Station& st, double side, double lateral, double half_l, double half_w);
struct BuildingSkin {
  std::size_t style = 0;               // index into the library's facade styles
  double u_front = 0.0, u_side = 0.0;  // texture offsets of the long and short walls
  double cornice_m = 0.45;
};
BuildingSkin randomSkin(const TextureLibrary& lib, Rng& rng);
void buildingMesh(Street& street, const Footprint& f, double height, const BuildingSkin& skin);
void buildingMesh(Street& street, Rng& rng, const Footprint& f, double height);  // random skin
// Trunk and crown of radius r at c; `axis` orients the trunk.
void treeMesh(Street& street, Rng& rng, const Eigen::Vector2d& c, const Eigen::Vector2d& axis,
              double r, double trunk_h);
void tree(Street& street, Rng& rng, const Station& st, double side);  // by the sidewalk
// A random tree with its crown centred `lateral` from the centre line, if it fits.
void treeAt(Street& street, Rng& rng, const Station& st, double side, double lateral,
            double clearance);
void hedge(Street& street, Rng& rng, double s, double side);
void pole(Street& street, Rng& rng, const Station& st, double side);  // lamp or sign
bool claimPole(Street& street, const Station& st, double side);
void poleMesh(Street& street, const Station& st, double side, bool lamp, double height);
void car(Street& street, Rng& rng, double s, double side);

// The street's layout (world_objects.cpp).
struct RowSpec {
  double lateral_lo, lateral_hi;  // front face from the centre line (m)
  double width_lo, width_hi, depth_lo, depth_hi, height_lo, height_hi;
  double gap_chance, gap_hi;  // chance of a gap between buildings, its largest size
  double margin;              // overlap allowance against placed footprints
};
// One row of buildings along one side, each keeping `clearance` from the route.
void buildingRow(Street& street, Rng& rng, double side, const RowSpec& spec, double clearance);
void endWalls(Street& street, Rng& rng);  // facades across the street beyond both ends
void addBuildings(Street& street, std::uint64_t seed);
void addStreetFurniture(Street& street, std::uint64_t seed);  // trees, poles, parked cars

// The other styles' layouts (world_styles.cpp, world_repetitive.cpp).
void addOpenRoadObjects(Street& street, std::uint64_t seed);
void addSparseObjects(Street& street, std::uint64_t seed);
void addVegetationObjects(Street& street, std::uint64_t seed);
void addRepetitiveObjects(Street& street, std::uint64_t seed);

}  // namespace gvio::sim::detail
