#include "io/comma2k19.hpp"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "fusion/geodesy.hpp"
#include "fusion/gnss_screening.hpp"
#include "io/input_error.hpp"
#include "io/text.hpp"

namespace gvio::io {
namespace fs = std::filesystem;
namespace {

using RowFn =
    std::function<void(const LineReader& at, std::int64_t t_ns, const std::vector<double>& values)>;

// Reads a CSV whose first line is a '#' header naming the columns. `columns[0]` is the time
// column (seconds, parsed exactly to ns, strictly increasing); the others are finite numbers.
// Calls `fn` with the values of `columns[1..]` in that order.
void forEachRow(const fs::path& file, const std::vector<std::string>& columns, const RowFn& fn) {
  LineReader in(file);
  std::string line;
  std::vector<std::size_t> index;
  std::size_t needed = 0;
  std::int64_t last_t_ns = 0;
  std::size_t rows = 0;
  while (in.next(line)) {
    if (trim(line).empty()) continue;
    if (index.empty()) {
      if (line.rfind('#', 0) != 0) in.fail("expected a '#' header line naming the columns");
      std::vector<std::string_view> names = splitDelimited(std::string_view(line).substr(1), ',');
      for (const std::string& c : columns) {
        std::size_t k = 0;
        while (k < names.size() && names[k] != c) ++k;
        if (k == names.size()) in.fail("missing column '" + c + "' in the header");
        index.push_back(k);
        needed = std::max(needed, k + 1);
      }
      continue;
    }
    const std::vector<std::string_view> fields = splitDelimited(line, ',');
    if (fields.size() < needed) {
      in.fail(fmt::format("expected at least {} columns, found {}", needed, fields.size()));
    }
    const std::int64_t t_ns = parseSecondsNs(fields[index[0]], in, columns[0]);
    if (rows > 0 && t_ns <= last_t_ns) {
      in.fail(fmt::format("{} not strictly increasing ({} after {})", columns[0],
                          formatSeconds(t_ns), formatSeconds(last_t_ns)));
    }
    std::vector<double> values;
    for (std::size_t c = 1; c < columns.size(); ++c) {
      values.push_back(parseFinite(fields[index[c]], in, columns[c]));
    }
    fn(in, t_ns, values);
    last_t_ns = t_ns;
    ++rows;
  }
  if (index.empty()) throw InputError(file, 0, "empty file (no header)");
  if (rows == 0) throw InputError(file, in.lineNumber(), "no data rows");
}

// The device frame (forward, right, down) to gvio's body frame (forward, left, up).
const Eigen::Vector3d kFrdToFlu(1.0, -1.0, -1.0);

}  // namespace

bool looksLikeComma2k19(const fs::path& dir) {
  std::error_code ec;
  return fs::is_regular_file(dir / "csv" / "imu.csv", ec) &&
         fs::is_regular_file(dir / "csv" / "gnss_ublox_fix.csv", ec);
}

Dataset readComma2k19(const fs::path& dir, const ReaderConfig& config) {
  Dataset ds;
  ds.format = DatasetFormat::kComma2k19;
  ds.root = dir;
  ds.variant = "csv";
  const fs::path csv = dir / "csv";
  forEachRow(csv / "imu.csv",
             {"t_boot_s", "ax_fwd", "ay_right", "az_down", "gx_fwd", "gy_right", "gz_down"},
             [&](const LineReader&, std::int64_t t_ns, const std::vector<double>& v) {
               ImuSample s;
               s.t_ns = t_ns;
               s.acc_b_mps2 = Eigen::Vector3d(v[0], v[1], v[2]).cwiseProduct(kFrdToFlu);
               s.gyr_b_radps = Eigen::Vector3d(v[3], v[4], v[5]).cwiseProduct(kFrdToFlu);
               ds.imu.push_back(s);
             });
  const fs::path fixes = csv / "gnss_ublox_fix.csv";
  forEachRow(
      fixes,
      {"t_boot_s", "lat_deg", "lon_deg", "alt_m", "speed_mps", "bearing_deg", "utc_timestamp"},
      [&](const LineReader& at, std::int64_t t_ns, const std::vector<double>& v) {
        if (fusion::latLonOutOfRange(v[0], v[1])) {
          at.fail("latitude/longitude out of range");
        }
        if (v[3] < 0.0) at.fail("negative speed_mps");
        GnssFix f;
        f.t_ns = t_ns;
        f.lat_deg = v[0];
        f.lon_deg = v[1];
        f.h_ellipsoid_m = v[2];
        f.speed_mps = v[3];
        f.course_deg = v[4];
        f.sigma_h_m = config.comma2k19_sigma_h_m;
        f.sigma_v_m = config.comma2k19_sigma_v_m;
        ds.gnss.push_back(f);
      });
  ds.gnss_source = fixes.string();
  const fs::path gt = csv / "global_pose_gt.csv";
  std::error_code ec;
  if (!fs::is_regular_file(gt, ec)) return ds;
  const GnssFix& first = ds.gnss.front();
  const fusion::Lla origin{first.lat_deg, first.lon_deg, first.h_ellipsoid_m};
  const fusion::EnuFrame enu(origin);
  Trajectory truth;
  forEachRow(gt, {"t_boot_s", "ecef_x", "ecef_y", "ecef_z", "q0", "q1", "q2", "q3"},
             [&](const LineReader& at, std::int64_t t_ns, const std::vector<double>& v) {
               const Eigen::Quaterniond q_read(v[3], v[4], v[5], v[6]);
               if (std::abs(q_read.norm() - 1.0) > 1e-3) at.fail("quaternion not unit norm");
               // Within the tolerance, not exactly unit: a rotation only once normalised.
               const Eigen::Quaterniond q_ecef_dev = q_read.normalized();
               Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
               T.linear() = enu.R_enu_ecef() * q_ecef_dev.toRotationMatrix() *
                            kFrdToFlu.asDiagonal().toDenseMatrix();
               T.translation() = enu.ecefToEnu(Eigen::Vector3d(v[0], v[1], v[2]));
               truth.t_ns.push_back(t_ns);
               truth.poses.push_back(T);
             });
  ds.groundtruth = std::move(truth);
  ds.groundtruth_source = gt.string();
  ds.groundtruth_enu_origin = origin;
  return ds;
}

}  // namespace gvio::io
