#include "cli/render_video.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <functional>
#include <optional>

#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "cli/render_camera.hpp"
#include "io/atomic_write.hpp"
#include "io/input_error.hpp"
#include "io/quiet_stderr.hpp"
#include "io/run_map.hpp"
#include "odometry/error.hpp"
#include "render/annotate.hpp"
#include "render/egl_context.hpp"
#include "render/framebuffer.hpp"
#include "render/renderer.hpp"
#include "viz/camera_view.hpp"
#include "viz/image_bgr.hpp"
#include "viz/map_layers.hpp"
#include "viz/run_views.hpp"
#include "viz/video_views.hpp"

namespace gvio::cli {
namespace {
namespace fs = std::filesystem;

// The top-down video reveals the map within this distance of the path driven so far.
constexpr double kRevealM = 40.0;
// The follow video draws the map's ground tiles of this side within this distance of its camera.
constexpr double kTileM = 32.0;
constexpr double kDrawRadiusM = 120.0;
constexpr double kTrailS = 20.0;  // the follow video's path: the last 20 s

// The container's codec by extension (FFmpeg picks the container from it).
std::vector<int> codecsFor(const fs::path& out) {
  const std::string ext = out.extension().string();
  if (ext == ".mp4" || ext == ".m4v" || ext == ".mov") {
    return {cv::VideoWriter::fourcc('a', 'v', 'c', '1'),
            cv::VideoWriter::fourcc('m', 'p', '4', 'v')};
  }
  if (ext == ".avi") return {cv::VideoWriter::fourcc('M', 'J', 'P', 'G')};
  throw io::InputError(out, 0, "unknown video container (expected .mp4, .m4v, .mov or .avi)");
}

// The frame at an instant of the drive (BGR, the video's size).
using FrameSource = std::function<cv::Mat(std::int64_t t_ns)>;

void encode(const VideoRequest& r, const std::vector<std::int64_t>& times, int width, int height,
            const FrameSource& frame) {
  const std::vector<int> codecs = codecsFor(r.out);
  // H.264 and MPEG-4 code 4:2:0 chroma, whole 2x2 blocks: an odd side (KITTI's 1241 px) gets one
  // replicated column or row rather than a silent rescale by the encoder.
  const cv::Size size(width + width % 2, height + height % 2);
  io::writeViaPathAtomic(r.out, r.out.extension().string(), [&](const fs::path& tmp) {
    cv::VideoWriter writer;
    for (const int codec : codecs) {
      if (writer.open(tmp.string(), cv::CAP_FFMPEG, codec, r.fps, size)) break;
    }
    if (!writer.isOpened()) throw io::InputError(r.out, 0, "no video encoder for this container");
    Progress progress("render video", times.size(), "frames", r.progress);
    for (std::size_t k = 0; k < times.size(); ++k) {
      const cv::Mat image = frame(times[k]);
      if (image.cols != width || image.rows != height) {
        throw InvalidInput("render --video: a frame of the wrong size");
      }
      cv::Mat padded;
      cv::copyMakeBorder(image, padded, 0, size.height - height, 0, size.width - width,
                         cv::BORDER_REPLICATE);
      writer.write(padded);
      progress.update(k + 1);
    }
    progress.finish();
    writer.release();
    // VideoWriter reports no write errors (a full disk, a file size limit): read the container's
    // frame count back (its index, no decoding) before the file replaces anything.
    std::optional<cv::VideoCapture> check;
    {
      const io::QuietStderr quiet;  // FFmpeg logs "moov atom not found" for a cut-short file
      check.emplace(tmp.string(), cv::CAP_FFMPEG);
    }
    const auto written = static_cast<std::size_t>(
        std::llround(check->isOpened() ? check->get(cv::CAP_PROP_FRAME_COUNT) : -1.0));
    if (!check->isOpened() || written != times.size()) {
      throw io::InputError(r.out, 0,
                           fmt::format("the video was not written completely ({} of {} frames "
                                       "readable: disk full or a file size limit?)",
                                       check->isOpened() ? written : 0, times.size()));
    }
  });
}

double driveTimeS(const Trajectory& traj, std::int64_t t_ns) {
  return static_cast<double>(t_ns - traj.t_ns.front()) * 1e-9;
}

// The whole map and trajectory from a chase camera that follows the body. The map is uploaded
// once, in ground tiles, and each frame draws the tiles near and ahead of the camera.
int followVideo(const VideoRequest& r, const io::RunFiles& run) {
  const Trajectory& traj = io::mapTrajectory(run);
  const auto times = viz::videoFrameTimes(traj, r.fps, r.speed, r.span);
  render::Scene scene;
  std::vector<Eigen::Vector3d> centres;
  if (run.cloud && !run.cloud->p_enu.empty()) {
    const Eigen::AlignedBox3d q = viz::quantileBounds(run.cloud->p_enu);
    viz::CloudStyle style;
    style.z_lo = q.min().z();
    style.z_hi = q.max().z();
    style.shade_by_intensity = true;
    style.size_px = 2.0F;
    const auto dense = viz::densePointIndices(run.cloud.value());
    std::vector<Eigen::Vector3f> dense_p;
    dense_p.reserve(dense.size());
    for (const std::uint32_t i : dense) dense_p.push_back(run.cloud->p_enu[i]);
    for (auto& tile : viz::groundTiles(dense_p, kTileM, centres)) {
      for (std::uint32_t& i : tile) i = dense[i];
      scene.point_clouds.push_back(viz::colouredCloud(*run.cloud, style, &tile));
    }
  }
  render::Polyline path;
  for (const auto& T : traj.poses) path.points.push_back(T.translation());
  path.colors = {render::Color(0.2F, 0.2F, 0.2F, 1.0F)};
  scene.polylines.push_back(path);
  const render::EglContext context;
  const render::Renderer renderer(context);
  render::Framebuffer target(r.width, r.height);
  const render::GpuScene gpu(scene);
  render::DrawOptions draw;
  encode(r, times, r.width, r.height, [&](std::int64_t t_ns) {
    const Eigen::Isometry3d T_w_b = viz::poseAt(traj, t_ns);
    const render::RenderCamera camera = viz::chaseCamera(T_w_b, r.width, r.height);
    draw.point_clouds = viz::tilesInView(centres, camera, kDrawRadiusM, kTileM);
    cv::Mat bgr = viz::toBgr(renderer.renderColor(gpu, camera, target, draw));
    // The recent trail only: the line is drawn over the image, not depth-tested, and the drive's
    // far earlier parts would cross buildings in front of them.
    viz::drawDrive(bgr, camera, viz::pathUntil(traj, t_ns, kTrailS));
    viz::drawDriveTime(bgr, driveTimeS(traj, t_ns));
    return bgr;
  });
  return static_cast<int>(times.size());
}

// The top-down map revealed along the path driven so far.
int topDownVideo(const VideoRequest& r, const io::RunFiles& run) {
  const Trajectory& traj = io::mapTrajectory(run);
  const auto times = viz::videoFrameTimes(traj, r.fps, r.speed, r.span);
  const viz::ViewSpec spec = viz::buildTopDownMapOnly(run, r.width, r.height);
  const render::EglContext context;
  const render::Renderer renderer(context);
  render::Framebuffer target(r.width, r.height);
  const render::ImageRgba full =
      renderer.renderColor(render::GpuScene(spec.scene), spec.camera, target);
  encode(r, times, r.width, r.height, [&](std::int64_t t_ns) {
    const auto path = viz::pathUntil(traj, t_ns);
    render::ImageRgba image = viz::revealedAlongPath(full, spec.camera, path, kRevealM);
    render::annotate(image, spec.annotations);
    cv::Mat bgr = viz::toBgr(image);
    viz::drawDrive(bgr, spec.camera, path);
    viz::drawDriveTime(bgr, driveTimeS(traj, t_ns));
    return bgr;
  });
  return static_cast<int>(times.size());
}

// The map over the recorded camera, frame by frame.
int cameraVideo(const VideoRequest& r) {
  viz::CameraViewOptions options;
  options.colour = viz::parseMapColour(r.map_colour);
  const RecordedCameraOverlay overlay(r.run, r.dataset, options, viz::parseOverlayMode(r.overlay));
  const Trajectory& traj = io::mapTrajectory(overlay.run());
  const auto times = viz::videoFrameTimes(traj, r.fps, r.speed, r.span);
  encode(r, times, overlay.width(), overlay.height(), [&](std::int64_t t_ns) {
    cv::Mat bgr = overlay.at(t_ns);
    viz::drawDriveTime(bgr, driveTimeS(traj, t_ns));
    return bgr;
  });
  return static_cast<int>(times.size());
}

}  // namespace

int renderVideo(const VideoRequest& r) {
  const viz::VideoView view = viz::parseVideoView(r.view);
  (void)codecsFor(r.out);  // an unknown container before any rendering
  if (!fs::is_directory(fs::absolute(r.out).parent_path())) {
    throw io::InputError(r.out, 0, "output folder does not exist");
  }
  int frames = 0;
  if (view == viz::VideoView::kCamera) {
    frames = cameraVideo(r);
  } else {
    if (const auto warning = io::incompleteRunWarning(r.run)) spdlog::warn("{}", *warning);
    io::RunReadOptions read;
    read.occupancy = false;
    const io::RunFiles run = io::readRunDir(r.run, read);
    frames = view == viz::VideoView::kFollow ? followVideo(r, run) : topDownVideo(r, run);
  }
  spdlog::info("wrote {} ({} frames at {:g} fps, {:g}x the drive's speed, view {})", r.out.string(),
               frames, r.fps, r.speed, r.view);
  return 0;
}

}  // namespace gvio::cli
