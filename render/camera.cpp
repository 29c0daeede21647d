#include "render/camera.hpp"

#include <fmt/format.h>

#include <cmath>

#include "render/render_error.hpp"

namespace gvio::render {
namespace {

// Perspective projection acting on OpenCV camera coordinates. With pixel centres at integer
// OpenCV coordinates and at half-integer window coordinates, NDC x = 2 (u + 0.5) / W - 1 and,
// since image rows run downwards, NDC y = 1 - 2 (v + 0.5) / H. Depth maps z in [n, f] to [-1, 1].
Eigen::Matrix4d pinholeProjection(const PinholeIntrinsics& K) {
  const double W = K.width, H = K.height, n = K.near_m, f = K.far_m;
  Eigen::Matrix4d P = Eigen::Matrix4d::Zero();
  P(0, 0) = 2.0 * K.fx / W;
  P(0, 2) = 2.0 * (K.cx + 0.5) / W - 1.0;
  P(1, 1) = -2.0 * K.fy / H;
  P(1, 2) = 1.0 - 2.0 * (K.cy + 0.5) / H;
  P(2, 2) = (f + n) / (f - n);
  P(2, 3) = -2.0 * f * n / (f - n);
  P(3, 2) = 1.0;
  return P;
}

void validate(const PinholeIntrinsics& K) {
  if (!(K.fx > 0.0 && K.fy > 0.0) || K.width < 1 || K.height < 1 || !(K.near_m > 0.0) ||
      !(K.far_m > K.near_m) || !std::isfinite(K.cx) || !std::isfinite(K.cy)) {
    throw RenderError(
        fmt::format("invalid pinhole camera fx {} fy {} cx {} cy {} size {}x{} near {} far {}",
                    K.fx, K.fy, K.cx, K.cy, K.width, K.height, K.near_m, K.far_m));
  }
}

Eigen::AlignedBox3d nonEmpty(const Eigen::AlignedBox3d& bounds) {
  if (bounds.isEmpty()) throw RenderError("nothing to draw: the scene is empty");
  Eigen::AlignedBox3d b = bounds;
  // Degenerate extents (one point, a straight line) still get a 1 m view.
  const Eigen::Vector3d pad = (Eigen::Vector3d::Constant(1.0) - b.sizes()).cwiseMax(0.0) * 0.5;
  b.min() -= pad;
  b.max() += pad;
  return b;
}

}  // namespace

RenderCamera pinholeCamera(const PinholeIntrinsics& K, const Eigen::Isometry3d& T_w_c) {
  validate(K);
  RenderCamera cam;
  cam.width = K.width;
  cam.height = K.height;
  cam.view = T_w_c.inverse().matrix();
  cam.projection = pinholeProjection(K);
  cam.near_m = K.near_m;
  cam.far_m = K.far_m;
  return cam;
}

RenderCamera topDownCamera(const Eigen::AlignedBox3d& bounds, int width, int height,
                           double margin) {
  const Eigen::AlignedBox3d b = nonEmpty(bounds);
  RenderCamera cam;
  cam.width = width;
  cam.height = height;
  cam.perspective = false;
  // Camera above the scene looking down: x_c = east, y_c = -north (image down = south), z_c = -up.
  const Eigen::Vector3d c = b.center();
  cam.near_m = 1.0;
  cam.far_m = b.sizes().z() + 2.0;
  Eigen::Matrix4d R = Eigen::Matrix4d::Identity();
  R.topLeftCorner<3, 3>() << 1, 0, 0, 0, -1, 0, 0, 0, -1;
  Eigen::Matrix4d Tr = Eigen::Matrix4d::Identity();
  Tr.topRightCorner<3, 1>() = -Eigen::Vector3d(c.x(), c.y(), b.max().z() + 1.0);
  cam.view = R * Tr;
  const double mpp = std::max(b.sizes().x() / width, b.sizes().y() / height) * (1.0 + 2.0 * margin);
  cam.metres_per_pixel = mpp;
  const double half_w = 0.5 * mpp * width, half_h = 0.5 * mpp * height;
  Eigen::Matrix4d P = Eigen::Matrix4d::Identity();
  P(0, 0) = 1.0 / half_w;
  P(1, 1) = -1.0 / half_h;  // image rows run downwards (camera y down -> NDC y up)
  P(2, 2) = 2.0 / (cam.far_m - cam.near_m);
  P(2, 3) = -(cam.far_m + cam.near_m) / (cam.far_m - cam.near_m);
  cam.projection = P;
  return cam;
}

RenderCamera lookAtCamera(const Eigen::Vector3d& eye, const Eigen::Vector3d& target, int width,
                          int height, double fov_y_deg, double near_m, double far_m) {
  if (!((target - eye).norm() > 0.0)) throw RenderError("lookAtCamera: eye and target coincide");
  // Camera axes: z towards the target, x to the right, y down (world up is +z).
  const Eigen::Vector3d z = (target - eye).normalized();
  Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ());
  if (x.norm() < 1e-9) x = Eigen::Vector3d::UnitX();
  x.normalize();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Isometry3d T_w_c = Eigen::Isometry3d::Identity();
  T_w_c.linear() << x, y, z;
  T_w_c.translation() = eye;
  PinholeIntrinsics K;
  K.width = width;
  K.height = height;
  K.fy = 0.5 * height / std::tan(0.5 * fov_y_deg * M_PI / 180.0);
  K.fx = K.fy;
  K.cx = 0.5 * width - 0.5;
  K.cy = 0.5 * height - 0.5;
  K.near_m = near_m;
  K.far_m = far_m;
  return pinholeCamera(K, T_w_c);
}

RenderCamera orbitCamera(const Eigen::AlignedBox3d& bounds, int width, int height,
                         double azimuth_deg, double elevation_deg, double fov_y_deg) {
  const Eigen::AlignedBox3d b = nonEmpty(bounds);
  const double radius = 0.5 * b.sizes().norm();
  const double fov = fov_y_deg * M_PI / 180.0, az = azimuth_deg * M_PI / 180.0,
               el = elevation_deg * M_PI / 180.0;
  const double distance = radius / std::sin(0.5 * std::min(fov, fov * width / height));
  const Eigen::Vector3d target = b.center();
  const Eigen::Vector3d eye =
      target + distance * Eigen::Vector3d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az),
                                          std::sin(el));
  return lookAtCamera(eye, target, width, height, fov_y_deg,
                      std::max(0.01, distance - 2.0 * radius), distance + 2.0 * radius);
}

Eigen::Vector2d projectToPixel(const RenderCamera& camera, const Eigen::Vector3d& p_w,
                               double* depth_m) {
  const Eigen::Vector4d p_c = camera.view * p_w.homogeneous();
  const Eigen::Vector4d clip = camera.projection * p_c;
  if (depth_m != nullptr) *depth_m = p_c.z();
  const double ndc_x = clip.x() / clip.w(), ndc_y = clip.y() / clip.w();
  return {0.5 * (ndc_x + 1.0) * camera.width - 0.5, 0.5 * (1.0 - ndc_y) * camera.height - 0.5};
}

double windowDepthToMetric(const RenderCamera& camera, double d) {
  if (d >= 1.0) return 0.0;
  const double n = camera.near_m, f = camera.far_m, ndc = 2.0 * d - 1.0;
  if (!camera.perspective) return n + 0.5 * (ndc + 1.0) * (f - n);
  return 2.0 * f * n / ((f + n) - ndc * (f - n));
}

}  // namespace gvio::render
