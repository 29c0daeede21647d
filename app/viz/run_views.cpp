#include "viz/run_views.hpp"

#include <fmt/format.h>

#include "eval/evaluate.hpp"
#include "odometry/error.hpp"

namespace gvio::viz {
namespace {

using render::Color;

const Color kTruth(0.55F, 0.55F, 0.55F, 1), kVio(1.0F, 0.5F, 0.05F, 1),
    kFused(0.12F, 0.38F, 0.85F, 1);

render::Rgb rgb(const Color& c) {
  return {c[0], c[1], c[2]};
}

render::Polyline line(const Trajectory& t, const Color& color, float width_px) {
  render::Polyline l;
  for (const auto& T : t.poses) l.points.push_back(T.translation());
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

render::GroundGrid groundGrid(const Eigen::AlignedBox3d& box) {
  render::GroundGrid g;
  const double extent = std::max({box.sizes().x(), box.sizes().y(), 1.0});
  g.spacing_m = render::niceLength(extent / 8.0);
  g.half_cells = static_cast<int>(std::ceil(0.5 * extent / g.spacing_m)) + 1;
  g.center =
      Eigen::Vector3d(std::round(box.center().x() / g.spacing_m) * g.spacing_m,
                      std::round(box.center().y() / g.spacing_m) * g.spacing_m, box.min().z());
  g.color = Color(0.85F, 0.85F, 0.85F, 1);
  return g;
}

// Trajectories as lines, the main one last (on top); legend entries in the same order.
void addTrajectories(const io::RunFiles& run, ViewSpec& v) {
  if (run.truth) {
    v.scene.polylines.push_back(line(*run.truth, kTruth, 2.0F));
    v.annotations.legend.push_back({"ground truth", rgb(kTruth), false});
  }
  if (run.vio) {
    v.scene.polylines.push_back(line(*run.vio, kVio, 2.0F));
    v.annotations.legend.push_back({"VIO (own world frame)", rgb(kVio), false});
  }
  if (run.fused) {
    v.scene.polylines.push_back(line(*run.fused, kFused, 3.0F));
    v.annotations.legend.push_back({"fused (ENU)", rgb(kFused), false});
  }
  v.scene.point_clouds.push_back(endpoints(v.scene.polylines.back().points));
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

}  // namespace

RunView parseRunView(const std::string& name) {
  if (name == "topdown") return RunView::kTopDown;
  if (name == "perspective") return RunView::kPerspective;
  if (name == "error") return RunView::kError;
  throw InvalidInput("--view: expected topdown, perspective or error (got '" + name + "')");
}

ViewSpec buildRunView(const io::RunFiles& run, RunView view, int width, int height) {
  ViewSpec v;
  v.annotations.title = "gvio run " + run.dir.filename().string();
  if (view == RunView::kError) {
    addErrorColouredTrajectory(run, v);
  } else {
    addTrajectories(run, v);
  }
  const Eigen::AlignedBox3d box = v.scene.bounds();
  v.scene.grids.push_back(groundGrid(box));
  if (view == RunView::kPerspective) {
    v.camera = render::orbitCamera(box, width, height);
  } else {
    v.camera = render::topDownCamera(box, width, height, 0.08);
    v.annotations.metres_per_pixel = v.camera.metres_per_pixel;
    v.annotations.north_deg = 0.0;  // ENU top-down: north is up
  }
  return v;
}

}  // namespace gvio::viz
