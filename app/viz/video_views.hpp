#pragma once
// `gvio render --video`: the frames of a video along the drive. Pure functions of the run's data
// and the cameras; the CLI renders, encodes and writes.
//  - follow:  a chase camera behind and above the body, the whole map and trajectory, the body
//             as a disc;
//  - topdown: the top-down map revealed where the drive has been so far (within reveal_m of the
//             path driven), the path growing, the body as a disc;
//  - camera:  the map over the recorded camera image (viz/camera_view.hpp), frame by frame.
#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "odometry/trajectory.hpp"
#include "render/camera.hpp"
#include "render/image.hpp"

namespace gvio::viz {

enum class VideoView { kFollow, kTopDown, kCamera };
VideoView parseVideoView(const std::string& name);  // InvalidInput for anything else

// The part of the drive a video shows, in seconds from the trajectory's first stamp.
struct DriveSpan {
  double from_s = 0.0;
  double to_s = INFINITY;  // the end of the trajectory
};

// The instants of the video's frames: from the span's start to its end (clamped to the
// trajectory), one every speed / fps seconds of the drive (the video then plays `speed` times
// faster than the drive). InvalidInput for fps or speed not > 0, a trajectory without stamps, or
// a span that is empty or outside the trajectory.
std::vector<std::int64_t> videoFrameTimes(const Trajectory& traj, double fps, double speed,
                                          const DriveSpan& span = {});

// A chase camera: 14 m behind the body along its heading (the body x axis on the ground plane),
// 7 m above it, looking at a point 10 m ahead; 60 degrees vertical field of view.
render::RenderCamera chaseCamera(const Eigen::Isometry3d& T_w_b, int width, int height);

// The points in square tiles of side tile_m on the ground plane (x-y), as index lists in a fixed
// order (by tile row, then column); `centres` gets each tile's centre (mean height of its points).
std::vector<std::vector<std::uint32_t>> groundTiles(const std::vector<Eigen::Vector3f>& p,
                                                    double tile_m,
                                                    std::vector<Eigen::Vector3d>& centres);
// Which tiles a perspective camera can show: centre within radius_m of the camera and not behind
// it (a tile's half diagonal of slack).
std::vector<bool> tilesInView(const std::vector<Eigen::Vector3d>& centres,
                              const render::RenderCamera& camera, double radius_m, double tile_m);

// The positions of the trajectory up to and including t_ns (from t_ns - window_s when given).
std::vector<Eigen::Vector3d> pathUntil(const Trajectory& traj, std::int64_t t_ns,
                                       double window_s = INFINITY);

// The top-down map (`full`, RGBA, rendered once for the whole drive) where the path so far has
// passed within reveal_m, white elsewhere; RGBA, so annotations can still be drawn on it.
render::ImageRgba revealedAlongPath(const render::ImageRgba& full,
                                    const render::RenderCamera& camera,
                                    const std::vector<Eigen::Vector3d>& path, double reveal_m);

// The path (BGR magenta line, broken behind the camera) and the body as a disc at its end.
void drawDrive(cv::Mat& bgr, const render::RenderCamera& camera,
               const std::vector<Eigen::Vector3d>& path);
// "t = 12.3 s" in the top-left corner.
void drawDriveTime(cv::Mat& bgr, double drive_time_s);

// The trajectory's pose at t_ns: interpolated, else (in a gap) the last pose before it.
Eigen::Isometry3d poseAt(const Trajectory& traj, std::int64_t t_ns);

}  // namespace gvio::viz
