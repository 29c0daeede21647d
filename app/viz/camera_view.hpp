#pragma once
// `gvio render --view camera`: the map seen from a recorded camera at one instant, drawn over
// that camera's rectified image, with the trajectory ahead of it. The exact pinhole of the
// rectified left camera (render::pinholeCamera) puts a map point where the image shows it when
// the pose and the map are right, so the overlay shows where they are not. Pure functions; the
// CLI reads the run, the dataset and the image.
#include <Eigen/Geometry>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "io/run_dir.hpp"
#include "odometry/measurements.hpp"
#include "render/camera.hpp"
#include "render/image.hpp"
#include "render/scene.hpp"

namespace gvio::viz {

// blend: the map half-transparent over the image; edges: the outline of the drawn map over the
// image, which keeps the image readable; none: the map alone (on black), to compare with the image.
enum class OverlayMode { kBlend, kEdges, kNone };
OverlayMode parseOverlayMode(const std::string& name);  // InvalidInput for anything else

// How map points are coloured: by their distance from the camera (jet), or by the grey level of
// the image they were seen in (map.pcd's intensity), which the recorded image should repeat.
enum class MapColour { kDepth, kIntensity };
MapColour parseMapColour(const std::string& name);  // InvalidInput for anything else

// The render intrinsics of a rectified (pinhole, undistorted) camera.
render::PinholeIntrinsics renderIntrinsics(const CameraModel& camera, double near_m, double far_m);

// The camera at `t_ns` on the map trajectory: T_map_c = T_map_b(t) T_b_c (pose interpolated);
// nullopt when t is outside the trajectory or inside a gap of it.
std::optional<Eigen::Isometry3d> cameraPoseAt(const io::RunFiles& run, std::int64_t t_ns,
                                              const Eigen::Isometry3d& T_b_c);

struct CameraViewOptions {
  double ahead_s = 20.0;      // how much of the trajectory ahead of the camera is drawn
  double max_depth_m = 80.0;  // map points farther than this are left out (colour range too)
  // Splat size: a point stands for a patch of this size (m), so near points close into a surface
  // and far ones stay fine (clamped to [1.5, 12] px).
  double splat_m = 0.08;
  MapColour colour = MapColour::kDepth;
};

// The map points in front of the camera (the nearest per pixel), coloured as options.colour says
// (distance: jet, near red to far blue) and sized by their distance, and the body's estimated path
// from t to t + ahead_s in magenta. The background is transparent: the render's alpha channel is
// the map's coverage.
render::Scene cameraScene(const io::RunFiles& run, const render::RenderCamera& camera,
                          std::int64_t t_ns, const CameraViewOptions& options);

// The trajectory's positions with stamps in [t0_ns, t1_ns].
std::vector<Eigen::Vector3d> positionsBetween(const Trajectory& traj, std::int64_t t0_ns,
                                              std::int64_t t1_ns);

// The map trajectory's positions from t_ns to t_ns + ahead_s.
std::vector<Eigen::Vector3d> pathAhead(const io::RunFiles& run, std::int64_t t_ns, double ahead_s);

// `path` projected into the camera, drawn onto a BGR image as a magenta line (broken where it
// passes behind the camera). The edges overlay has no GL line of its own: its median filter
// would erase it.
void drawPath(cv::Mat& bgr, const render::RenderCamera& camera,
              const std::vector<Eigen::Vector3d>& path);

// The recorded 8-bit grey image with the rendered map (RGBA, same size) over it; BGR out.
cv::Mat composeOverlay(const render::ImageRgba& rendered, const cv::Mat& recorded_grey,
                       OverlayMode mode);

}  // namespace gvio::viz
