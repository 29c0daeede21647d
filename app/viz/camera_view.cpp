#include "viz/camera_view.hpp"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "fusion/vio_enu_alignment.hpp"
#include "io/run_map.hpp"
#include "odometry/error.hpp"
#include "render/colormap.hpp"
#include "viz/map_layers.hpp"

namespace gvio::viz {
namespace {

constexpr float kMinSplatPx = 1.5F;
constexpr float kMaxSplatPx = 12.0F;
const render::Color kPathColor{0.95F, 0.1F, 0.75F, 1.0F};
// Blend: share of the map in a covered pixel. Edges: the outline's colour (BGR).
constexpr double kBlendWeight = 0.6;
const cv::Vec3b kEdgeBgr{0, 255, 255};
const cv::Scalar kPathBgr(191, 25, 242);  // kPathColor

}  // namespace

std::vector<Eigen::Vector3d> positionsBetween(const Trajectory& traj, std::int64_t t0_ns,
                                              std::int64_t t1_ns) {
  std::vector<Eigen::Vector3d> path;
  for (std::size_t i = 0; i < traj.size() && i < traj.t_ns.size(); ++i) {
    if (traj.t_ns[i] >= t0_ns && traj.t_ns[i] <= t1_ns) path.push_back(traj.poses[i].translation());
  }
  return path;
}

std::vector<Eigen::Vector3d> pathAhead(const io::RunFiles& run, std::int64_t t_ns, double ahead_s) {
  return positionsBetween(io::mapTrajectory(run), t_ns,
                          t_ns + static_cast<std::int64_t>(ahead_s * 1e9));
}

void drawPath(cv::Mat& bgr, const render::RenderCamera& camera,
              const std::vector<Eigen::Vector3d>& path) {
  std::vector<cv::Point> run_px;
  const auto flush = [&] {
    if (run_px.size() >= 2) {
      cv::polylines(bgr, run_px, false, kPathBgr, 3, cv::LINE_AA);
    }
    run_px.clear();
  };
  for (const Eigen::Vector3d& p : path) {
    double z = 0.0;
    const Eigen::Vector2d px = render::projectToPixel(camera, p, &z);
    if (!(z > camera.near_m) || !px.allFinite() || px.cwiseAbs().maxCoeff() > 1e5) {
      flush();  // behind the camera: the line breaks there
      continue;
    }
    run_px.emplace_back(static_cast<int>(std::lround(px.x())),
                        static_cast<int>(std::lround(px.y())));
  }
  flush();
}

OverlayMode parseOverlayMode(const std::string& name) {
  if (name == "blend") return OverlayMode::kBlend;
  if (name == "edges") return OverlayMode::kEdges;
  if (name == "none") return OverlayMode::kNone;
  throw InvalidInput("unknown overlay '" + name + "' (expected blend, edges or none)");
}

MapColour parseMapColour(const std::string& name) {
  if (name == "depth") return MapColour::kDepth;
  if (name == "intensity") return MapColour::kIntensity;
  throw InvalidInput("unknown map colour '" + name + "' (expected depth or intensity)");
}

render::PinholeIntrinsics renderIntrinsics(const CameraModel& camera, double near_m, double far_m) {
  render::PinholeIntrinsics K;
  K.fx = camera.fx;
  K.fy = camera.fy;
  K.cx = camera.cx;
  K.cy = camera.cy;
  K.width = camera.width_px;
  K.height = camera.height_px;
  K.near_m = near_m;
  K.far_m = far_m;
  return K;
}

std::optional<Eigen::Isometry3d> cameraPoseAt(const io::RunFiles& run, std::int64_t t_ns,
                                              const Eigen::Isometry3d& T_b_c) {
  const Trajectory& traj = io::mapTrajectory(run);
  if (!traj.hasTimestamps()) return std::nullopt;
  const auto T_map_b = fusion::interpolatePose(traj, t_ns);
  if (!T_map_b) return std::nullopt;
  return *T_map_b * T_b_c;
}

render::Scene cameraScene(const io::RunFiles& run, const render::RenderCamera& camera,
                          std::int64_t t_ns, const CameraViewOptions& options) {
  render::Scene scene;
  scene.background = {0, 0, 0, 0};
  if (run.cloud && !run.cloud->p_enu.empty()) {
    const std::vector<std::uint32_t> visible = nearestPerPixel(run.cloud->p_enu, camera);
    render::PointCloud points;
    points.round = true;
    // The focal length in pixels: projectToPixel of a point 1 m to the side at 1 m depth.
    const Eigen::Isometry3d T_w_c(camera.view.inverse());
    const Eigen::Vector2d c0 = render::projectToPixel(camera, T_w_c * Eigen::Vector3d(0, 0, 1));
    const Eigen::Vector2d c1 = render::projectToPixel(camera, T_w_c * Eigen::Vector3d(1, 0, 1));
    const double f_px = (c1 - c0).norm();
    for (const std::uint32_t i : visible) {
      const Eigen::Vector3d p = run.cloud->p_enu[i].cast<double>();
      double z = 0.0;
      (void)render::projectToPixel(camera, p, &z);
      if (!(z > 0.0) || z > options.max_depth_m) continue;
      const bool grey = options.colour == MapColour::kIntensity && !run.cloud->intensity.empty();
      const render::Rgb c =
          grey ? render::Rgb{run.cloud->intensity[i] / 255.0F, run.cloud->intensity[i] / 255.0F,
                             run.cloud->intensity[i] / 255.0F}
               : render::colormap(
                     render::ColorMap::kJet,
                     1.0 - render::normalise(std::log(z), 0.0, std::log(options.max_depth_m)));
      points.points.push_back(p);
      points.colors.emplace_back(c.r, c.g, c.b, 1.0F);
      points.sizes_px.push_back(
          std::clamp(static_cast<float>(f_px * options.splat_m / z), kMinSplatPx, kMaxSplatPx));
    }
    if (!points.points.empty()) scene.point_clouds.push_back(std::move(points));
  }
  render::Polyline ahead;
  ahead.points = pathAhead(run, t_ns, options.ahead_s);
  if (ahead.points.size() >= 2) {
    ahead.colors = {kPathColor};
    ahead.widths_px = {3.0F};
    scene.polylines.push_back(std::move(ahead));
  }
  return scene;
}

cv::Mat composeOverlay(const render::ImageRgba& rendered, const cv::Mat& recorded_grey,
                       OverlayMode mode) {
  if (recorded_grey.type() != CV_8UC1 || recorded_grey.cols != rendered.width ||
      recorded_grey.rows != rendered.height) {
    throw InvalidInput("overlay: the recorded image and the render differ in size or type");
  }
  cv::Mat out;
  cv::cvtColor(recorded_grey, out, cv::COLOR_GRAY2BGR);
  if (mode == OverlayMode::kNone) out.setTo(cv::Scalar::all(0));
  if (mode == OverlayMode::kEdges) {
    // The map's outlines and depth steps: edges of its rendered colour (jet of the distance) over
    // a black background, so silhouettes count as edges too.
    cv::Mat grey(rendered.height, rendered.width, CV_8UC1), edges;
    for (int y = 0; y < rendered.height; ++y) {
      for (int x = 0; x < rendered.width; ++x) {
        const std::uint8_t* m = rendered.pixel(x, y);
        grey.at<std::uint8_t>(y, x) = static_cast<std::uint8_t>(
            (m[3] * (0.299 * m[0] + 0.587 * m[1] + 0.114 * m[2])) / 255.0);
      }
    }
    // Closing then a median fill the gaps between splats, so only the map's structure has edges.
    cv::morphologyEx(grey, grey, cv::MORPH_CLOSE,
                     cv::getStructuringElement(cv::MORPH_ELLIPSE, {7, 7}));
    cv::medianBlur(grey, grey, 7);
    cv::Canny(grey, edges, 50, 150);
    out.setTo(kEdgeBgr, edges);
    return out;
  }
  for (int y = 0; y < rendered.height; ++y) {
    for (int x = 0; x < rendered.width; ++x) {
      const std::uint8_t* m = rendered.pixel(x, y);
      const double a = (mode == OverlayMode::kNone ? 1.0 : kBlendWeight) * m[3] / 255.0;
      cv::Vec3b& o = out.at<cv::Vec3b>(y, x);
      // RGBA in, BGR out.
      for (int c = 0; c < 3; ++c) {
        o[c] = cv::saturate_cast<std::uint8_t>((1.0 - a) * o[c] + a * m[2 - c]);
      }
    }
  }
  return out;
}

}  // namespace gvio::viz
