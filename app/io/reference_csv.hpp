#pragma once
// A GNSS/INS reference trajectory as CSV with a header naming its columns, the layout of
// taroz/MatRTKLIB's and many survey-grade INS exports (NovAtel Inertial Explorer, Applanix
// POSPac text exports): "GPS TOW (s), GPS Week, Latitude (deg), Longitude (deg), Ellipsoid Height
// (m), ..., Roll (deg), Pitch (deg), Heading (deg), East/North/Up Velocity (m/s)". Columns are
// found by name (case-insensitive, units in parentheses), in any order; others are ignored.
// Required: GPS TOW, GPS Week, latitude, longitude, ellipsoidal height. Attitude (roll, pitch,
// heading: NED convention, heading clockwise from north, the body x forward, y right, z down) and
// ENU velocity are optional, all three angles or none. Times are GPST, converted to UTC with the
// leap seconds of io/gps_time.hpp. Bad input: InputError naming the file and line.
#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <vector>

#include "fusion/geodesy.hpp"
#include "odometry/trajectory.hpp"

namespace gvio::io {

struct ReferenceEpoch {
  std::int64_t t_ns = 0;  // UTC ns since the Unix epoch
  fusion::Lla lla;        // ellipsoidal height
  // Roll, pitch, heading in degrees (NED; heading clockwise from north), when the file has them.
  std::optional<Eigen::Vector3d> rph_deg;
  std::optional<Eigen::Vector3d> v_enu_mps;
};

struct ReferenceCsv {
  std::vector<ReferenceEpoch> epochs;  // strictly increasing times
  bool has_attitude = false;
};

// True when the file's first line names the columns of a reference CSV (a "GPS TOW" column and a
// latitude column): how simulate and eval tell it from a trajectory file.
bool looksLikeReferenceCsv(const std::filesystem::path& file);

ReferenceCsv readReferenceCsv(const std::filesystem::path& file);

// The body poses in the local ENU frame `enu`: position from latitude/longitude/height, the body
// frame x forward, y left, z up (the simulator's vehicle convention) from the NED roll, pitch and
// heading (R_enu_body = R_enu_ned * Rz(heading) Ry(pitch) Rx(roll) * diag(1, -1, -1)). Throws
// InvalidInput when the file has no attitude.
Trajectory referenceBodyPoses(const ReferenceCsv& reference, const fusion::EnuFrame& enu);

// Positions only (identity orientations) in `enu`: for position-only evaluation.
Trajectory referencePositions(const ReferenceCsv& reference, const fusion::EnuFrame& enu);

}  // namespace gvio::io
