#include "viz/map_layers.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <unordered_map>
#include <unordered_set>

#include "render/colormap.hpp"

namespace gvio::viz {
namespace {

using render::Color;

const Color kRim(0.1F, 0.1F, 0.1F, 1), kUsed(0.0F, 0.85F, 0.9F, 1), kRejected(1.0F, 0.45F, 0.0F, 1),
    kNotFused(0.45F, 0.45F, 0.45F, 1), kOutage(0.85F, 0.0F, 0.85F, 1);

render::Rgb rgb(const Color& c) {
  return {c[0], c[1], c[2]};
}

Color heightColour(double z, double lo, double hi) {
  const render::Rgb c = render::colormap(render::ColorMap::kViridis, render::normalise(z, lo, hi));
  return {c.r, c.g, c.b, 1.0F};
}

// Integer cell of a point on a cubic lattice of `cell` metres, packed 21 bits per axis (OctoMap's
// keys span +-2^15 leaves, far inside).
std::uint64_t cellKey(const Eigen::Vector3d& p, double cell) {
  std::uint64_t key = 0;
  for (int a = 0; a < 3; ++a) {
    const auto i = static_cast<std::int64_t>(std::floor(p[a] / cell)) + (1 << 20);
    key = key << 21U | (static_cast<std::uint64_t>(i) & 0x1FFFFFU);
  }
  return key;
}

// Fixes of one status as rimmed discs.
void addDiscs(const std::vector<Eigen::Vector3d>& points, const Color& fill, float size_px,
              std::vector<render::PointCloud>& out) {
  if (points.empty()) return;
  render::PointCloud rim, disc;
  rim.points = disc.points = points;
  rim.colors = {kRim};
  rim.sizes_px = {size_px + 3.0F};
  disc.colors = {fill};
  disc.sizes_px = {size_px};
  out.push_back(std::move(rim));
  out.push_back(std::move(disc));
}

}  // namespace

Eigen::AlignedBox3d quantileBounds(const std::vector<Eigen::Vector3f>& p, double lo, double hi) {
  Eigen::AlignedBox3d box;
  if (p.empty()) return box;
  std::vector<float> v(p.size());
  const auto n = static_cast<double>(p.size() - 1);
  const auto i_lo = static_cast<std::ptrdiff_t>(std::floor(lo * n)),
             i_hi = static_cast<std::ptrdiff_t>(std::ceil(hi * n));
  for (int a = 0; a < 3; ++a) {
    for (std::size_t i = 0; i < p.size(); ++i) v[i] = p[i][a];
    std::nth_element(v.begin(), v.begin() + i_lo, v.end());
    box.min()[a] = v[static_cast<std::size_t>(i_lo)];
    std::nth_element(v.begin(), v.begin() + i_hi, v.end());
    box.max()[a] = v[static_cast<std::size_t>(i_hi)];
  }
  return box;
}

double typicalSpacingM(const std::vector<Eigen::Vector3f>& p, double max_m) {
  if (p.size() < 2 || !(max_m > 0.0)) return max_m;
  // A deterministic sample; its points' neighbours lie in the 27 cells of side max_m around them,
  // so only those cells are filled from one pass over the cloud.
  const std::size_t stride = std::max<std::size_t>(1, p.size() / 1000);
  std::unordered_set<std::uint64_t> wanted;
  for (std::size_t i = 0; i < p.size(); i += stride) {
    for (int dx = -1; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dz = -1; dz <= 1; ++dz) {
          wanted.insert(cellKey(p[i].cast<double>() + max_m * Eigen::Vector3d(dx, dy, dz), max_m));
        }
      }
    }
  }
  std::unordered_map<std::uint64_t, std::vector<std::size_t>> cells;
  for (std::size_t j = 0; j < p.size(); ++j) {
    const std::uint64_t k = cellKey(p[j].cast<double>(), max_m);
    if (wanted.count(k) != 0) cells[k].push_back(j);
  }
  std::vector<double> nearest;
  for (std::size_t i = 0; i < p.size(); i += stride) {
    double best = max_m * max_m;
    for (int dx = -1; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dz = -1; dz <= 1; ++dz) {
          const auto it =
              cells.find(cellKey(p[i].cast<double>() + max_m * Eigen::Vector3d(dx, dy, dz), max_m));
          if (it == cells.end()) continue;
          for (const std::size_t j : it->second) {
            const double d2 = (p[j] - p[i]).cast<double>().squaredNorm();
            if (j != i && d2 > 0.0) best = std::min(best, d2);
          }
        }
      }
    }
    nearest.push_back(std::sqrt(best));
  }
  const auto mid = nearest.begin() + static_cast<std::ptrdiff_t>(nearest.size() / 2);
  std::nth_element(nearest.begin(), mid, nearest.end());
  return *mid;
}

float pointSizePx(double spacing_m, double metres_per_pixel) {
  if (!(metres_per_pixel > 0.0)) return 2.0F;
  return static_cast<float>(std::clamp(std::ceil(1.3 * spacing_m / metres_per_pixel), 2.0, 5.0));
}

bool hasDensePoints(const io::MapCloud& cloud) {
  return std::find(cloud.source.begin(), cloud.source.end(), io::MapCloud::kDense) !=
         cloud.source.end();
}

render::PointCloud colouredCloud(const io::MapCloud& cloud, const CloudStyle& style,
                                 const std::vector<std::uint32_t>* keep) {
  const bool shade = style.shade_by_intensity && cloud.intensity.size() == cloud.p_enu.size();
  render::PointCloud pc;
  pc.round = false;  // squares tile a surface without the discs' corner gaps
  pc.sizes_px = {style.size_px};
  const std::size_t n = keep != nullptr ? keep->size() : cloud.p_enu.size();
  pc.points.reserve(n);
  pc.colors.reserve(n);
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t i = keep != nullptr ? (*keep)[k] : k;
    const Eigen::Vector3d p = cloud.p_enu[i].cast<double>();
    Color c = heightColour(p.z(), style.z_lo, style.z_hi);
    if (shade) {
      const float f = 0.35F + 0.65F * std::clamp(cloud.intensity[i], 0.0F, 255.0F) / 255.0F;
      c.head<3>() *= f;
    }
    pc.points.push_back(p);
    pc.colors.push_back(c);
  }
  return pc;
}

std::vector<std::uint32_t> densePointIndices(const io::MapCloud& cloud) {
  const bool dense = hasDensePoints(cloud);
  std::vector<std::uint32_t> indices;
  for (std::size_t i = 0; i < cloud.p_enu.size(); ++i) {
    if (!dense || cloud.source[i] == io::MapCloud::kDense) {
      indices.push_back(static_cast<std::uint32_t>(i));
    }
  }
  return indices;
}

std::vector<std::uint32_t> nearestPerPixel(const std::vector<Eigen::Vector3f>& p,
                                           const render::RenderCamera& camera,
                                           const std::vector<std::uint32_t>* among) {
  constexpr double kMaxCells = 4e6;  // 16 MB of indices and as much of depths
  const double pixels = static_cast<double>(camera.width) * camera.height;
  const int cell = std::max(1, static_cast<int>(std::ceil(std::sqrt(pixels / kMaxCells))));
  const int cols = (camera.width + cell - 1) / cell, rows = (camera.height + cell - 1) / cell;
  const std::size_t cells = static_cast<std::size_t>(cols) * static_cast<std::size_t>(rows);
  constexpr std::uint32_t kNone = 0xFFFFFFFFU;
  std::vector<std::uint32_t> nearest(cells, kNone);
  std::vector<float> depth(cells, std::numeric_limits<float>::infinity());
  const std::size_t n = among != nullptr ? among->size() : p.size();
  for (std::size_t j = 0; j < n; ++j) {
    const std::size_t i = among != nullptr ? (*among)[j] : j;
    double z = 0.0;
    const Eigen::Vector2d uv = render::projectToPixel(camera, p[i].cast<double>(), &z);
    if (z < camera.near_m || z > camera.far_m) continue;  // clipped anyway
    const double u = std::floor((uv.x() + 0.5) / cell), v = std::floor((uv.y() + 0.5) / cell);
    if (!(u >= 0 && v >= 0 && u < cols && v < rows)) continue;
    const std::size_t k =
        static_cast<std::size_t>(v) * static_cast<std::size_t>(cols) + static_cast<std::size_t>(u);
    if (static_cast<float>(z) < depth[k]) {
      depth[k] = static_cast<float>(z);
      nearest[k] = static_cast<std::uint32_t>(i);
    }
  }
  std::vector<std::uint32_t> keep;
  for (const std::uint32_t i : nearest) {
    if (i != kNone) keep.push_back(i);
  }
  std::sort(keep.begin(), keep.end());  // the file's order, as without thinning
  return keep;
}

std::optional<double> startHeadingRad(const std::vector<Eigen::Vector3d>& path) {
  for (const auto& p : path) {
    const Eigen::Vector2d d = (p - path.front()).head<2>();
    if (d.norm() >= 5.0) return std::atan2(d.y(), d.x());
  }
  return std::nullopt;
}

void addGnssFixes(const std::vector<io::GnssFixRecord>& fixes, double z_used, double z_others,
                  std::vector<render::PointCloud>& clouds,
                  std::vector<render::LegendEntry>& legend) {
  // Used, rejected, and not fused (screened out, unmatched, unaligned) in one grey.
  auto kind = [](io::FixStatus s) {
    return s == io::FixStatus::kUsed ? 0 : (s == io::FixStatus::kRejected ? 1 : 2);
  };
  std::vector<Eigen::Vector3d> by_kind[3];
  std::size_t counts[3] = {0, 0, 0};
  for (const auto& f : fixes) {
    const int k = kind(f.status);
    ++counts[k];
    if (!f.p_enu.allFinite()) continue;
    by_kind[k].emplace_back(f.p_enu.x(), f.p_enu.y(), k == 0 ? z_used : z_others);
  }
  addDiscs(by_kind[0], kUsed, 5.0F, clouds);
  addDiscs(by_kind[2], kNotFused, 5.0F, clouds);
  addDiscs(by_kind[1], kRejected, 7.0F, clouds);
  const char* names[3] = {"used", "rejected", "not fused"};
  const Color colours[3] = {kUsed, kRejected, kNotFused};
  for (int k = 0; k < 3; ++k) {
    if (counts[k] > 0) {
      legend.push_back({fmt::format("GNSS {} ({})", names[k], counts[k]), rgb(colours[k]), false});
    }
  }
}

std::vector<render::Polyline> outageStretches(const Trajectory& traj,
                                              const std::vector<io::TimeSpan>& outages,
                                              std::optional<double> z) {
  std::vector<render::Polyline> lines;
  if (!traj.hasTimestamps()) return lines;
  for (const auto& o : outages) {
    const auto t0 = static_cast<std::int64_t>(std::llround(o.t0_s * 1e9)),
               t1 = static_cast<std::int64_t>(std::llround(o.t1_s * 1e9));
    // First pose at or after t0 (minus one: the bracketing pose), last at or before t1 (plus one).
    auto first = std::lower_bound(traj.t_ns.begin(), traj.t_ns.end(), t0);
    auto last = std::upper_bound(traj.t_ns.begin(), traj.t_ns.end(), t1);
    if (first != traj.t_ns.begin()) --first;
    if (last != traj.t_ns.end()) ++last;
    render::Polyline l;
    for (auto it = first; it < last; ++it) {
      Eigen::Vector3d p =
          traj.poses[static_cast<std::size_t>(it - traj.t_ns.begin())].translation();
      if (z) p.z() = *z;
      l.points.push_back(p);
    }
    if (l.points.size() < 2) continue;
    l.colors = {kOutage};
    l.widths_px = {6.0F};
    lines.push_back(std::move(l));
  }
  return lines;
}

render::LegendEntry outageLegend() {
  return {"GNSS outage", rgb(kOutage), false};
}

double lodCellSize(double resolution_m, double min_size_m) {
  double cell = resolution_m;
  for (int k = 0; k < 16 && cell < min_size_m * (1.0 - 1e-9); ++k) cell *= 2.0;
  return cell;
}

bool hasVaryingColour(const io::OccupancyMap& map) {
  if (!map.has_color || map.voxels.empty()) return false;
  const auto& first = map.voxels.front().rgb;
  return std::any_of(map.voxels.begin(), map.voxels.end(),
                     [&](const io::OccupiedVoxel& v) { return v.rgb != first; });
}

std::vector<render::VoxelSet> voxelSets(const io::OccupancyMap& map, const VoxelStyle& style) {
  const double cell = lodCellSize(map.resolution_m, style.min_size_m);
  struct Pool {
    std::uint32_t r = 0, g = 0, b = 0, n = 0;
  };
  // Leaves smaller than a cell pool into it (occupied if any is, as OctoMap's max rule makes its
  // inner nodes); larger pruned leaves keep their size.
  std::unordered_map<std::uint64_t, Pool> pooled;
  std::map<float, std::vector<std::size_t>> larger;
  for (std::size_t i = 0; i < map.voxels.size(); ++i) {
    const auto& v = map.voxels[i];
    if (static_cast<double>(v.size_m) >= cell * (1.0 - 1e-6)) {
      larger[v.size_m].push_back(i);
      continue;
    }
    Pool& p = pooled[cellKey(v.center_enu.cast<double>(), cell)];
    p.r += v.rgb[0];
    p.g += v.rgb[1];
    p.b += v.rgb[2];
    ++p.n;
  }
  auto colour = [&](const Eigen::Vector3d& c, float r, float g, float b) -> Color {
    if (style.tree_colour) return {r / 255.0F, g / 255.0F, b / 255.0F, 1.0F};
    return heightColour(c.z(), style.z_lo, style.z_hi);
  };
  std::vector<render::VoxelSet> sets;
  if (!pooled.empty()) {
    render::VoxelSet s;
    s.size_m = cell;
    s.centers.reserve(pooled.size());
    s.colors.reserve(pooled.size());
    for (const auto& [key, p] : pooled) {
      Eigen::Vector3d c;
      for (int a = 2; a >= 0; --a) {
        const auto i =
            static_cast<std::int64_t>((key >> (21U * static_cast<unsigned>(2 - a))) & 0x1FFFFFU) -
            (1 << 20);
        c[a] = (static_cast<double>(i) + 0.5) * cell;
      }
      const auto n = static_cast<float>(p.n);
      s.centers.push_back(c);
      s.colors.push_back(colour(c, static_cast<float>(p.r) / n, static_cast<float>(p.g) / n,
                                static_cast<float>(p.b) / n));
    }
    sets.push_back(std::move(s));
  }
  for (const auto& [size, indices] : larger) {
    render::VoxelSet s;
    s.size_m = size;
    for (const std::size_t i : indices) {
      const auto& v = map.voxels[i];
      s.centers.push_back(v.center_enu.cast<double>());
      s.colors.push_back(colour(s.centers.back(), v.rgb[0], v.rgb[1], v.rgb[2]));
    }
    sets.push_back(std::move(s));
  }
  return sets;
}

}  // namespace gvio::viz
