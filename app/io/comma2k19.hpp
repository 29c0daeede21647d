#pragma once
// comma2k19 segments converted to CSV (../shared/data/comma2k19, see its README): IMU, u-blox GNSS
// fixes and the fused ground truth, all on the t_boot_s clock; no camera frames are read, so a run
// is GNSS/INS (fusion/gnss_ins.hpp).
//
//   csv/imu.csv             t_boot_s, ax_fwd, ay_right, az_down (m/s^2), gx_fwd, gy_right, gz_down
//                           (rad/s), ... : the device frame is forward-right-down. Checked against
//                           the truth: a level device reads az_down ~ -9.8 (specific force), and
//                           the integrated gyro rates match the truth's attitude changes with these
//                           signs (gy_right > 0 nose up, lag 0 +- 10 ms). The body frame of gvio is
//                           forward-left-up, so y and z change sign: acc_b = (ax, -ay, -az).
//   csv/gnss_ublox_fix.csv  t_boot_s, lat_deg, lon_deg, speed_mps, utc_timestamp (ms), alt_m,
//                           bearing_deg: alt_m is taken as ellipsoidal (the geoid is ~-32 m there;
//                           the heights sit ~1 m above the truth, consistent with an antenna above
//                           the device). No accuracy columns: sigmas from dataset.comma2k19_*.
//   csv/global_pose_gt.csv  t_boot_s, gps_week, gps_tow_s, ecef_x, ecef_y, ecef_z, q0..q3 (device
//                           -> ECEF, w x y z), vel_ecef_*: converted to body poses in the local ENU
//                           frame of the first fix (Dataset::groundtruth_enu_origin).
// Columns are found by their header names, so extra columns are fine. Bad input (missing file or
// column, a non-finite value, time not strictly increasing) throws InputError naming file:line.
#include <filesystem>

#include "io/dataset.hpp"
#include "io/reader_config.hpp"

namespace gvio::io {

// True when `dir` holds csv/imu.csv and csv/gnss_ublox_fix.csv.
bool looksLikeComma2k19(const std::filesystem::path& dir);

Dataset readComma2k19(const std::filesystem::path& dir, const ReaderConfig& config);

}  // namespace gvio::io
