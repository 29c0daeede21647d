#include "io/reference_csv.hpp"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <string>

#include "io/gps_time.hpp"
#include "io/input_error.hpp"
#include "io/text.hpp"
#include "odometry/error.hpp"
#include "odometry/lie.hpp"

namespace gvio::io {
namespace {

constexpr double kDegToRad = M_PI / 180.0;

// A column name without its unit, lower case, single spaces: "GPS TOW (s)" -> "gps tow".
std::string columnKey(std::string_view name) {
  std::string key;
  for (const char c : name.substr(0, name.find('('))) {
    if (std::isspace(static_cast<unsigned char>(c)) != 0 || c == '_') {
      if (!key.empty() && key.back() != ' ') key.push_back(' ');
    } else {
      key.push_back(static_cast<char>(std::tolower(static_cast<unsigned char>(c))));
    }
  }
  while (!key.empty() && key.back() == ' ') key.pop_back();
  return key;
}

enum Column { kTow, kWeek, kLat, kLon, kHeight, kRoll, kPitch, kHeading, kVe, kVn, kVu, kColumns };

// Each column's accepted names (after columnKey).
const std::array<std::vector<std::string_view>, kColumns> kNames = {{
    {"gps tow", "tow", "gps time", "gps seconds"},
    {"gps week", "week"},
    {"latitude", "lat"},
    {"longitude", "lon"},
    {"ellipsoid height", "ellipsoidal height", "height", "h ell"},
    {"roll"},
    {"pitch"},
    {"heading", "yaw", "azimuth"},
    {"east velocity", "ve", "vel east"},
    {"north velocity", "vn", "vel north"},
    {"up velocity", "vu", "vel up"},
}};

std::array<int, kColumns> findColumns(const std::vector<std::string_view>& header) {
  std::array<int, kColumns> index{};
  index.fill(-1);
  for (std::size_t i = 0; i < header.size(); ++i) {
    const std::string key = columnKey(header[i]);
    for (int c = 0; c < kColumns; ++c) {
      const auto& names = kNames[static_cast<std::size_t>(c)];
      if (index[static_cast<std::size_t>(c)] < 0 &&
          std::find(names.begin(), names.end(), key) != names.end()) {
        index[static_cast<std::size_t>(c)] = static_cast<int>(i);
      }
    }
  }
  return index;
}

}  // namespace

bool looksLikeReferenceCsv(const std::filesystem::path& file) {
  LineReader in(file);
  std::string line;
  if (!in.next(line) || line.find(',') == std::string::npos) return false;
  const auto index = findColumns(splitDelimited(line, ','));
  return index[kTow] >= 0 && index[kLat] >= 0;
}

ReferenceCsv readReferenceCsv(const std::filesystem::path& file) {
  LineReader in(file);
  std::string line;
  if (!in.next(line)) throw InputError(file, 0, "empty file: expected a header naming the columns");
  const auto index = findColumns(splitDelimited(line, ','));
  const char* const required[] = {"GPS TOW (s)", "GPS Week", "Latitude (deg)", "Longitude (deg)",
                                  "Ellipsoid Height (m)"};
  for (int c = kTow; c <= kHeight; ++c) {
    if (index[static_cast<std::size_t>(c)] < 0) {
      in.fail(fmt::format("no '{}' column in the header (a reference CSV names its columns: {})",
                          required[c], fmt::join(required, ", ")));
    }
  }
  const int angles = (index[kRoll] >= 0) + (index[kPitch] >= 0) + (index[kHeading] >= 0);
  if (angles != 0 && angles != 3) {
    in.fail("roll, pitch and heading: all three columns or none");
  }
  const bool velocity = index[kVe] >= 0 && index[kVn] >= 0 && index[kVu] >= 0;
  const int last = *std::max_element(index.begin(), index.end());

  ReferenceCsv out;
  out.has_attitude = angles == 3;
  while (in.next(line)) {
    if (isBlankOrComment(line, '#')) continue;
    const auto fields = splitDelimited(line, ',');
    if (static_cast<int>(fields.size()) <= last) {
      in.fail(fmt::format("{} fields, the header names at least {}", fields.size(), last + 1));
    }
    const auto field = [&](Column c) { return fields[static_cast<std::size_t>(index[c])]; };
    std::int64_t tow_ns = 0;
    if (!secondsToNs(field(kTow), tow_ns) || tow_ns < 0 ||
        tow_ns >= kSecondsPerWeek * 1'000'000'000) {
      in.fail(fmt::format("GPS time of week '{}' is not in [0, 604800) s", field(kTow)));
    }
    const std::int64_t week = parseInt64(field(kWeek), in, "GPS week");
    if (week < 0 || week > 10000) in.fail(fmt::format("GPS week {} is not plausible", week));
    ReferenceEpoch e;
    e.t_ns = gpstToUtcNs(gpsWeekTowToGpstUnixNs(week, tow_ns));
    e.lla = {parseFinite(field(kLat), in, "latitude"), parseFinite(field(kLon), in, "longitude"),
             parseFinite(field(kHeight), in, "ellipsoidal height")};
    if (!fusion::isValidLla(e.lla)) in.fail("latitude/longitude out of range");
    if (out.has_attitude) {
      e.rph_deg = Eigen::Vector3d(parseFinite(field(kRoll), in, "roll"),
                                  parseFinite(field(kPitch), in, "pitch"),
                                  parseFinite(field(kHeading), in, "heading"));
    }
    if (velocity) {
      e.v_enu_mps = Eigen::Vector3d(parseFinite(field(kVe), in, "east velocity"),
                                    parseFinite(field(kVn), in, "north velocity"),
                                    parseFinite(field(kVu), in, "up velocity"));
    }
    if (!out.epochs.empty() && e.t_ns <= out.epochs.back().t_ns) {
      in.fail("times must increase (GPS week and time of week)");
    }
    out.epochs.push_back(e);
  }
  if (out.epochs.empty()) throw InputError(file, 0, "no epochs after the header");
  return out;
}

Trajectory referenceBodyPoses(const ReferenceCsv& reference, const fusion::EnuFrame& enu) {
  if (!reference.has_attitude) {
    throw InvalidInput(
        "the reference has no roll, pitch and heading columns: take the orientation from the "
        "motion (gvio simulate --orientation motion)");
  }
  Eigen::Matrix3d R_enu_ned;
  R_enu_ned << 0, 1, 0, 1, 0, 0, 0, 0, -1;
  const Eigen::Matrix3d R_frd_flu = Eigen::Vector3d(1, -1, -1).asDiagonal();
  Trajectory out;
  for (const ReferenceEpoch& e : reference.epochs) {
    const Eigen::Vector3d rph = *e.rph_deg * kDegToRad;
    const Eigen::Matrix3d R_ned_frd = odometry::rotationZyx(rph);
    Eigen::Isometry3d T_enu_b = Eigen::Isometry3d::Identity();
    T_enu_b.linear() = R_enu_ned * R_ned_frd * R_frd_flu;
    T_enu_b.translation() = enu.toEnu(e.lla);
    out.t_ns.push_back(e.t_ns);
    out.poses.push_back(T_enu_b);
  }
  return out;
}

Trajectory referencePositions(const ReferenceCsv& reference, const fusion::EnuFrame& enu) {
  Trajectory out;
  for (const ReferenceEpoch& e : reference.epochs) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = enu.toEnu(e.lla);
    out.t_ns.push_back(e.t_ns);
    out.poses.push_back(T);
  }
  return out;
}

}  // namespace gvio::io
