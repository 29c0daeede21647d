#pragma once
// Render cameras. Every camera maps world points to the OpenCV camera frame (x right, y down,
// z forward) with `view`, then to clip space with `projection`, so one convention serves the
// exact pinhole camera (the simulator's), the orbit view and the orthographic top-down view.
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace gvio::render {

struct PinholeIntrinsics {
  double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0;  // OpenCV convention: pixel centres at integers
  int width = 0, height = 0;
  double near_m = 0.1, far_m = 1000.0;
};

struct RenderCamera {
  int width = 0, height = 0;
  Eigen::Matrix4d view = Eigen::Matrix4d::Identity();        // world -> OpenCV camera frame
  Eigen::Matrix4d projection = Eigen::Matrix4d::Identity();  // camera frame -> clip
  bool perspective = true;
  double near_m = 0.1, far_m = 1000.0;
  double metres_per_pixel = 0.0;  // orthographic cameras only
};

// Exact pinhole camera at pose T_w_c: a world point p projects where OpenCV's projectPoints puts
// it (u = fx x/z + cx, v = fy y/z + cy, no distortion). Throws RenderError on invalid intrinsics.
RenderCamera pinholeCamera(const PinholeIntrinsics& K, const Eigen::Isometry3d& T_w_c);

// Orthographic view straight down the world -z axis (ENU: north up, east right), fitted to the
// x-y extent of `bounds` with a relative margin, equal metres per pixel on both axes.
RenderCamera topDownCamera(const Eigen::AlignedBox3d& bounds, int width, int height,
                           double margin = 0.05);

// Perspective camera at `eye` looking at `target`, image x to the right and y down with world up
// +z (a view straight up or down takes +x as its image x), square pixels, principal point at the
// image centre. Throws RenderError for eye == target or invalid sizes.
RenderCamera lookAtCamera(const Eigen::Vector3d& eye, const Eigen::Vector3d& target, int width,
                          int height, double fov_y_deg, double near_m, double far_m);
// Perspective view orbiting the centre of `bounds` (azimuth from +x towards +y, elevation above
// the x-y plane), far enough that the bounding sphere fits the vertical field of view.
RenderCamera orbitCamera(const Eigen::AlignedBox3d& bounds, int width, int height,
                         double azimuth_deg = -60.0, double elevation_deg = 35.0,
                         double fov_y_deg = 45.0);

// Pixel coordinates (OpenCV convention) of a world point; z of the camera frame in `depth_m`.
Eigen::Vector2d projectToPixel(const RenderCamera& camera, const Eigen::Vector3d& p_w,
                               double* depth_m = nullptr);

// Window depth in [0, 1] -> z in the camera frame (metres); 0 for the far plane (nothing drawn).
double windowDepthToMetric(const RenderCamera& camera, double window_depth);

}  // namespace gvio::render
