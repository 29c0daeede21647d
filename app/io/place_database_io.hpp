#pragma once
// keyframes.bin in a run folder: the run's place database (mapping/place_database.hpp), written
// when the run is georeferenced and loop closure is on, for gvio merge's joint alignment.
// A little-endian binary file (descriptors would triple in size as text):
//   "GVIOKFDB" u32 version (3; 1 and 2 are read too) u32 flags (bit 0: IMU)
//   camera: i32 width, height; f64 fx, fy, cx, cy; f64[12] T_b_c (rows of [R | t])
//   u64 keyframes, fixes, loops
//   per keyframe: i64 t_ns; f64[12] T_vio; f64[12] T_ref_b; f64 sigma_m, sigma_rot_deg, path_m;
//                 u32 keypoints, points, thumbnail; f32[2 x keypoints] px;
//                 u8[32 x keypoints] descriptors; f32[3 x points] p_c; f32[thumbnail]
//   per fix: u64 node; i64 t_ns; f64[3] q_b; f64[3] p_enu; f64 sigma_h_m, sigma_v_m;
//            i32 quality (NMEA GGA fix quality, 0..9; version 2: version 1 has none, read as 1)
//            f64 shape_ee, shape_nn, shape_en (the stated ellipse's shape, trace 2: version 3;
//            older versions have none, read as a circle)
//   per loop: u64 i, j; f64[12] T_i_j; f64[36] covariance (row-major)
// The reader checks every count against the bytes left and every value (finite, rigid poses,
// increasing stamps, indices in range) and names the byte offset of the first bad one.
#include <filesystem>

#include "mapping/place_database.hpp"

namespace gvio::io {

void writePlaceDatabase(const std::filesystem::path& file, const mapping::PlaceDatabase& db);
// Throws InputError ("file: byte N: what") for anything malformed.
mapping::PlaceDatabase readPlaceDatabase(const std::filesystem::path& file);
// The same from bytes in memory (the fuzz target); `file` only names them in errors.
mapping::PlaceDatabase parsePlaceDatabase(const std::string& bytes,
                                          const std::filesystem::path& file);

}  // namespace gvio::io
