#include "cli/render_camera.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <limits>

#include "cli/config.hpp"
#include "io/dataset_sources.hpp"
#include "io/image_loader.hpp"
#include "io/input_error.hpp"
#include "io/run_dir.hpp"
#include "io/run_sources.hpp"
#include "odometry/error.hpp"
#include "odometry/rectifier.hpp"
#include "render/egl_context.hpp"
#include "render/framebuffer.hpp"
#include "render/renderer.hpp"
#include "viz/camera_view.hpp"

namespace gvio::cli {
namespace {
namespace fs = std::filesystem;

// An image farther than this from the requested instant is not "the image at T".
constexpr double kMaxImageOffsetS = 0.2;

std::size_t nearestFrame(const io::Dataset& ds, std::int64_t t_ns) {
  std::size_t best = ds.frames.size();
  std::int64_t best_dt = std::numeric_limits<std::int64_t>::max();
  for (std::size_t i = 0; i < ds.frames.size(); ++i) {
    const std::int64_t dt = std::llabs(ds.frames[i].t_ns - t_ns);
    if (dt < best_dt) {
      best_dt = dt;
      best = i;
    }
  }
  if (best == ds.frames.size() || static_cast<double>(best_dt) * 1e-9 > kMaxImageOffsetS) {
    throw InvalidInput(fmt::format("{}: no image within {} s of the requested time",
                                   ds.root.string(), kMaxImageOffsetS));
  }
  return best;
}

// The dataset as the run opened it: its sources and its reader configuration (config.yaml).
io::Dataset reopenDataset(const CameraRenderRequest& r, std::string& mode) {
  const fs::path report = r.run / "report.json";
  const io::RunSources recorded = io::readRunSources(report);
  mode = recorded.mode;
  if (!recorded.dataset && !r.dataset) {
    throw io::InputError(
        report, 0, "no \"sources\" (a run by an older gvio): name the dataset with --dataset");
  }
  io::DatasetSources sources = recorded.dataset.value_or(io::DatasetSources{});
  if (r.dataset) {
    sources.dataset = *r.dataset;
    sources.format.reset();
  }
  ConfigSources config;
  if (fs::exists(r.run / "config.yaml")) config.file = r.run / "config.yaml";
  const AppConfig app = loadConfig(config);
  return io::openDataset(sources, app.dataset);
}

}  // namespace

int renderCameraView(const CameraRenderRequest& r) {
  const viz::OverlayMode overlay = viz::parseOverlayMode(r.overlay);
  if (!std::isfinite(r.at_s) || r.at_s < 0.0) throw InvalidInput("--at must be >= 0 s");
  if (!std::isfinite(r.ahead_s) || r.ahead_s < 0.0) throw InvalidInput("--ahead must be >= 0 s");
  if (!fs::is_directory(fs::absolute(r.out).parent_path())) {
    throw io::InputError(r.out, 0, "output folder does not exist");
  }
  if (const auto warning = io::incompleteRunWarning(r.run)) spdlog::warn("{}", *warning);
  io::RunReadOptions read;
  read.occupancy = read.gnss_fixes = read.outages = read.loops = false;
  const io::RunFiles run = io::readRunDir(r.run, read);
  const Trajectory& traj = viz::mapTrajectory(run);
  if (!traj.hasTimestamps()) throw io::InputError(r.run, 0, "the trajectory has no timestamps");
  const std::int64_t wanted_ns = traj.t_ns.front() + static_cast<std::int64_t>(r.at_s * 1e9);

  std::string mode;
  const io::Dataset ds = reopenDataset(r, mode);
  odometry::VioMode vio_mode{};
  try {
    vio_mode = odometry::parseVioMode(mode);
  } catch (const InvalidInput&) {
    throw io::InputError(r.run / "report.json", 0,
                         "the run has no camera trajectory (mode \"" + mode + "\")");
  }
  const bool stereo = odometry::usesStereo(vio_mode) && ds.cameras.size() >= 2;
  if (ds.cameras.empty()) throw InvalidInput(ds.root.string() + ": no camera");
  const odometry::Rectifier rectifier(
      ds.cameras[0], stereo ? std::optional<CameraModel>(ds.cameras[1]) : std::nullopt);
  const std::size_t frame = nearestFrame(ds, wanted_ns);
  const std::int64_t t_ns = ds.frames[frame].t_ns;
  const cv::Mat raw_left = io::loadFrameImage(ds, frame, 0);
  const cv::Mat raw_right = stereo ? io::loadFrameImage(ds, frame, 1) : cv::Mat();
  const cv::Mat left = rectifier.rectify(raw_left, raw_right).left;

  const CameraModel& cam = rectifier.left();
  const auto T_map_c = viz::cameraPoseAt(run, t_ns, cam.T_b_c);
  if (!T_map_c) {
    throw InvalidInput(fmt::format("{}: the trajectory has no pose at {:.3f} s", r.run.string(),
                                   static_cast<double>(t_ns) * 1e-9));
  }
  viz::CameraViewOptions options;
  options.ahead_s = r.ahead_s;
  options.colour = viz::parseMapColour(r.map_colour);
  render::PinholeIntrinsics K;
  K.fx = cam.fx;
  K.fy = cam.fy;
  K.cx = cam.cx;
  K.cy = cam.cy;
  K.width = cam.width_px;
  K.height = cam.height_px;
  K.near_m = 0.3;
  K.far_m = 2.0 * options.max_depth_m;
  const render::RenderCamera camera = render::pinholeCamera(K, *T_map_c);
  const render::Scene scene = viz::cameraScene(run, camera, t_ns, options);

  const render::EglContext context;
  const render::Renderer renderer(context);
  render::Framebuffer target(K.width, K.height);
  const render::GpuScene gpu(scene);
  const render::ImageRgba image = renderer.renderColor(gpu, camera, target);
  cv::Mat out = viz::composeOverlay(image, left, overlay);
  if (overlay == viz::OverlayMode::kEdges) {
    viz::drawPath(out, camera, viz::pathAhead(run, t_ns, options.ahead_s));
  }
  io::writePng(r.out, out);
  std::size_t points = 0;
  for (const auto& pc : scene.point_clouds) points += pc.points.size();
  spdlog::info("wrote {} ({}x{}, camera at {:.3f} s, image {}): {} map points in view",
               r.out.string(), K.width, K.height, static_cast<double>(t_ns) * 1e-9,
               io::imageSource(ds, frame, 0), points);
  return 0;
}

}  // namespace gvio::cli
