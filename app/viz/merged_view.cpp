#include "viz/merged_view.hpp"

#include <fmt/format.h>

#include <algorithm>

#include "odometry/error.hpp"
#include "viz/map_layers.hpp"

namespace gvio::viz {
namespace {

render::Color rgba(const render::Rgb& c, float scale = 1.0F) {
  return {c.r * scale, c.g * scale, c.b * scale, 1.0F};
}

// The tile grid's outlines, above the points.
render::Polyline tileOutline(const fleet::MergedTile& t, double size_m, double z) {
  render::Polyline line;
  const Eigen::Vector2d a = t.sw_map;
  for (const Eigen::Vector2d& c :
       {a, Eigen::Vector2d(a.x() + size_m, a.y()), Eigen::Vector2d(a.x() + size_m, a.y() + size_m),
        Eigen::Vector2d(a.x(), a.y() + size_m), a}) {
    line.points.emplace_back(c.x(), c.y(), z);
  }
  line.colors = {render::Color(0.35F, 0.35F, 0.35F, 1.0F)};
  line.widths_px = {1.0F};
  return line;
}

}  // namespace

render::Rgb driveColour(std::uint16_t point_source_id) {
  // Tableau 10 (Tableau's default qualitative palette), distinct for the first ten drives.
  static constexpr std::array<render::Rgb, 10> kPalette{{{0.12F, 0.47F, 0.71F},
                                                         {1.00F, 0.50F, 0.05F},
                                                         {0.17F, 0.63F, 0.17F},
                                                         {0.84F, 0.15F, 0.16F},
                                                         {0.58F, 0.40F, 0.74F},
                                                         {0.55F, 0.34F, 0.29F},
                                                         {0.89F, 0.47F, 0.76F},
                                                         {0.50F, 0.50F, 0.50F},
                                                         {0.74F, 0.74F, 0.13F},
                                                         {0.09F, 0.75F, 0.81F}}};
  return kPalette[(point_source_id + kPalette.size() - 1) % kPalette.size()];
}

ViewSpec buildMergedTopDown(const fleet::MergedMap& map, int width, int height) {
  if (map.points.empty()) {
    throw InvalidInput((map.dir / "tiles.json").string() + ": the merged map has no point");
  }
  ViewSpec v;
  v.annotations.title = fmt::format("gvio merge {}: {} drives, {} tiles of {:g} m, EPSG:{}",
                                    map.dir.filename().string(), map.drives.size(),
                                    map.tiles.size(), map.tile_size_m, map.utm_epsg);
  const Eigen::AlignedBox3d q = quantileBounds(map.points);
  Eigen::AlignedBox3d fit(q.min(), q.max());
  float z_min = q.min().z(), z_max = q.max().z();
  for (const auto& p : map.points) {
    z_min = std::min(z_min, p.z());
    z_max = std::max(z_max, p.z());
  }
  fit.min().z() = z_min;
  fit.max().z() = z_max;
  for (const auto& t : map.tiles) {  // the whole grid is in view
    fit.extend(Eigen::Vector3d(t.sw_map.x(), t.sw_map.y(), z_min));
    fit.extend(
        Eigen::Vector3d(t.sw_map.x() + map.tile_size_m, t.sw_map.y() + map.tile_size_m, z_min));
  }
  const double top = fit.max().z() + 1.0;
  Eigen::AlignedBox3d box = fit;
  box.extend(Eigen::Vector3d(fit.min().x(), fit.min().y(), top + 4.0));
  v.camera = topDownClearOfOverlays(box, width, height);
  v.annotations.metres_per_pixel = v.camera.metres_per_pixel;
  v.annotations.north_deg = 0.0;  // UTM grid north is up

  // Points: the nearest to the camera (the highest) per pixel, in their drive's colour.
  const auto keep = nearestPerPixel(map.points, v.camera);
  render::PointCloud cloud;
  cloud.points.reserve(keep.size());
  cloud.colors.reserve(keep.size());
  for (const std::uint32_t k : keep) {
    cloud.points.push_back(map.points[k].cast<double>());
    cloud.colors.push_back(rgba(driveColour(map.point_source_id[k])));
  }
  const double mpp = v.camera.metres_per_pixel;
  cloud.sizes_px = {pointSizePx(typicalSpacingM(map.points, 5.0 * mpp), mpp)};
  v.scene.point_clouds.push_back(std::move(cloud));

  for (const auto& t : map.tiles) v.scene.polylines.push_back(tileOutline(t, map.tile_size_m, top));
  for (const auto& d : map.drives) {
    v.annotations.legend.push_back(
        {fmt::format("{} (point source ID {})", d.name, d.point_source_id),
         driveColour(d.point_source_id), false});
    if (d.track_map.size() < 2) continue;
    render::Polyline track;
    for (const auto& p : d.track_map) track.points.emplace_back(p.x(), p.y(), top + 2.0);
    track.colors = {rgba(driveColour(d.point_source_id), 0.6F)};
    track.widths_px = {2.5F};
    v.scene.polylines.push_back(std::move(track));
  }
  v.annotations.legend.push_back(
      {fmt::format("tile ({:g} m)", map.tile_size_m), render::Rgb{0.35F, 0.35F, 0.35F}, false});
  return v;
}

}  // namespace gvio::viz
