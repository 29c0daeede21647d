#include "odometry/time_offset_factor.hpp"

namespace gvio::odometry {
namespace {

// u_a(t_d) and d u_a / d t_d for the anchor pixel.
Eigen::Vector3d bearingAt(const MovingPixel& a, const PinholeView& cam, double t_d) {
  const Eigen::Vector2d px = a.px + t_d * a.velocity_pxps;
  return {(px.x() - cam.cx) / cam.fx, (px.y() - cam.cy) / cam.fy, 1.0};
}

Eigen::Vector3d bearingRate(const MovingPixel& a, const PinholeView& cam) {
  return {a.velocity_pxps.x() / cam.fx, a.velocity_pxps.y() / cam.fy, 0.0};
}

}  // namespace

ReprojectionTimeOffsetFactor::ReprojectionTimeOffsetFactor(const MovingPixel& anchor,
                                                           const PinholeView& anchor_camera,
                                                           const PinholeView& observer,
                                                           const MovingPixel& observed,
                                                           double sigma_px)
    : anchor_(anchor),
      observed_(observed),
      anchor_camera_(anchor_camera),
      observer_(observer),
      inv_sigma_(1.0 / sigma_px) {}

bool ReprojectionTimeOffsetFactor::Evaluate(double const* const* parameters, double* residuals,
                                            double** jacobians) const {
  const double rho = parameters[2][0];
  const double t_d = parameters[3][0];
  const Eigen::Vector3d u_a = bearingAt(anchor_, anchor_camera_, t_d);
  const Eigen::Vector2d z = observed_.px + t_d * observed_.velocity_pxps;
  const bool want = jacobians != nullptr;
  Eigen::Matrix<double, 2, 3> J_ca;
  if (!anchoredResidual(u_a, anchor_camera_.T_b_c, observer_, z, inv_sigma_, parameters[0],
                        parameters[1], rho, residuals, want ? jacobians[0] : nullptr,
                        want ? jacobians[1] : nullptr, want ? &J_ca : nullptr)) {
    return false;
  }
  if (!want) return true;
  if (jacobians[2] != nullptr) {
    Eigen::Map<Eigen::Vector2d>{jacobians[2]} = J_ca * (-u_a / (rho * rho));
  }
  if (jacobians[3] != nullptr) {
    // r = proj(P_co(u_a(t_d) / rho)) - z(t_d): both the anchor and the observation move.
    Eigen::Map<Eigen::Vector2d>{jacobians[3]} =
        J_ca * (bearingRate(anchor_, anchor_camera_) / rho) - inv_sigma_ * observed_.velocity_pxps;
  }
  return true;
}

SameFrameTimeOffsetFactor::SameFrameTimeOffsetFactor(const MovingPixel& anchor,
                                                     const PinholeView& anchor_camera,
                                                     const PinholeView& observer,
                                                     const MovingPixel& observed, double sigma_px)
    : anchor_(anchor),
      observed_(observed),
      anchor_camera_(anchor_camera),
      observer_(observer),
      T_co_ca_(observer.T_b_c.inverse() * anchor_camera.T_b_c),
      inv_sigma_(1.0 / sigma_px) {}

bool SameFrameTimeOffsetFactor::Evaluate(double const* const* parameters, double* residuals,
                                         double** jacobians) const {
  const double rho = parameters[0][0];
  const double t_d = parameters[1][0];
  if (!(rho > 0.0)) return false;
  const Eigen::Vector3d u_a = bearingAt(anchor_, anchor_camera_, t_d);
  const Eigen::Vector2d z = observed_.px + t_d * observed_.velocity_pxps;
  Eigen::Vector2d r_value;
  Eigen::Matrix<double, 2, 3> J_proj;
  if (!projectResidual(observer_, T_co_ca_ * (u_a / rho), z, inv_sigma_, r_value, &J_proj)) {
    return false;
  }
  Eigen::Map<Eigen::Vector2d>{residuals} = r_value;
  if (jacobians == nullptr) return true;
  const Eigen::Matrix<double, 2, 3> J_ca = J_proj * T_co_ca_.rotation();
  if (jacobians[0] != nullptr) {
    Eigen::Map<Eigen::Vector2d>{jacobians[0]} = J_ca * (-u_a / (rho * rho));
  }
  if (jacobians[1] != nullptr) {
    Eigen::Map<Eigen::Vector2d>{jacobians[1]} =
        J_ca * (bearingRate(anchor_, anchor_camera_) / rho) - inv_sigma_ * observed_.velocity_pxps;
  }
  return true;
}

}  // namespace gvio::odometry
