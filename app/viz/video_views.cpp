#include "viz/video_views.hpp"

#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <map>
#include <utility>

#include <opencv2/imgproc.hpp>

#include "fusion/vio_enu_alignment.hpp"
#include "odometry/error.hpp"
#include "viz/camera_view.hpp"

namespace gvio::viz {
namespace {

constexpr double kChaseBackM = 14.0, kChaseUpM = 7.0, kChaseAheadM = 10.0, kChaseFovDeg = 60.0;
const cv::Scalar kBodyBgr(191, 25, 242);
const cv::Scalar kTextBgr(20, 20, 20);

}  // namespace

VideoView parseVideoView(const std::string& name) {
  if (name == "follow") return VideoView::kFollow;
  if (name == "topdown") return VideoView::kTopDown;
  if (name == "camera") return VideoView::kCamera;
  throw InvalidInput("unknown video view '" + name + "' (expected follow, topdown or camera)");
}

std::vector<std::int64_t> videoFrameTimes(const Trajectory& traj, double fps, double speed,
                                          const DriveSpan& span) {
  if (!(fps > 0.0) || !std::isfinite(fps)) throw InvalidInput("--fps must be > 0");
  if (!(speed > 0.0) || !std::isfinite(speed)) throw InvalidInput("--speed must be > 0");
  if (!traj.hasTimestamps() || traj.empty()) {
    throw InvalidInput("the trajectory has no timestamps to make a video along");
  }
  const double length_s = static_cast<double>(traj.t_ns.back() - traj.t_ns.front()) * 1e-9;
  if (!(span.from_s >= 0.0) || !(span.to_s > span.from_s) || span.from_s > length_s) {
    throw InvalidInput(fmt::format("--from {:g} --to {:g}: not a span of the {:.1f} s drive",
                                   span.from_s, span.to_s, length_s));
  }
  const double step_s = speed / fps;
  const std::int64_t t0 = traj.t_ns.front() + static_cast<std::int64_t>(span.from_s * 1e9);
  const std::int64_t t1 = span.to_s >= length_s
                              ? traj.t_ns.back()
                              : traj.t_ns.front() + static_cast<std::int64_t>(span.to_s * 1e9);
  std::vector<std::int64_t> times;
  for (std::int64_t k = 0;; ++k) {
    const auto t =
        t0 + static_cast<std::int64_t>(std::llround(static_cast<double>(k) * step_s * 1e9));
    if (t > t1) break;
    times.push_back(t);
  }
  return times;
}

render::RenderCamera chaseCamera(const Eigen::Isometry3d& T_w_b, int width, int height) {
  Eigen::Vector3d heading = T_w_b.rotation().col(0);
  heading.z() = 0.0;
  heading = heading.norm() > 1e-6 ? heading.normalized() : Eigen::Vector3d::UnitX();
  const Eigen::Vector3d p = T_w_b.translation();
  const Eigen::Vector3d eye = p - kChaseBackM * heading + Eigen::Vector3d(0, 0, kChaseUpM);
  return render::lookAtCamera(eye, p + kChaseAheadM * heading, width, height, kChaseFovDeg, 0.5,
                              2000.0);
}

std::vector<std::vector<std::uint32_t>> groundTiles(const std::vector<Eigen::Vector3f>& p,
                                                    double tile_m,
                                                    std::vector<Eigen::Vector3d>& centres) {
  std::map<std::pair<std::int64_t, std::int64_t>, std::vector<std::uint32_t>> tiles;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (!p[i].allFinite()) continue;
    const auto key = std::make_pair(
        static_cast<std::int64_t>(std::floor(static_cast<double>(p[i].y()) / tile_m)),
        static_cast<std::int64_t>(std::floor(static_cast<double>(p[i].x()) / tile_m)));
    tiles[key].push_back(static_cast<std::uint32_t>(i));
  }
  std::vector<std::vector<std::uint32_t>> out;
  centres.clear();
  for (auto& [key, indices] : tiles) {
    double z = 0.0;
    for (const std::uint32_t i : indices) z += static_cast<double>(p[i].z());
    centres.emplace_back((static_cast<double>(key.second) + 0.5) * tile_m,
                         (static_cast<double>(key.first) + 0.5) * tile_m,
                         z / static_cast<double>(indices.size()));
    out.push_back(std::move(indices));
  }
  return out;
}

std::vector<bool> tilesInView(const std::vector<Eigen::Vector3d>& centres,
                              const render::RenderCamera& camera, double radius_m, double tile_m) {
  const Eigen::Isometry3d T_w_c(camera.view.inverse());
  const Eigen::Vector3d eye = T_w_c.translation();
  const Eigen::Vector3d forward = T_w_c.rotation().col(2);
  const double slack = tile_m * M_SQRT1_2;
  std::vector<bool> in(centres.size());
  for (std::size_t k = 0; k < centres.size(); ++k) {
    const Eigen::Vector3d d = centres[k] - eye;
    in[k] = d.norm() <= radius_m + slack && d.dot(forward) >= -slack;
  }
  return in;
}

std::vector<Eigen::Vector3d> pathUntil(const Trajectory& traj, std::int64_t t_ns, double window_s) {
  const std::int64_t t0_ns = std::isfinite(window_s)
                                 ? t_ns - static_cast<std::int64_t>(window_s * 1e9)
                                 : std::numeric_limits<std::int64_t>::min();
  return positionsBetween(traj, t0_ns, t_ns);
}

render::ImageRgba revealedAlongPath(const render::ImageRgba& full,
                                    const render::RenderCamera& camera,
                                    const std::vector<Eigen::Vector3d>& path, double reveal_m) {
  cv::Mat mask = cv::Mat::zeros(full.height, full.width, CV_8UC1);
  const int radius_px = std::max(
      1, static_cast<int>(std::lround(reveal_m / std::max(camera.metres_per_pixel, 1e-9))));
  for (const Eigen::Vector3d& p : path) {
    const Eigen::Vector2d px = render::projectToPixel(camera, p);
    if (!px.allFinite() || px.cwiseAbs().maxCoeff() > 1e6) continue;
    cv::circle(mask, {static_cast<int>(std::lround(px.x())), static_cast<int>(std::lround(px.y()))},
               radius_px, cv::Scalar(255), cv::FILLED);
  }
  render::ImageRgba out = full;
  for (int y = 0; y < full.height; ++y) {
    for (int x = 0; x < full.width; ++x) {
      if (mask.at<std::uint8_t>(y, x) != 0) continue;
      std::uint8_t* px = out.rgba.data() + (static_cast<std::size_t>(y) * full.width + x) * 4;
      px[0] = px[1] = px[2] = px[3] = 255;
    }
  }
  return out;
}

Eigen::Isometry3d poseAt(const Trajectory& traj, std::int64_t t_ns) {
  if (const auto T = fusion::interpolatePose(traj, t_ns)) return *T;
  std::size_t i = 0;
  while (i + 1 < traj.size() && i + 1 < traj.t_ns.size() && traj.t_ns[i + 1] <= t_ns) ++i;
  return traj.poses.at(i);
}

void drawDrive(cv::Mat& bgr, const render::RenderCamera& camera,
               const std::vector<Eigen::Vector3d>& path) {
  drawPath(bgr, camera, path);
  if (!path.empty()) {
    double z = 0.0;
    const Eigen::Vector2d px = render::projectToPixel(camera, path.back(), &z);
    if ((z > camera.near_m || !camera.perspective) && px.allFinite() &&
        px.cwiseAbs().maxCoeff() < 1e6) {
      const cv::Point c(static_cast<int>(std::lround(px.x())),
                        static_cast<int>(std::lround(px.y())));
      cv::circle(bgr, c, 8, cv::Scalar(255, 255, 255), cv::FILLED, cv::LINE_AA);
      cv::circle(bgr, c, 6, kBodyBgr, cv::FILLED, cv::LINE_AA);
    }
  }
}

void drawDriveTime(cv::Mat& bgr, double drive_time_s) {
  const double scale = std::max(0.5, bgr.rows / 720.0);
  cv::putText(bgr, fmt::format("t = {:.1f} s", drive_time_s), {12, static_cast<int>(30 * scale)},
              cv::FONT_HERSHEY_SIMPLEX, 0.8 * scale, cv::Scalar(255, 255, 255),
              static_cast<int>(4 * scale), cv::LINE_AA);
  cv::putText(bgr, fmt::format("t = {:.1f} s", drive_time_s), {12, static_cast<int>(30 * scale)},
              cv::FONT_HERSHEY_SIMPLEX, 0.8 * scale, kTextBgr, static_cast<int>(2 * scale),
              cv::LINE_AA);
}

}  // namespace gvio::viz
