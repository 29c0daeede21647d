#include "viz/run_views.hpp"

#include <fmt/format.h>

#include <cmath>

#include "eval/evaluate.hpp"
#include "odometry/error.hpp"
#include "viz/loop_layer.hpp"
#include "viz/map_layers.hpp"

namespace gvio::viz {
namespace {

using render::Color;

const Color kTruth(0.55F, 0.55F, 0.55F, 1), kVio(1.0F, 0.5F, 0.05F, 1),
    kFused(0.12F, 0.38F, 0.85F, 1);
constexpr double kElevationDeg = 35.0, kGridBelowM = 0.3;

render::Rgb rgb(const Color& c) {
  return {c[0], c[1], c[2]};
}

std::vector<Eigen::Vector3d> positions(const Trajectory& t) {
  std::vector<Eigen::Vector3d> p;
  p.reserve(t.size());
  for (const auto& T : t.poses) p.push_back(T.translation());
  return p;
}

// A trajectory as a line; at height `z` when given (top-down: above the map).
render::Polyline line(const Trajectory& t, const Color& color, float width_px,
                      std::optional<double> z = std::nullopt) {
  render::Polyline l;
  l.points = positions(t);
  if (z) {
    for (auto& p : l.points) p.z() = *z;
  }
  l.colors = {color};
  l.widths_px = {width_px};
  return l;
}

// Start (green) and end (red) discs of the main trajectory.
render::PointCloud endpoints(const std::vector<Eigen::Vector3d>& points) {
  render::PointCloud pc;
  pc.points = {points.front(), points.back()};
  pc.colors = {Color(0.1F, 0.7F, 0.2F, 1), Color(0.85F, 0.1F, 0.1F, 1)};
  pc.sizes_px = {12.0F};
  return pc;
}

// Under the box's floor: a grid at the ground's own height would z-fight with the map's ground.
render::GroundGrid groundGrid(const Eigen::AlignedBox3d& box, double below_m = 0.0) {
  render::GroundGrid g;
  const double extent = std::max({box.sizes().x(), box.sizes().y(), 1.0});
  g.spacing_m = render::niceLength(extent / 8.0);
  g.half_cells = static_cast<int>(std::ceil(0.5 * extent / g.spacing_m)) + 1;
  g.center = Eigen::Vector3d(std::round(box.center().x() / g.spacing_m) * g.spacing_m,
                             std::round(box.center().y() / g.spacing_m) * g.spacing_m,
                             box.min().z() - below_m);
  g.color = Color(0.85F, 0.85F, 0.85F, 1);
  return g;
}

// The trajectory the map is built from: fused (ENU), else VIO.
const Trajectory& mainTrajectory(const io::RunFiles& run) {
  return run.fused ? *run.fused : *run.vio;
}

// Trajectories as lines, the main one last (on top); legend entries in the same order. Over a
// map (ENU) the VIO line is left out when a fused one exists: its world frame is not the map's.
void addTrajectories(const io::RunFiles& run, ViewSpec& v, bool over_map,
                     std::optional<double> z = std::nullopt) {
  if (run.truth) {
    v.scene.polylines.push_back(line(*run.truth, kTruth, 2.0F, z));
    v.annotations.legend.push_back({"ground truth", rgb(kTruth), false});
  }
  if (run.vio && !(over_map && run.fused)) {
    v.scene.polylines.push_back(line(*run.vio, kVio, 2.0F, z));
    v.annotations.legend.push_back({"VIO (own world frame)", rgb(kVio), false});
  }
  if (run.fused) {
    v.scene.polylines.push_back(line(*run.fused, kFused, 3.0F, z));
    v.annotations.legend.push_back({"fused (ENU)", rgb(kFused), false});
  }
}

void addOutages(const io::RunFiles& run, ViewSpec& v, std::optional<double> z) {
  if (!run.fused) return;
  const auto stretches = outageStretches(*run.fused, run.outages, z);
  if (stretches.empty()) return;
  v.scene.polylines.insert(v.scene.polylines.end(), stretches.begin(), stretches.end());
  v.annotations.legend.push_back(outageLegend());
}

// The estimate coloured by its APE against the truth: the fused trajectory as is (both in ENU),
// else the VIO one after SE(3) alignment.
void addErrorColouredTrajectory(const io::RunFiles& run, ViewSpec& v) {
  if (!run.truth)
    throw InvalidInput(
        "the error view needs ground truth (groundtruth.tum in the run or --reference)");
  eval::EvalOptions opt;
  opt.align = run.fused ? eval::Alignment::kNone : eval::Alignment::kSe3;
  const eval::EvalResult r = eval::evaluate(*run.truth, run.fused ? *run.fused : *run.vio, opt);
  v.scene.polylines.push_back(line(*run.truth, kTruth, 2.0F));
  render::Polyline est;
  for (std::size_t i = 0; i < r.est.size(); ++i) {
    est.points.emplace_back(r.est[i].topRightCorner<3, 1>());
    const render::Rgb c = render::colormap(
        render::ColorMap::kViridis, render::normalise(r.ape[i], r.ape_stats.min, r.ape_stats.max));
    est.colors.emplace_back(c.r, c.g, c.b, 1.0F);
  }
  est.widths_px = {4.0F};
  v.scene.polylines.push_back(est);
  v.scene.point_clouds.push_back(endpoints(est.points));
  v.annotations.legend = {{"ground truth", rgb(kTruth), false},
                          {run.fused ? "fused (ENU)" : "VIO, SE(3) aligned",
                           render::colormap(render::ColorMap::kViridis, 0.6), false}};
  v.annotations.color_bar = render::Annotations::ColorBar{
      render::ColorMap::kViridis, r.ape_stats.min, r.ape_stats.max, "APE (m)"};
  v.annotations.title +=
      fmt::format(", APE rmse {:.3f} m over {} poses", r.ape_stats.rmse, r.ape_stats.n);
}

void heightBar(double lo, double hi, ViewSpec& v) {
  v.annotations.color_bar =
      render::Annotations::ColorBar{render::ColorMap::kViridis, lo, hi, "height (m)"};
}

}  // namespace

// A top-down camera fitted to `box` with the box kept clear of the overlays: the compass and
// colour bar column at the right edge and the title strip at the top (render::annotationUnitPx).
// The reserve is in pixels, so it is refitted until the scale settles.
render::RenderCamera topDownClearOfOverlays(const Eigen::AlignedBox3d& box, int width, int height) {
  const double unit = render::annotationUnitPx(width, height);
  render::RenderCamera camera = render::topDownCamera(box, width, height, 0.08);
  for (int i = 0; i < 4; ++i) {
    Eigen::AlignedBox3d reserved = box;
    reserved.max().x() += 10.0 * unit * camera.metres_per_pixel;
    reserved.max().y() += 5.0 * unit * camera.metres_per_pixel;
    camera = render::topDownCamera(reserved, width, height, 0.08);
  }
  return camera;
}

namespace {

// Orthographic, north up. Layers by height, since the camera looks straight down: the cloud at
// its own heights, then (lifted above everything) used fixes, trajectories, outages, rejected and
// skipped fixes, accepted loop closures, start/end.
void buildTopDown(const io::RunFiles& run, int width, int height, ViewSpec& v) {
  const bool map = run.cloud && !run.cloud->p_enu.empty();
  Eigen::AlignedBox3d fit;  // what the view must show
  double z_lo = 0.0, z_hi = 0.0;
  if (map) {
    // Horizontal extent without stray points; heights all of them (the lowest ground must not
    // fall behind the far plane), the colour scale again without the strays.
    const Eigen::AlignedBox3d q = quantileBounds(run.cloud->p_enu);
    float z_min = q.min().z(), z_max = q.max().z();
    for (const auto& p : run.cloud->p_enu) {
      z_min = std::min(z_min, p.z());
      z_max = std::max(z_max, p.z());
    }
    fit.extend(Eigen::Vector3d(q.min().x(), q.min().y(), z_min));
    fit.extend(Eigen::Vector3d(q.max().x(), q.max().y(), z_max));
    z_lo = q.min().z();
    z_hi = q.max().z();
  }
  for (const auto* t : {&run.fused, &run.vio, &run.truth}) {
    if (!*t || (map && t == &run.vio && run.fused)) continue;
    for (const auto& p : positions(**t)) fit.extend(p);
  }
  if (run.gnss_fixes) {
    for (const auto& f : *run.gnss_fixes) {
      if (f.status == io::FixStatus::kUsed && f.p_enu.allFinite()) fit.extend(f.p_enu);
    }
  }
  const double top = fit.max().z() + 1.0;
  std::vector<render::PointCloud> markers;  // fixes and loop keyframes
  std::vector<render::LegendEntry> fix_legend;
  if (run.gnss_fixes) addGnssFixes(*run.gnss_fixes, top + 1.0, top + 4.0, markers, fix_legend);
  addTrajectories(run, v, map, top + 2.0);
  addOutages(run, v, top + 3.0);
  v.annotations.legend.insert(v.annotations.legend.end(), fix_legend.begin(), fix_legend.end());
  // Loop keyframes are poses of the main trajectory, already inside `fit`.
  if (run.loops) {
    addLoopClosures(*run.loops, mainTrajectory(run), top + 4.5, v.scene.polylines, markers,
                    v.annotations.legend);
  }
  Eigen::AlignedBox3d box = fit;
  box.extend(Eigen::Vector3d(fit.min().x(), fit.min().y(), top + 6.0));
  v.camera = topDownClearOfOverlays(box, width, height);
  v.annotations.metres_per_pixel = v.camera.metres_per_pixel;
  v.annotations.north_deg = 0.0;  // ENU top-down: north is up
  v.scene.grids.push_back(groundGrid(fit, kGridBelowM));
  if (map) {
    CloudStyle style;
    style.z_lo = z_lo;
    style.z_hi = z_hi;
    const double mpp = v.camera.metres_per_pixel;
    style.size_px = pointSizePx(typicalSpacingM(run.cloud->p_enu, 5.0 * mpp), mpp);
    const auto keep = nearestPerPixel(run.cloud->p_enu, v.camera);
    v.scene.point_clouds.push_back(colouredCloud(*run.cloud, style, &keep));
    heightBar(z_lo, z_hi, v);
  }
  v.scene.point_clouds.insert(v.scene.point_clouds.end(), markers.begin(), markers.end());
  auto ends = endpoints(positions(mainTrajectory(run)));
  for (auto& p : ends.points) p.z() = top + 5.0;
  v.scene.point_clouds.push_back(ends);
}

// Behind and above the start of the drive, looking along its first heading.
render::RenderCamera behindTheDrive(const io::RunFiles& run, const Eigen::AlignedBox3d& box,
                                    int width, int height) {
  const auto heading = startHeadingRad(positions(mainTrajectory(run)));
  const double azimuth_deg = heading ? *heading * 180.0 / M_PI + 180.0 : -60.0;
  return render::orbitCamera(box, width, height, azimuth_deg, kElevationDeg);
}

void buildPerspective(const io::RunFiles& run, int width, int height, ViewSpec& v) {
  if (!run.cloud || run.cloud->p_enu.empty()) {  // no map: the trajectories' orbit view
    addTrajectories(run, v, false);
    v.scene.point_clouds.push_back(endpoints(v.scene.polylines.back().points));
    const Eigen::AlignedBox3d box = v.scene.bounds();
    v.scene.grids.push_back(groundGrid(box));
    v.camera = render::orbitCamera(box, width, height);
    return;
  }
  const io::MapCloud& cloud = *run.cloud;
  const Eigen::AlignedBox3d q = quantileBounds(cloud.p_enu);
  v.camera = behindTheDrive(run, q, width, height);
  CloudStyle style;
  style.z_lo = q.min().z();
  style.z_hi = q.max().z();
  style.shade_by_intensity = true;
  const double mpp = metresPerPixelAt(v.camera, q.center());
  style.size_px = pointSizePx(typicalSpacingM(cloud.p_enu, 5.0 * mpp), mpp);
  // The dense cloud when there is one (sparse landmarks are its noisier subset).
  const auto dense = densePointIndices(cloud);
  const auto keep = nearestPerPixel(cloud.p_enu, v.camera, &dense);
  v.annotations.legend.push_back(
      {fmt::format("{} ({})", hasDensePoints(cloud) ? "dense stereo points" : "map points",
                   dense.size()),
       render::colormap(render::ColorMap::kViridis, 0.5), false});
  v.scene.point_clouds.push_back(colouredCloud(cloud, style, &keep));
  addTrajectories(run, v, true);
  addOutages(run, v, std::nullopt);
  v.scene.point_clouds.push_back(endpoints(positions(mainTrajectory(run))));
  v.scene.grids.push_back(groundGrid(q, kGridBelowM));
  heightBar(style.z_lo, style.z_hi, v);
}

void buildOctomap(const io::RunFiles& run, int width, int height, ViewSpec& v) {
  if (!run.occupancy) {
    throw InvalidInput("the octomap view needs map.ot or map.bt in the run folder " +
                       run.dir.string());
  }
  const io::OccupancyMap& map = *run.occupancy;
  if (map.voxels.empty()) {
    throw InvalidInput("the octomap view has nothing to draw: " + map.file.string() +
                       " holds no occupied voxels");
  }
  std::vector<Eigen::Vector3f> centers;
  centers.reserve(map.voxels.size());
  for (const auto& vox : map.voxels) centers.push_back(vox.center_enu);
  Eigen::AlignedBox3d q = quantileBounds(centers);
  q.min() -= Eigen::Vector3d::Constant(0.5 * map.resolution_m);
  q.max() += Eigen::Vector3d::Constant(0.5 * map.resolution_m);
  v.camera = behindTheDrive(run, q, width, height);
  VoxelStyle style;
  // Voxels far below a pixel cost triangles and show nothing: merge them into about one pixel.
  style.min_size_m = metresPerPixelAt(v.camera, q.center());
  style.tree_colour = hasVaryingColour(map);
  style.z_lo = q.min().z();
  style.z_hi = q.max().z();
  auto sets = voxelSets(map, style);
  std::size_t drawn = 0;
  for (const auto& s : sets) drawn += s.centers.size();
  const double cell = lodCellSize(map.resolution_m, style.min_size_m);
  v.annotations.legend.push_back({fmt::format("occupied voxels ({}, {:g} m cells)", drawn, cell),
                                  style.tree_colour
                                      ? render::Rgb{0.6F, 0.6F, 0.6F}
                                      : render::colormap(render::ColorMap::kViridis, 0.5),
                                  false});
  v.scene.voxel_sets = std::move(sets);
  addTrajectories(run, v, true);
  addOutages(run, v, std::nullopt);
  v.scene.point_clouds.push_back(endpoints(positions(mainTrajectory(run))));
  v.scene.grids.push_back(groundGrid(q, kGridBelowM));
  if (!style.tree_colour) heightBar(style.z_lo, style.z_hi, v);
}

}  // namespace

RunView parseRunView(const std::string& name) {
  if (name == "topdown") return RunView::kTopDown;
  if (name == "perspective") return RunView::kPerspective;
  if (name == "octomap") return RunView::kOctomap;
  if (name == "error") return RunView::kError;
  throw InvalidInput("--view: expected topdown, perspective, octomap or error (got '" + name +
                     "')");
}

io::RunReadOptions readOptionsFor(RunView view,
                                  const std::optional<std::filesystem::path>& reference) {
  io::RunReadOptions o;
  o.reference = reference;
  o.cloud = view == RunView::kTopDown || view == RunView::kPerspective;
  o.occupancy = view == RunView::kOctomap;
  o.gnss_fixes = view == RunView::kTopDown;
  o.outages = view != RunView::kError;
  o.loops = view == RunView::kTopDown;
  return o;
}

ViewSpec buildTopDownMapOnly(io::RunFiles run, int width, int height) {
  run.truth.reset();
  run.loops.reset();
  run.outages.clear();
  ViewSpec v = buildRunView(run, RunView::kTopDown, width, height);
  v.scene.polylines.clear();
  std::erase_if(v.annotations.legend, [](const render::LegendEntry& e) {
    return e.label == "VIO (own world frame)" || e.label == "fused (ENU)";
  });
  v.annotations.legend.insert(v.annotations.legend.begin(),
                              {"path driven", render::Rgb{0.95F, 0.1F, 0.75F}, false});
  return v;
}

double metresPerPixelAt(const render::RenderCamera& camera, const Eigen::Vector3d& p_w) {
  if (!camera.perspective) return camera.metres_per_pixel;
  const double depth = (camera.view * p_w.homogeneous()).z();
  const double fy = -0.5 * camera.projection(1, 1) * camera.height;  // P(1,1) = -2 fy / H
  return std::abs(depth) / fy;
}

ViewSpec buildRunView(const io::RunFiles& run, RunView view, int width, int height) {
  ViewSpec v;
  v.annotations.title = "gvio run " + run.dir.filename().string();
  switch (view) {
    case RunView::kError: {
      addErrorColouredTrajectory(run, v);
      const Eigen::AlignedBox3d box = v.scene.bounds();
      v.scene.grids.push_back(groundGrid(box));
      v.camera = topDownClearOfOverlays(box, width, height);
      v.annotations.metres_per_pixel = v.camera.metres_per_pixel;
      v.annotations.north_deg = 0.0;
      break;
    }
    case RunView::kTopDown:
      buildTopDown(run, width, height, v);
      break;
    case RunView::kPerspective:
      buildPerspective(run, width, height, v);
      break;
    case RunView::kOctomap:
      buildOctomap(run, width, height, v);
      break;
  }
  return v;
}

}  // namespace gvio::viz
