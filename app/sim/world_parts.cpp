#include "sim/world_parts.hpp"

#include <algorithm>
#include <cmath>

namespace gvio::sim::detail {
namespace {

Eigen::Vector2d perp(const Eigen::Vector2d& v) {
  return {-v.y(), v.x()};
}

// Separating-axis test of two oriented rectangles.
bool overlap(const Footprint& a, const Footprint& b) {
  const std::array<Eigen::Vector2d, 4> axes{a.axis, perp(a.axis), b.axis, perp(b.axis)};
  const Eigen::Vector2d d = b.c - a.c;
  for (const auto& ax : axes) {
    const double ra =
        a.half_l * std::abs(a.axis.dot(ax)) + a.half_w * std::abs(perp(a.axis).dot(ax));
    const double rb =
        b.half_l * std::abs(b.axis.dot(ax)) + b.half_w * std::abs(perp(b.axis).dot(ax));
    if (std::abs(d.dot(ax)) > ra + rb) return false;
  }
  return true;
}

Eigen::Vector2f toFloat(const Eigen::Vector2d& uv) {
  return uv.cast<float>();
}

}  // namespace

Station stationAt(const std::vector<Station>& stations, double s) {
  if (s <= stations.front().s) return stations.front();
  if (s >= stations.back().s) return stations.back();
  const auto it = std::upper_bound(stations.begin(), stations.end(), s,
                                   [](double v, const Station& st) { return v < st.s; });
  const Station& b = *it;
  const Station& a = *(it - 1);
  const double f = (s - a.s) / std::max(b.s - a.s, 1e-9);
  Station r = a;
  r.p = a.p + f * (b.p - a.p);
  r.t = (a.t + f * (b.t - a.t)).normalized();
  r.n = perp(r.t);
  r.z_road = a.z_road + f * (b.z_road - a.z_road);
  r.s = s;
  return r;
}

std::int64_t CellGrid::cell(double v) const {
  return static_cast<std::int64_t>(std::floor(v / cell_m_));
}

std::int64_t CellGrid::key(std::int64_t cx, std::int64_t cy) const {
  return (cx << 32) ^ (cy & 0xFFFFFFFFLL);
}

void CellGrid::insert(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi, std::uint32_t item) {
  for (std::int64_t cx = cell(lo.x()); cx <= cell(hi.x()); ++cx) {
    for (std::int64_t cy = cell(lo.y()); cy <= cell(hi.y()); ++cy)
      cells_[key(cx, cy)].push_back(item);
  }
}

void CellGrid::collect(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi,
                       std::vector<std::uint32_t>& out) const {
  out.clear();
  for (std::int64_t cx = cell(lo.x()); cx <= cell(hi.x()); ++cx) {
    for (std::int64_t cy = cell(lo.y()); cy <= cell(hi.y()); ++cy) {
      const auto it = cells_.find(key(cx, cy));
      if (it != cells_.end()) out.insert(out.end(), it->second.begin(), it->second.end());
    }
  }
}

double Footprint::distanceTo(const Eigen::Vector2d& q) const {
  const Eigen::Vector2d d = q - c;
  const double x = std::max(std::abs(d.dot(axis)) - half_l, 0.0);
  const double y = std::max(std::abs(d.dot(perp(axis))) - half_w, 0.0);
  return std::hypot(x, y);
}

Eigen::Vector2d Footprint::lo() const {
  const Eigen::Vector2d e = half_l * axis.cwiseAbs() + half_w * perp(axis).cwiseAbs();
  return c - e;
}

Eigen::Vector2d Footprint::hi() const {
  return 2.0 * c - lo();
}

std::array<Eigen::Vector2d, 4> Footprint::corners() const {
  const Eigen::Vector2d l = half_l * axis, w = half_w * perp(axis);
  return {c - l - w, c + l - w, c + l + w, c - l + w};
}

Footprint Footprint::grown(double margin) const {
  Footprint f = *this;
  f.half_l += margin;
  f.half_w += margin;
  return f;
}

void RouteIndex::add(const RoutePoint& point) {
  grid_.insert(point.p, point.p, static_cast<std::uint32_t>(points_.size()));
  points_.push_back(point);
}

bool RouteIndex::anyWithin(const Eigen::Vector2d& q, double radius) const {
  const Eigen::Vector2d r(radius, radius);
  grid_.collect(q - r, q + r, scratch_);
  return std::any_of(scratch_.begin(), scratch_.end(),
                     [&](std::uint32_t i) { return (points_[i].p - q).norm() < radius; });
}

bool RouteIndex::clear(const Footprint& f, double clearance) const {
  const Eigen::Vector2d r(clearance, clearance);
  grid_.collect(f.lo() - r, f.hi() + r, scratch_);
  return std::none_of(scratch_.begin(), scratch_.end(),
                      [&](std::uint32_t i) { return f.distanceTo(points_[i].p) < clearance; });
}

double RouteIndex::roadHeight(const Eigen::Vector2d& q) const {
  for (double radius = 8.0; radius < 2000.0; radius *= 4.0) {
    const Eigen::Vector2d r(radius, radius);
    grid_.collect(q - r, q + r, scratch_);  // each point is in one cell: no repeats
    double sum = 0.0, weight = 0.0;
    for (const auto i : scratch_) {
      const double d2 = (points_[i].p - q).squaredNorm() / (radius * radius);
      if (d2 >= 1.0) continue;
      const double w = (1.0 - d2) * (1.0 - d2);
      sum += w * points_[i].z_road;
      weight += w;
    }
    if (weight > 1e-6) return sum / weight;
  }
  return points_.empty() ? 0.0 : points_.front().z_road;
}

std::vector<RoutePoint> RouteIndex::near(const Eigen::Vector2d& q, double radius) const {
  const Eigen::Vector2d r(radius, radius);
  grid_.collect(q - r, q + r, scratch_);
  std::vector<RoutePoint> out;
  for (const auto i : scratch_) {
    if ((points_[i].p - q).norm() < radius) out.push_back(points_[i]);
  }
  return out;
}

bool FootprintIndex::overlaps(const Footprint& f, double margin) const {
  const Footprint g = f.grown(margin);
  grid_.collect(g.lo(), g.hi(), scratch_);
  return std::any_of(scratch_.begin(), scratch_.end(),
                     [&](std::uint32_t i) { return overlap(g, placed_[i]); });
}

void FootprintIndex::add(const Footprint& f) {
  grid_.insert(f.lo(), f.hi(), static_cast<std::uint32_t>(placed_.size()));
  placed_.push_back(f);
}

FaceSkin tiled(const TextureLibrary& lib, std::size_t texture, double u0) {
  const Eigen::Vector2d& tile = lib.tile_m[texture];
  return {texture, u0, 1.0 / tile.x(), 1.0, 1.0 / tile.y()};
}

FaceSkin stretched(std::size_t texture, double length, double height, double u_lo, double u_hi) {
  return {texture, u_lo, (u_hi - u_lo) / length, 1.0, 1.0 / height};
}

void MeshBuilder::quad(std::size_t texture, const std::array<Eigen::Vector3d, 4>& p,
                       const std::array<Eigen::Vector2d, 4>& uv) {
  auto& m = meshes_[texture];
  const auto base = static_cast<std::uint32_t>(m.vertices.size());
  for (int i = 0; i < 4; ++i) {
    m.vertices.push_back(p[i]);
    m.uv.push_back(toFloat(uv[i]));
  }
  m.indices.insert(m.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
}

void MeshBuilder::triangle(std::size_t texture, const std::array<Eigen::Vector3d, 3>& p,
                           const std::array<Eigen::Vector2d, 3>& uv) {
  auto& m = meshes_[texture];
  const auto base = static_cast<std::uint32_t>(m.vertices.size());
  for (int i = 0; i < 3; ++i) {
    m.vertices.push_back(p[i]);
    m.uv.push_back(toFloat(uv[i]));
    m.indices.push_back(base + static_cast<std::uint32_t>(i));
  }
}

void MeshBuilder::box(const Footprint& f, double z0, double z1, double z_ref, const BoxSkin& skin,
                      double top_inset_l) {
  Footprint top_f = f;
  top_f.half_l = std::max(0.01, f.half_l - top_inset_l);
  const auto c = f.corners();  // counter-clockwise: the two long walls are c0-c1 and c2-c3
  const auto c2 = top_f.corners();
  for (std::size_t i = 0; i < 4; ++i) {
    const Eigen::Vector2d &a = c[i], &b = c[(i + 1) % 4], &ta = c2[i], &tb = c2[(i + 1) % 4];
    const FaceSkin& s = i % 2 == 0 ? skin.long_faces : skin.short_faces;
    const double len = (b - a).norm();
    const Eigen::Vector2d dir = (b - a) / len;
    const double v_bottom = s.v0 - s.dv * (z0 - z_ref), v_top = s.v0 - s.dv * (z1 - z_ref);
    quad(s.texture,
         {Eigen::Vector3d(a.x(), a.y(), z0), Eigen::Vector3d(b.x(), b.y(), z0),
          Eigen::Vector3d(tb.x(), tb.y(), z1), Eigen::Vector3d(ta.x(), ta.y(), z1)},
         {Eigen::Vector2d(s.u0, v_bottom), Eigen::Vector2d(s.u0 + s.du * len, v_bottom),
          Eigen::Vector2d(s.u0 + s.du * (tb - a).dot(dir), v_top),
          Eigen::Vector2d(s.u0 + s.du * (ta - a).dot(dir), v_top)});
  }
  const FaceSkin& t = skin.top;
  std::array<Eigen::Vector3d, 4> top;
  std::array<Eigen::Vector2d, 4> uv;
  const std::array<Eigen::Vector2d, 4> local{
      Eigen::Vector2d(-top_f.half_l, -f.half_w), Eigen::Vector2d(top_f.half_l, -f.half_w),
      Eigen::Vector2d(top_f.half_l, f.half_w), Eigen::Vector2d(-top_f.half_l, f.half_w)};
  for (std::size_t i = 0; i < 4; ++i) {
    top[i] = Eigen::Vector3d(c2[i].x(), c2[i].y(), z1);
    uv[i] = Eigen::Vector2d(t.u0 + t.du * local[i].x(), t.v0 + t.dv * local[i].y());
  }
  quad(t.texture, top, uv);
}

void MeshBuilder::blob(const Eigen::Vector3d& centre, const Eigen::Vector3d& radii, Rng& rng,
                       std::size_t texture, double tile_m) {
  const double g = (1.0 + std::sqrt(5.0)) / 2.0;
  const std::array<Eigen::Vector3d, 12> unit{
      Eigen::Vector3d(-1, g, 0),  Eigen::Vector3d(1, g, 0),   Eigen::Vector3d(-1, -g, 0),
      Eigen::Vector3d(1, -g, 0),  Eigen::Vector3d(0, -1, g),  Eigen::Vector3d(0, 1, g),
      Eigen::Vector3d(0, -1, -g), Eigen::Vector3d(0, 1, -g),  Eigen::Vector3d(g, 0, -1),
      Eigen::Vector3d(g, 0, 1),   Eigen::Vector3d(-g, 0, -1), Eigen::Vector3d(-g, 0, 1)};
  static constexpr std::array<std::array<int, 3>, 20> kFaces{
      {{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
       {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
       {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}}};
  std::array<Eigen::Vector3d, 12> v;
  for (std::size_t i = 0; i < 12; ++i)
    v[i] = centre + radii.cwiseProduct(unit[i].normalized() * rng.uniform(0.75, 1.15));
  for (const auto& face : kFaces) {
    const std::array<Eigen::Vector3d, 3> p{v[static_cast<std::size_t>(face[0])],
                                           v[static_cast<std::size_t>(face[1])],
                                           v[static_cast<std::size_t>(face[2])]};
    const Eigen::Vector3d normal = (p[1] - p[0]).cross(p[2] - p[0]).cwiseAbs();
    int drop = 0;  // project along the dominant normal axis
    normal.maxCoeff(&drop);
    const int ua = drop == 0 ? 1 : 0, va = drop == 2 ? 1 : 2;
    std::array<Eigen::Vector2d, 3> uv;
    for (std::size_t i = 0; i < 3; ++i) uv[i] = Eigen::Vector2d(p[i][ua], -p[i][va]) / tile_m;
    triangle(texture, p, uv);
  }
}

std::size_t MeshBuilder::triangles() const {
  std::size_t n = 0;
  for (const auto& m : meshes_) n += m.indices.size() / 3;
  return n;
}

std::vector<render::TexturedMesh> MeshBuilder::take() {
  std::vector<render::TexturedMesh> out;
  for (std::size_t i = 0; i < meshes_.size(); ++i) {
    if (meshes_[i].indices.empty()) continue;
    meshes_[i].texture = i;
    out.push_back(std::move(meshes_[i]));
  }
  meshes_.assign(meshes_.size(), {});
  return out;
}

}  // namespace gvio::sim::detail
