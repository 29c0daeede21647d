#pragma once
// The calibration a ROS 2 bag carries, as a ROS 2 user expects it to be used:
//  - intrinsics and distortion from each image topic's CameraInfo (image_transport's convention:
//    <namespace>/camera_info beside <namespace>/image_raw): plumb_bob (k1 k2 p1 p2 k3),
//    rational_polynomial (k1 k2 p1 p2 k3 k4 k5 k6), equidistant (k1 k2 k3 k4); for an image_rect
//    topic the rectified projection P with no distortion, in the frame R turns the raw one into;
//  - camera-IMU and camera-camera extrinsics from the tf tree (/tf_static, and /tf links that
//    never change), between the IMU message's frame_id and each camera's (REP 103: the optical
//    frame, z forward, x right); without a camera-camera link, the second camera from the two
//    CameraInfos' R and P (P's fourth column: -fx' times the baseline, REP 104 / CameraInfo.msg);
//  - the GNSS antenna's lever arm from the link to the NavSatFix message's frame_id.
// Every value's source is recorded in Dataset::calibration_sources. Kalibr files (--calib) still
// replace the cameras (io/kalibr.hpp).
#include "io/dataset.hpp"
#include "io/ros2/ros2_bag.hpp"

namespace gvio::io::ros2 {

// Sets ds.cameras' intrinsics and T_b_c when the bag calibrates every camera (else leaves them
// uncalibrated and says why in ds.calibration_missing: no CameraInfo, no tf path, a CameraInfo
// that contradicts its images (size, binning, region of interest) or names an unsupported
// distortion model), ds.gnss_lever_arm_b, and ds.calibration_sources. ds.bag_topics names the
// topics of each role. Throws Ros2Error for a message that cannot be decoded or a transform that
// is not a rigid motion.
void applyBagCalibration(const Ros2Bag& bag, Dataset& ds);

}  // namespace gvio::io::ros2
