#include "cli/render_camera.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <limits>

#include "cli/config.hpp"
#include "io/image_loader.hpp"
#include "io/input_error.hpp"
#include "io/run_map.hpp"
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

bool stereoMode(const fs::path& run_dir, const std::string& mode) {
  try {
    return odometry::usesStereo(odometry::parseVioMode(mode));
  } catch (const InvalidInput&) {
    throw io::InputError(run_dir / "report.json", 0,
                         "the run has no camera trajectory (mode \"" + mode + "\")");
  }
}

}  // namespace

struct RecordedCameraOverlay::State {
  io::RunFiles run;
  io::Dataset ds;
  bool stereo = false;
  std::optional<odometry::Rectifier> rectifier;
  viz::CameraViewOptions options;
  viz::OverlayMode overlay = viz::OverlayMode::kBlend;
  render::PinholeIntrinsics K;
  render::EglContext context;
  render::Renderer renderer{context};
  std::optional<render::Framebuffer> target;
};

RecordedCameraOverlay::RecordedCameraOverlay(const fs::path& run_dir,
                                             const std::optional<fs::path>& dataset,
                                             const viz::CameraViewOptions& options,
                                             viz::OverlayMode overlay)
    : RecordedCameraOverlay(io::readMapRun(run_dir), dataset, options, overlay) {}

RecordedCameraOverlay::RecordedCameraOverlay(io::RunFiles run,
                                             const std::optional<fs::path>& dataset,
                                             const viz::CameraViewOptions& options,
                                             viz::OverlayMode overlay)
    : state_(std::make_unique<State>()) {
  State& s = *state_;
  io::requireMapTimestamps(run);
  s.run = std::move(run);
  const fs::path run_dir = s.run.dir;
  std::string mode;
  s.ds = io::reopenRunDataset(run_dir, dataset, loadRunConfig(run_dir).dataset, mode);
  if (s.ds.cameras.empty()) throw InvalidInput(s.ds.root.string() + ": no camera");
  s.stereo = stereoMode(run_dir, mode) && s.ds.cameras.size() >= 2;
  s.rectifier.emplace(s.ds.cameras[0],
                      s.stereo ? std::optional<CameraModel>(s.ds.cameras[1]) : std::nullopt);
  s.options = options;
  s.overlay = overlay;
  const CameraModel& cam = s.rectifier->left();
  s.K = viz::renderIntrinsics(cam, 0.3, 2.0 * options.max_depth_m);
  s.target.emplace(s.K.width, s.K.height);
}

RecordedCameraOverlay::~RecordedCameraOverlay() = default;

const io::RunFiles& RecordedCameraOverlay::run() const {
  return state_->run;
}
int RecordedCameraOverlay::width() const {
  return state_->K.width;
}
int RecordedCameraOverlay::height() const {
  return state_->K.height;
}
const CameraModel& RecordedCameraOverlay::camera() const {
  return state_->rectifier->left();
}

cv::Mat RecordedCameraOverlay::at(std::int64_t wanted_ns, std::string* frame_info) const {
  State& s = *state_;
  const std::size_t frame = nearestFrame(s.ds, wanted_ns);
  const std::int64_t t_ns = s.ds.frames[frame].t_ns;
  const cv::Mat raw_left = io::loadFrameImage(s.ds, frame, 0);
  const cv::Mat raw_right = s.stereo ? io::loadFrameImage(s.ds, frame, 1) : cv::Mat();
  const cv::Mat left = s.rectifier->rectify(raw_left, raw_right).left;
  const auto T_map_c = viz::cameraPoseAt(s.run, t_ns, s.rectifier->left().T_b_c);
  if (!T_map_c) {
    throw InvalidInput(fmt::format("{}: the trajectory has no pose at {:.3f} s", s.run.dir.string(),
                                   static_cast<double>(t_ns) * 1e-9));
  }
  const render::RenderCamera camera = render::pinholeCamera(s.K, *T_map_c);
  const render::Scene scene = viz::cameraScene(s.run, camera, t_ns, s.options);
  const render::GpuScene gpu(scene);
  const render::ImageRgba image = s.renderer.renderColor(gpu, camera, *s.target);
  cv::Mat out = viz::composeOverlay(image, left, s.overlay);
  if (s.overlay == viz::OverlayMode::kEdges) {
    viz::drawPath(out, camera, viz::pathAhead(s.run, t_ns, s.options.ahead_s));
  }
  if (frame_info != nullptr) {
    std::size_t points = 0;
    for (const auto& pc : scene.point_clouds) points += pc.points.size();
    *frame_info =
        fmt::format("camera at {:.3f} s, image {}: {} map points in view",
                    static_cast<double>(t_ns) * 1e-9, io::imageSource(s.ds, frame, 0), points);
  }
  return out;
}

int renderCameraView(const CameraRenderRequest& r) {
  const viz::OverlayMode overlay = viz::parseOverlayMode(r.overlay);
  if (!std::isfinite(r.at_s) || r.at_s < 0.0) throw InvalidInput("--at must be >= 0 s");
  if (!std::isfinite(r.ahead_s) || r.ahead_s < 0.0) throw InvalidInput("--ahead must be >= 0 s");
  if (!fs::is_directory(fs::absolute(r.out).parent_path())) {
    throw io::InputError(r.out, 0, "output folder does not exist");
  }
  viz::CameraViewOptions options;
  options.ahead_s = r.ahead_s;
  options.colour = viz::parseMapColour(r.map_colour);
  const RecordedCameraOverlay overlayer(r.run, r.dataset, options, overlay);
  const Trajectory& traj = io::mapTrajectory(overlayer.run());
  const std::int64_t wanted_ns = traj.t_ns.front() + static_cast<std::int64_t>(r.at_s * 1e9);
  std::string info;
  io::writePng(r.out, overlayer.at(wanted_ns, &info));
  spdlog::info("wrote {} ({}x{}, {})", r.out.string(), overlayer.width(), overlayer.height(), info);
  return 0;
}

}  // namespace gvio::cli
