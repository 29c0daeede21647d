// gvio render: draws what a run folder holds into a PNG, off-screen through EGL.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <regex>

#include "cli/app.hpp"
#include "cli/render_camera.hpp"
#include "cli/render_video.hpp"
#include "fleet/merged_map.hpp"
#include "io/image_loader.hpp"
#include "io/input_error.hpp"
#include "io/run_dir.hpp"
#include "odometry/error.hpp"
#include "render/framebuffer.hpp"
#include "render/renderer.hpp"
#include "viz/image_bgr.hpp"
#include "viz/merged_view.hpp"
#include "viz/run_views.hpp"

namespace gvio::cli {
namespace {

// Points of a merged map drawn at most (thinned evenly per tile): what a top-down image can show
// of a city's tiles without reading every point into memory.
constexpr std::size_t kMergedMapPoints = 8'000'000;

struct RenderCliOptions {
  std::string run, out, view = "topdown", size = "1600x1200";
  std::optional<std::string> reference;
  // --view camera
  std::optional<double> at_s;
  std::optional<std::string> dataset;
  std::string overlay = "blend", map_colour = "depth";
  double ahead_s = 20.0;
  // --video
  std::optional<std::string> video;
  double fps = 10.0, speed = 1.0;
  double from_s = 0.0, to_s = INFINITY;
  bool size_given = false;
};

std::pair<int, int> parseSize(const std::string& text) {
  static const std::regex kSize(R"((\d{1,6})x(\d{1,6}))");
  std::smatch m;
  if (!std::regex_match(text, m, kSize))
    throw gvio::InvalidInput("--size '" + text + "': expected WxH, e.g. 1600x1200");
  const int w = std::stoi(m[1]), h = std::stoi(m[2]);
  if (w < 1 || h < 1 || w > render::kMaxImageSize || h > render::kMaxImageSize) {
    throw gvio::InvalidInput(
        fmt::format("--size {}x{}: each side must be 1..{} px", w, h, render::kMaxImageSize));
  }
  return {w, h};
}

// Milliseconds since the previous lap, for the log line that breaks down where the time went.
class Stopwatch {
 public:
  double lapMs() {
    const auto now = std::chrono::steady_clock::now();
    const double ms = std::chrono::duration<double, std::milli>(now - last_).count();
    last_ = now;
    return ms;
  }

 private:
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

void logSceneSize(const render::Scene& scene) {
  for (const auto& pc : scene.point_clouds) {
    if (pc.points.size() < 100) continue;  // markers
    spdlog::debug("scene: {} points of {} px", pc.points.size(),
                  pc.sizes_px.empty() ? 2.0F : pc.sizes_px.front());
  }
  for (const auto& v : scene.voxel_sets) {
    spdlog::debug("scene: {} voxels of {:g} m", v.centers.size(), v.size_m);
  }
}

// Renders a built view into --out (PNG) with its overlays; logs where the time went.
int drawToPng(viz::ViewSpec& spec, int width, int height, const RenderCliOptions& o, double read_ms,
              double build_ms) {
  logSceneSize(spec.scene);
  Stopwatch clock;
  const render::EglContext context;
  spdlog::info("EGL {}: {} ({})", context.info().platform, context.info().gl_renderer,
               context.info().gl_version);
  const render::Renderer renderer(context);
  render::Framebuffer target(width, height);
  clock.lapMs();
  const render::GpuScene gpu(spec.scene);
  spec.scene = {};  // uploaded: the CPU copy of a large map is no longer needed
  const double upload_ms = clock.lapMs();
  render::ImageRgba image = renderer.renderColor(gpu, spec.camera, target);
  const double draw_ms = clock.lapMs();
  render::annotate(image, spec.annotations);
  io::writePng(o.out, viz::toBgr(image));
  spdlog::info(
      "wrote {} ({}x{}, view {}): read {:.0f} ms, scene {:.0f} ms, upload {:.0f} ms, "
      "draw {:.0f} ms",
      o.out, width, height, o.view, read_ms, build_ms, upload_ms, draw_ms);
  return 0;
}

int runVideo(const RenderCliOptions& o, ProgressStyle progress) {
  if (o.at_s) throw gvio::InvalidInput("--at is for a still image, not --video");
  VideoRequest r;
  r.run = o.run;
  r.out = *o.video;
  r.view = o.view;
  std::tie(r.width, r.height) = parseSize(o.size_given ? o.size : "1280x720");
  r.fps = o.fps;
  r.speed = o.speed;
  r.span = {o.from_s, o.to_s};
  if (o.dataset) r.dataset = *o.dataset;
  r.overlay = o.overlay;
  r.map_colour = o.map_colour;
  r.progress = progress;
  return renderVideo(r);
}

int runRender(const RenderCliOptions& o, ProgressStyle progress) {
  if (o.video) {
    if (!o.out.empty()) throw gvio::InvalidInput("--video writes the video: no --out with it");
    return runVideo(o, progress);
  }
  if (o.out.empty()) throw gvio::InvalidInput("--out is required (or --video FILE)");
  if (o.view == "camera") {
    if (!o.at_s) throw gvio::InvalidInput("--view camera needs --at T (seconds into the drive)");
    CameraRenderRequest r{o.run, o.out, std::nullopt, *o.at_s, o.overlay, o.map_colour, o.ahead_s};
    if (o.dataset) r.dataset = *o.dataset;
    return renderCameraView(r);
  }
  if (o.at_s || o.dataset) throw gvio::InvalidInput("--at and --dataset are for --view camera");
  const viz::RunView view = viz::parseRunView(o.view);
  const auto [width, height] = parseSize(o.size);
  std::optional<std::filesystem::path> reference;
  if (o.reference) reference = *o.reference;
  const std::filesystem::path out_dir = std::filesystem::absolute(o.out).parent_path();
  if (!std::filesystem::is_directory(out_dir)) {
    throw io::InputError(o.out, 0, "output folder does not exist");  // before rendering for nothing
  }
  if (const auto warning = io::incompleteRunWarning(o.run)) spdlog::warn("{}", *warning);
  Stopwatch clock;
  viz::ViewSpec spec;
  if (fleet::isMergedMap(o.run) && !std::filesystem::exists(o.run + "/trajectory.tum")) {
    // A `gvio merge` folder: the tiles from above, a colour per drive.
    if (view != viz::RunView::kTopDown || reference) {
      throw gvio::InvalidInput("--run " + o.run +
                               " is a merged map (tiles.json): it draws --view topdown only");
    }
    const fleet::MergedMap map = fleet::readMergedMap(o.run, kMergedMapPoints);
    spdlog::info("merged map: {} of {} points ({} tiles) drawn", map.points.size(),
                 map.total_points, map.tiles.size());
    const double read_ms = clock.lapMs();
    spec = viz::buildMergedTopDown(map, width, height);
    return drawToPng(spec, width, height, o, read_ms, clock.lapMs());
  }
  const io::RunFiles run = io::readRunDir(o.run, viz::readOptionsFor(view, reference));
  const double read_ms = clock.lapMs();
  spec = viz::buildRunView(run, view, width, height);
  return drawToPng(spec, width, height, o, read_ms, clock.lapMs());
}

}  // namespace

Command addRenderCommand(CLI::App& app, const CommonOptions& common) {
  auto o = std::make_shared<RenderCliOptions>();
  CLI::App* sub =
      app.add_subcommand("render", "Draw a run's map and trajectories off-screen (EGL) into a PNG");
  sub->add_option("--run", o->run,
                  "Run folder (trajectory.tum / trajectory_vio.tum; optional groundtruth.tum, "
                  "map.pcd, map.ot / map.bt, gnss_fixes.csv, report.json, loops.csv)")
      ->required();
  sub->add_option("--view", o->view,
                  "topdown (map), perspective (3-D cloud), octomap (voxels), error (colour = "
                  "APE against the truth), or camera (the map over the recorded image at --at)");
  sub->add_option("--size", o->size,
                  "Image size WxH (1..16384 px per side; videos: 1280x720 unless given)")
      ->each([o](const std::string&) { o->size_given = true; });
  sub->add_option("--reference", o->reference,
                  "Ground truth file (TUM/KITTI/EuRoC) instead of groundtruth.tum");
  sub->add_option("--at", o->at_s,
                  "--view camera: seconds from the start of the trajectory (nearest image)");
  sub->add_option("--overlay", o->overlay,
                  "--view camera: blend (map over the image), edges (the map's outlines) or none "
                  "(the map alone)");
  sub->add_option("--map-colour", o->map_colour,
                  "--view camera: depth (distance, jet) or intensity (the map's grey levels)");
  sub->add_option("--ahead", o->ahead_s,
                  "--view camera: seconds of trajectory ahead of the camera drawn (default 20)");
  sub->add_option("--dataset", o->dataset,
                  "--view camera: the dataset, if not where report.json's sources say");
  sub->add_option("--video", o->video,
                  "Write a video along the drive instead (.mp4 H.264, .avi MJPEG) of --view "
                  "follow (chase camera), topdown (the map growing) or camera");
  sub->add_option("--fps", o->fps, "--video: frames per second of video (default 10)");
  sub->add_option("--speed", o->speed,
                  "--video: seconds of drive per second of video (default 1: real time)");
  sub->add_option("--from", o->from_s, "--video: start, seconds into the drive (default 0)");
  sub->add_option("--to", o->to_s, "--video: end, seconds into the drive (default: its end)");
  sub->add_option("--out", o->out, "Output PNG");
  return {sub, [o, &common] { return runRender(*o, common.progressStyle()); }};
}

}  // namespace gvio::cli
