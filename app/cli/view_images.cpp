#include "cli/view_images.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "cli/render_camera.hpp"
#include "io/run_map.hpp"
#include "odometry/error.hpp"

namespace gvio::cli {
namespace {

// Keyframes along the map trajectory every `spacing_m` of path (the first pose included).
std::vector<view::KeyframeCamera> evenKeyframes(const Trajectory& traj, const CameraModel& camera,
                                                std::size_t count) {
  const double spacing_m = std::max(1.0, pathLengthM(traj) / static_cast<double>(count));
  std::vector<view::KeyframeCamera> out;
  double since = spacing_m;
  for (std::size_t k = 0; k < traj.size(); ++k) {
    if (k > 0) since += (traj.poses[k].translation() - traj.poses[k - 1].translation()).norm();
    if (since < spacing_m) continue;
    out.push_back({traj.t_ns[k], traj.poses[k] * camera.T_b_c});
    since = 0.0;
  }
  return out;
}

std::string jpegOf(const cv::Mat& bgr, int max_width_px) {
  cv::Mat image = bgr;
  if (bgr.cols > max_width_px) {
    const double s = static_cast<double>(max_width_px) / bgr.cols;
    cv::resize(bgr, image, cv::Size(), s, s, cv::INTER_AREA);
  }
  std::vector<unsigned char> bytes;
  cv::imencode(".jpg", image, bytes, {cv::IMWRITE_JPEG_QUALITY, 85});
  return {bytes.begin(), bytes.end()};
}

}  // namespace

std::optional<std::string> addKeyframeImages(io::RunFiles run, view::ViewInput& in,
                                             const ViewImagesRequest& r) {
  if (r.max_images == 0) return "--images 0";
  std::unique_ptr<RecordedCameraOverlay> overlay;
  try {
    overlay = std::make_unique<RecordedCameraOverlay>(
        std::move(run), r.dataset, viz::CameraViewOptions{}, viz::OverlayMode::kBlend);
  } catch (const std::exception& e) {
    return std::string(e.what());
  }
  nlohmann::json& kf = in.scene["keyframes"];
  if (kf.is_null()) {
    kf = view::keyframesJson(overlay->camera(), evenKeyframes(io::mapTrajectory(overlay->run()),
                                                              overlay->camera(), r.max_images));
  }
  const std::size_t n = kf["t"].size();
  const std::size_t step = std::max<std::size_t>(1, (n + r.max_images - 1) / r.max_images);
  in.keyframe_jpeg.assign(n, {});
  std::size_t missing = 0;
  for (std::size_t k = 0; k < n; k += step) {
    const auto t_ns = static_cast<std::int64_t>(std::llround(kf["t"][k].get<double>() * 1e9));
    try {
      in.keyframe_jpeg[k] = jpegOf(overlay->at(t_ns), r.max_width_px);
    } catch (const InvalidInput&) {
      ++missing;  // no image or no pose near the keyframe
    }
  }
  if (missing > 0)
    spdlog::warn("view: {} keyframes have no image within 0.2 s or no pose", missing);
  return std::nullopt;
}

}  // namespace gvio::cli
