#include "io/rtklib_pos.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <string_view>

#include "fusion/geodesy.hpp"
#include "fusion/gnss_covariance.hpp"
#include "io/gps_time.hpp"
#include "io/input_error.hpp"
#include "io/text.hpp"

namespace gvio::io {
namespace {

constexpr std::int64_t kNsPerS = 1'000'000'000;

// The column layout, from the last header line.
struct Layout {
  std::string time_system;  // GPST | UTC | JST
  bool ecef = false;        // else lat/lon in degrees
  bool geodetic_height = false;
  // The data column of the first velocity (vn or vx, m/s) when RTKLIB wrote velocities
  // ("Output Velocity"), else none.
  std::optional<std::size_t> velocity_column;
};

// The header names one column for the time, which is two fields in the data (date and time, or
// week and seconds): a column named after it is one field further right.
std::optional<std::size_t> velocityColumn(std::string_view header, bool ecef) {
  const std::vector<std::string_view> names = splitWhitespace(header.substr(1));
  const std::string_view first = ecef ? "vx(m/s)" : "vn(m/s)";
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (names[i] == first) return i + 1;
  }
  return std::nullopt;
}

bool contains(std::string_view s, std::string_view what) {
  return s.find(what) != std::string_view::npos;
}

// "%  GPST  latitude(deg) longitude(deg) height(m) Q ns sdn(m) ..." or "... x-ecef(m) ...".
std::optional<Layout> columnLayout(std::string_view header) {
  Layout layout;
  for (const char* system : {"GPST", "UTC", "JST"}) {
    if (contains(header, system)) {
      layout.time_system = system;
      break;
    }
  }
  if (layout.time_system.empty()) return std::nullopt;
  if (contains(header, "latitude(deg)") && contains(header, "longitude(deg)") &&
      contains(header, "height(m)") && contains(header, "sdn(m)")) {
    return layout;
  }
  if (contains(header, "x-ecef(m)") && contains(header, "z-ecef(m)") &&
      contains(header, "sdx(m)")) {
    layout.ecef = true;
    return layout;
  }
  return std::nullopt;
}

// What a header that is not one of ours says, for the error message.
std::string whyUnsupported(std::string_view header) {
  if (contains(header, "latitude(d'\")")) {
    return "latitudes in degrees-minutes-seconds are not supported: write degrees (RTKPOST "
           "option 'Lat/Lon Format: ddd.ddddddd')";
  }
  if (contains(header, "e-baseline") || contains(header, "n-baseline")) {
    return "an E/N/U baseline is relative to the base station, not georeferenced: write "
           "lat/lon/height or ECEF";
  }
  return "unknown RTKLIB column header (expected GPST|UTC|JST time and latitude(deg) "
         "longitude(deg) height(m) ... sdn(m) or x-ecef(m) ... sdx(m) columns)";
}

double signedSquare(double sqrt_var) {  // RTKLIB writes covariances as sign(c) sqrt(|c|)
  return sqrt_var < 0.0 ? -sqrt_var * sqrt_var : sqrt_var * sqrt_var;
}

// The time columns at the start of a data line: calendar (2 tokens) or week + tow (2 tokens).
std::int64_t parseTime(const std::vector<std::string_view>& f, const Layout& layout,
                       const LineReader& at) {
  std::int64_t t_ns = 0;
  if (contains(f[0], "/")) {
    std::string text = fmt::format("{} {}", f[0], f[1]);
    std::replace(text.begin(), text.begin() + 10, '/', '-');
    if (!kittiTimestampToNs(text, t_ns)) at.fail("malformed time '" + text + "'");
  } else {
    const std::int64_t week = parseInt64(f[0], at, "GPS week");
    const std::int64_t tow_ns = parseSecondsNs(f[1], at, "GPS seconds of week");
    // Week 10000 is in 2171; int64 nanoseconds end in 2262.
    if (week < 0 || week > 10000 || tow_ns < 0 || tow_ns >= kSecondsPerWeek * kNsPerS) {
      at.fail("GPS week / seconds of week out of range");
    }
    if (layout.time_system != "GPST") at.fail("week and seconds of week need GPST");
    return gpstToUtcNs(gpsWeekTowToGpstUnixNs(week, tow_ns));
  }
  if (layout.time_system == "GPST") return gpstToUtcNs(t_ns);
  if (layout.time_system == "JST") return t_ns - 9 * 3600 * kNsPerS;
  return t_ns;
}

}  // namespace

int nmeaQualityOfRtklibQ(int q) {
  switch (q) {
    case 1:
      return 4;  // fix -> RTK fixed
    case 2:
      return 5;  // float -> RTK float
    case 3:      // SBAS
    case 4:
      return 2;  // DGPS
    case 5:
      return 1;  // single
    case 6:
      return 5;  // PPP: decimetre-level once converged, floored like float RTK
    default:
      return 0;
  }
}

PosFile readRtklibPos(const std::filesystem::path& file, const ReaderConfig& config) {
  PosFile out;
  LineReader in(file);
  std::string line, last_header;
  std::optional<Layout> layout;
  bool geodetic = false;
  std::size_t first_no_solution_line = 0;
  while (in.next(line)) {
    const std::string_view text = trim(line);
    if (text.empty()) continue;
    if (text.front() == '%') {
      if (contains(text, "height=WGS84/geodetic") || contains(text, "height=geodetic")) {
        geodetic = true;
      }
      last_header = std::string(text);
      continue;
    }
    if (!layout) {  // the first data line: the header above it names the columns
      layout = columnLayout(last_header);
      if (!layout) {
        if (last_header.empty()) in.fail("no RTKLIB header ('%' lines) before the first solution");
        in.fail(whyUnsupported(last_header));
      }
      if (geodetic && !layout->ecef) {
        in.fail(
            "heights are above the geoid (RTKLIB 'Height: Geodetic'): write ellipsoidal "
            "heights");
      }
      layout->velocity_column = velocityColumn(last_header, layout->ecef);
      out.time_system = layout->time_system;
      out.position_format = layout->ecef ? "ecef" : "llh";
    }
    const std::vector<std::string_view> f = splitWhitespace(text);
    // time (2) + position (3) + Q + ns + 6 sigmas (age and ratio may follow)
    if (f.size() < 13) in.fail(fmt::format("{} columns, expected at least 13", f.size()));
    const std::int64_t t_ns = parseTime(f, *layout, in);
    const Eigen::Vector3d p(parseFinite(f[2], in, "position"), parseFinite(f[3], in, "position"),
                            parseFinite(f[4], in, "position"));
    const std::int64_t q = parseInt64(f[5], in, "Q");
    const std::int64_t ns = parseInt64(f[6], in, "number of satellites");
    double s[6];
    for (int i = 0; i < 6; ++i) s[i] = parseFinite(f[7 + static_cast<std::size_t>(i)], in, "sigma");
    if (q < 0 || q > 6 || ns < 0) in.fail(fmt::format("Q {} or ns {} out of range", q, ns));
    if (!out.fixes.empty() && t_ns <= out.fixes.back().t_ns) {
      in.fail(
          "time does not increase (RTKLIB's backward solution? write the forward or "
          "combined one)");
    }
    if (q == 0) {
      if (out.no_solution++ == 0) first_no_solution_line = in.lineNumber();
      continue;
    }
    GnssFix fix;
    fix.t_ns = t_ns;
    fix.quality = nmeaQualityOfRtklibQ(static_cast<int>(q));
    fix.num_sats = static_cast<int>(ns);
    Eigen::Matrix3d cov_enu;
    if (layout->ecef) {
      const fusion::Lla lla = fusion::ecefToLla(p);
      fix.lat_deg = lla.lat_deg;
      fix.lon_deg = lla.lon_deg;
      fix.h_ellipsoid_m = lla.h_ellipsoid_m;
      Eigen::Matrix3d cov_ecef;  // sdx sdy sdz sdxy sdyz sdzx
      cov_ecef << s[0] * s[0], signedSquare(s[3]), signedSquare(s[5]), signedSquare(s[3]),
          s[1] * s[1], signedSquare(s[4]), signedSquare(s[5]), signedSquare(s[4]), s[2] * s[2];
      const Eigen::Matrix3d R = fusion::EnuFrame(lla).R_enu_ecef();
      cov_enu = R * cov_ecef * R.transpose();
    } else {
      fix.lat_deg = p.x();
      fix.lon_deg = p.y();
      fix.h_ellipsoid_m = p.z();
      cov_enu.setZero();  // sdn sde sdu sdne sdeu sdun
      cov_enu(0, 0) = s[1] * s[1];
      cov_enu(1, 1) = s[0] * s[0];
      cov_enu(2, 2) = s[2] * s[2];
      cov_enu(0, 1) = cov_enu(1, 0) = signedSquare(s[3]);
    }
    if (!fusion::isValidLla({fix.lat_deg, fix.lon_deg, fix.h_ellipsoid_m})) {
      in.fail("position out of range");
    }
    if (const auto c = layout->velocity_column; c && f.size() >= *c + 3) {
      const Eigen::Vector3d v(parseFinite(f[*c], in, "velocity"),
                              parseFinite(f[*c + 1], in, "velocity"),
                              parseFinite(f[*c + 2], in, "velocity"));
      // vn ve vu, or ECEF vx vy vz: over ground as speed and course (clockwise from north).
      const Eigen::Vector3d v_enu =
          layout->ecef
              ? Eigen::Vector3d(fusion::EnuFrame({fix.lat_deg, fix.lon_deg, 0.0}).R_enu_ecef() * v)
              : Eigen::Vector3d(v.y(), v.x(), v.z());
      fix.speed_mps = std::hypot(v_enu.x(), v_enu.y());
      fix.course_deg = std::fmod(std::atan2(v_enu.x(), v_enu.y()) * 180.0 / M_PI + 360.0, 360.0);
      ++out.with_velocity;
    }
    const double floor_h = config.uereM(fix.quality);
    const fusion::HorizontalError h =
        fusion::flooredHorizontal(cov_enu.topLeftCorner<2, 2>(), floor_h);
    fix.sigma_h_m = h.sigma_m;
    fix.shape_en = h.shape_en;
    fix.sigma_v_m =
        std::max(std::sqrt(std::max(cov_enu(2, 2), 0.0)), floor_h * config.nmea_vertical_factor);
    out.fixes.push_back(fix);
  }
  if (!layout && !columnLayout(last_header)) {
    throw InputError(file, 0,
                     last_header.empty() ? "empty: no RTKLIB header" : whyUnsupported(last_header));
  }
  if (out.no_solution > 0) {
    out.warnings.push_back(
        fmt::format("{}: {} epochs without a solution (Q 0) skipped (first at "
                    "line {})",
                    file.string(), out.no_solution, first_no_solution_line));
  }
  return out;
}

}  // namespace gvio::io
