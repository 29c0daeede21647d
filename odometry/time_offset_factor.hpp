#pragma once
// Reprojection residuals with the camera-IMU time offset t_d as a state (Qin and Shen, "Online
// temporal calibration for monocular visual-inertial systems", IROS 2018, sec. IV): a feature
// keeps moving on the image plane at its tracked velocity V between the exposure and the frame's
// stamp, so the observation the pose at the stamp sees is z(t_d) = z + t_d V, t_d being how much
// the stamps lag the exposures (s). The anchor's bearing is shifted the same way,
// u_a(t_d) = u_a + t_d (V_a,x / f_x, V_a,y / f_y, 0). Frames keep their stamps (no re-timing of
// the IMU preintegration): the first-order shift holds while t_d V stays a few pixels, i.e. for
// offsets of tens of milliseconds.
#include <ceres/sized_cost_function.h>

#include "odometry/reprojection_factor.hpp"

namespace gvio::odometry {

// An anchored feature's pixel position and image-plane velocity (px, px/s).
struct MovingPixel {
  Eigen::Vector2d px = Eigen::Vector2d::Zero();
  Eigen::Vector2d velocity_pxps = Eigen::Vector2d::Zero();
};

// Observation in another frame j. Blocks: pose_i (7), pose_j (7), rho (1), t_d (1).
class ReprojectionTimeOffsetFactor final : public ceres::SizedCostFunction<2, 7, 7, 1, 1> {
 public:
  // `anchor_camera`: the rectified left camera the anchor pixel is in (its intrinsics turn pixels
  // into bearings; its T_b_c is the anchor's).
  ReprojectionTimeOffsetFactor(const MovingPixel& anchor, const PinholeView& anchor_camera,
                               const PinholeView& observer, const MovingPixel& observed,
                               double sigma_px);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  MovingPixel anchor_, observed_;
  PinholeView anchor_camera_, observer_;
  double inv_sigma_;
};

// Observation by another camera of the anchor's own frame (the right image). Blocks: rho, t_d.
class SameFrameTimeOffsetFactor final : public ceres::SizedCostFunction<2, 1, 1> {
 public:
  SameFrameTimeOffsetFactor(const MovingPixel& anchor, const PinholeView& anchor_camera,
                            const PinholeView& observer, const MovingPixel& observed,
                            double sigma_px);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  MovingPixel anchor_, observed_;
  PinholeView anchor_camera_, observer_;
  Eigen::Isometry3d T_co_ca_;
  double inv_sigma_;
};

}  // namespace gvio::odometry
