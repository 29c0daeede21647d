#pragma once
// Plain measurement structs shared by every stage (OpenVINS style: data only, no behaviour).
// Frames and units are in the names: *_mps2 = m/s^2, *_radps = rad/s, t_ns = int64 nanoseconds.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace gvio {

// Gravity magnitude used by the simulator and the estimators alike (local ENU: g_w = (0, 0, -g)).
inline constexpr double kGravity_mps2 = 9.81;

// Specific force and angular rate in the body (IMU) frame.
struct ImuSample {
  std::int64_t t_ns = 0;
  Eigen::Vector3d acc_b_mps2 = Eigen::Vector3d::Zero();
  Eigen::Vector3d gyr_b_radps = Eigen::Vector3d::Zero();
};

// One GNSS position fix at the antenna. Heights are ellipsoidal (WGS84); readers that get MSL
// heights (NMEA GGA) add the geoid separation the receiver reports.
struct GnssFix {
  std::int64_t t_ns = 0;
  double lat_deg = 0.0;
  double lon_deg = 0.0;
  double h_ellipsoid_m = 0.0;
  double sigma_h_m = 0.0;  // 1-sigma horizontal (per axis: sqrt of half the covariance's trace)
  double sigma_v_m = 0.0;  // 1-sigma vertical
  // The shape of the stated horizontal error ellipse (east, north): cov_en = sigma_h_m^2 shape_en,
  // trace 2 (fusion/gnss_covariance.hpp); the identity where the source states no correlation.
  Eigen::Matrix2d shape_en = Eigen::Matrix2d::Identity();
  int quality = 1;    // NMEA GGA fix quality (1 SPP, 2 DGPS, 4 RTK fixed, 5 RTK float)
  double hdop = 0.0;  // 0 when the source does not report it
  int num_sats = 0;   // 0 when the source does not report it
  // Velocity over ground as the receiver reports it (speed and course, the course clockwise from
  // true north); NaN when the source does not report it.
  double speed_mps = std::numeric_limits<double>::quiet_NaN();
  double course_deg = std::numeric_limits<double>::quiet_NaN();
};

// How a raw camera's lens bends rays away from the pinhole projection (x = X/Z, y = Y/Z, r = |x
// y|).
enum class Distortion {
  // Radial-tangential (OpenCV plumb_bob, Kalibr radtan): coefficients k1 k2 p1 p2 [k3], or with
  // k4 k5 k6 the rational model (ROS rational_polynomial, OpenCV's 8 coefficients). No
  // coefficients, or all of them 0, is the undistorted pinhole camera.
  kRadtan,
  // Equidistant fisheye (Kannala & Brandt 2006, OpenCV cv::fisheye, Kalibr equidistant): the
  // image radius grows with the ray's angle theta = atan(r), not with r: r_d = theta (1 + k1
  // theta^2 + k2 theta^4 + k3 theta^6 + k4 theta^8). Exactly 4 coefficients; all 0 is still a
  // fisheye (r_d = theta), not a pinhole.
  kEquidistant,
};

// "radtan" or "equidistant", as Kalibr names them.
inline std::string toString(Distortion d) {
  return d == Distortion::kEquidistant ? "equidistant" : "radtan";
}

// Pinhole camera with lens distortion (see Distortion) and its pose in the body.
struct CameraModel {
  std::string name;
  int width_px = 0;
  int height_px = 0;
  double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0;
  // How `distortion` is read. Rectified cameras are radtan with no coefficients (a pinhole).
  Distortion distortion_model = Distortion::kRadtan;
  std::vector<double> distortion;  // radtan: k1 k2 p1 p2 [k3 [k4 k5 k6]]; equidistant: k1..k4
  Eigen::Isometry3d T_b_c = Eigen::Isometry3d::Identity();
};

// False for a pinhole camera (radtan with no coefficient other than 0). An equidistant camera
// always distorts: with k1..k4 = 0 it still images the ray's angle, not its tangent.
inline bool hasLensDistortion(const CameraModel& cam) {
  if (cam.distortion_model == Distortion::kEquidistant) return true;
  for (const double d : cam.distortion) {
    if (d != 0.0) return true;
  }
  return false;
}

// Noise densities of an IMU (continuous time), as Kalibr/EuRoC sensor.yaml state them.
// Defaults: a typical automotive MEMS IMU (accelerometer ~200 ug/sqrt(Hz), gyro ~0.01
// deg/s/sqrt(Hz)).
struct ImuNoise {
  double acc_noise_density = 2.0e-3;  // m/s^2/sqrt(Hz)
  double gyr_noise_density = 1.7e-4;  // rad/s/sqrt(Hz)
  double acc_random_walk = 3.0e-4;    // m/s^3/sqrt(Hz)
  double gyr_random_walk = 2.0e-5;    // rad/s^2/sqrt(Hz)

  void validate() const;  // throws InvalidInput: every density must be finite and > 0
};

}  // namespace gvio
