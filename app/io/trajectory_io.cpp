#include "io/trajectory_io.hpp"

#include <fmt/format.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <ostream>
#include <vector>

#include "io/atomic_write.hpp"
#include "io/input_error.hpp"
#include "io/text.hpp"
#include "odometry/error.hpp"

namespace gvio::io {
namespace {

namespace fs = std::filesystem;
using Fields = std::vector<std::string_view>;

// Loose enough for quaternions printed with 6 digits (EuRoC ground truth), tight enough to catch
// a wrong column order (e.g. a position read as a quaternion component).
constexpr double kQuatNormTolerance = 1e-3;
// KITTI files print R with 7 digits; evo uses R as-is, so only reject what is clearly not a
// rotation (a transposed layout, a scaled or reflected matrix).
constexpr double kRotationTolerance = 1e-3;

// Names of the value columns after the timestamp, for error messages.
constexpr std::array<std::string_view, 7> kTumNames = {"tx", "ty", "tz", "qx", "qy", "qz", "qw"};
constexpr std::array<std::string_view, 7> kEurocNames = {"p_x", "p_y", "p_z", "q_w",
                                                         "q_x", "q_y", "q_z"};

// Calls `parse(fields, reader)` for every data line; '#' and blank lines are skipped.
// `delim` == 0 splits on whitespace (TUM, KITTI), otherwise on that character (CSV).
template <typename ParseLine>
void forEachRecord(const fs::path& file, char delim, ParseLine&& parse) {
  LineReader reader(file);
  std::string line;
  while (reader.next(line)) {
    if (isBlankOrComment(line)) continue;
    const Fields fields = delim == 0 ? splitWhitespace(line) : splitDelimited(trim(line), delim);
    parse(fields, reader);
  }
}

void requireFields(const Fields& fields, std::size_t expected, bool at_least,
                   const LineReader& at) {
  if (at_least ? fields.size() >= expected : fields.size() == expected) return;
  at.fail(fmt::format("expected {}{} fields, got {}", at_least ? "at least " : "", expected,
                      fields.size()));
}

// Association and interpolation need strictly increasing stamps; a repeat or a step back means a
// broken file (concatenated runs, a wrong column), never something to sort silently.
void requireIncreasing(const std::vector<std::int64_t>& stamps, std::int64_t t_ns,
                       const LineReader& at, StampOrder order = StampOrder::kIncreasing) {
  if (order == StampOrder::kAsGiven || stamps.empty() || t_ns > stamps.back()) return;
  at.fail(fmt::format("timestamp not increasing (previous {} s, this {} s)",
                      formatSeconds(stamps.back()), formatSeconds(t_ns)));
}

void requirePoses(const Trajectory& traj, const fs::path& file) {
  if (traj.empty()) throw InputError(file, 0, "no poses");
}

Eigen::Quaterniond unitQuaternion(double w, double x, double y, double z, const LineReader& at) {
  const Eigen::Quaterniond q(w, x, y, z);
  const double norm = q.norm();
  if (!(std::abs(norm - 1.0) <= kQuatNormTolerance)) {
    at.fail(fmt::format("quaternion not normalised (|q| = {:.9g})", norm));
  }
  return q.normalized();
}

Eigen::Isometry3d makePose(const Eigen::Vector3d& t, const Eigen::Quaterniond& q) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = q.toRotationMatrix();
  pose.translation() = t;
  return pose;
}

// Parses fields[first..first+n) with the given names (for error messages).
template <std::size_t N>
std::array<double, N> parseValues(const Fields& fields, std::size_t first,
                                  const std::array<std::string_view, N>& names,
                                  const LineReader& at) {
  std::array<double, N> values{};
  for (std::size_t i = 0; i < N; ++i) values[i] = parseFinite(fields[first + i], at, names[i]);
  return values;
}

// EuRoC stamps are integer ns; evo reads the column as float, so "1.4037e18" is accepted too.
std::int64_t parseStampNs(std::string_view token, const LineReader& at) {
  if (token.find_first_of(".eE") == std::string_view::npos) {
    return parseInt64(token, at, "timestamp");
  }
  const double ns = parseFinite(token, at, "timestamp");
  if (std::abs(ns) > 9.2e18) at.fail(fmt::format("timestamp '{}' out of range", token));
  return std::llround(ns);
}

Eigen::Isometry3d parseKittiPose(const Fields& fields, const LineReader& at) {
  static constexpr std::array<std::string_view, 12> kNames = {
      "r11", "r12", "r13", "tx", "r21", "r22", "r23", "ty", "r31", "r32", "r33", "tz"};
  const auto v = parseValues(fields, 0, kNames, at);
  Eigen::Matrix<double, 3, 4, Eigen::RowMajor> rt;
  for (int i = 0; i < 12; ++i) rt(i / 4, i % 4) = v[static_cast<std::size_t>(i)];
  const Eigen::Matrix3d r = rt.leftCols<3>();
  const double ortho = (r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  const double det = r.determinant();
  if (!(ortho <= kRotationTolerance) || !(det > 0.0)) {
    at.fail(fmt::format("not a rotation (|R^T R - I|max = {:.3g}, det(R) = {:.6g})", ortho, det));
  }
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = r;  // as read, not re-orthonormalised: evo uses it unchanged
  pose.translation() = rt.col(3);
  return pose;
}

std::vector<std::int64_t> readKittiTimes(const fs::path& file, StampOrder order) {
  std::vector<std::int64_t> stamps;
  forEachRecord(file, 0, [&](const Fields& fields, const LineReader& at) {
    requireFields(fields, 1, false, at);
    const std::int64_t t_ns = parseSecondsNs(fields[0], at, "timestamp");
    requireIncreasing(stamps, t_ns, at, order);
    stamps.push_back(t_ns);
  });
  return stamps;
}

void requireTimestamps(const Trajectory& traj, const fs::path& file, std::string_view format) {
  if (traj.t_ns.size() == traj.poses.size()) return;
  if (!traj.hasTimestamps()) {
    throw InvalidInput(fmt::format("{}: the {} format needs timestamps, the trajectory has none",
                                   file.string(), format));
  }
  throw InvalidInput(fmt::format("{}: trajectory has {} timestamps for {} poses", file.string(),
                                 traj.t_ns.size(), traj.poses.size()));
}

// The quaternion of a pose as written: from R as stored (KITTI-read poses are not
// re-orthonormalised).
Eigen::Quaterniond quaternionOf(const Eigen::Isometry3d& pose) {
  return Eigen::Quaterniond(Eigen::Matrix3d(pose.linear())).normalized();
}

}  // namespace

std::optional<TrajectoryFormat> parseTrajectoryFormat(std::string_view name) {
  if (name == "tum") return TrajectoryFormat::kTum;
  if (name == "kitti") return TrajectoryFormat::kKitti;
  if (name == "euroc") return TrajectoryFormat::kEuroc;
  return std::nullopt;
}

std::string toString(TrajectoryFormat format) {
  switch (format) {
    case TrajectoryFormat::kTum:
      return "tum";
    case TrajectoryFormat::kKitti:
      return "kitti";
    case TrajectoryFormat::kEuroc:
      return "euroc";
  }
  return "unknown";
}

Trajectory readTum(const fs::path& file, StampOrder order) {
  Trajectory traj;
  forEachRecord(file, 0, [&](const Fields& fields, const LineReader& at) {
    requireFields(fields, 8, false, at);
    const std::int64_t t_ns = parseSecondsNs(fields[0], at, "timestamp");
    const auto v = parseValues(fields, 1, kTumNames, at);
    const Eigen::Quaterniond q = unitQuaternion(v[6], v[3], v[4], v[5], at);  // w last
    requireIncreasing(traj.t_ns, t_ns, at, order);
    traj.t_ns.push_back(t_ns);
    traj.poses.push_back(makePose({v[0], v[1], v[2]}, q));
  });
  requirePoses(traj, file);
  return traj;
}

Trajectory readKitti(const fs::path& file, const std::optional<fs::path>& times_file,
                     StampOrder order) {
  Trajectory traj;
  forEachRecord(file, 0, [&](const Fields& fields, const LineReader& at) {
    requireFields(fields, 12, false, at);
    traj.poses.push_back(parseKittiPose(fields, at));
  });
  requirePoses(traj, file);
  if (!times_file) return traj;
  traj.t_ns = readKittiTimes(*times_file, order);
  if (traj.t_ns.size() != traj.poses.size()) {
    throw InputError(*times_file, 0,
                     fmt::format("{} timestamps for {} poses in {}", traj.t_ns.size(),
                                 traj.poses.size(), file.string()));
  }
  return traj;
}

Trajectory readEurocCsv(const fs::path& file, StampOrder order) {
  Trajectory traj;
  forEachRecord(file, ',', [&](const Fields& fields, const LineReader& at) {
    requireFields(fields, 8, true, at);
    const std::int64_t t_ns = parseStampNs(fields[0], at);
    const auto v = parseValues(fields, 1, kEurocNames, at);
    const Eigen::Quaterniond q = unitQuaternion(v[3], v[4], v[5], v[6], at);  // w first
    requireIncreasing(traj.t_ns, t_ns, at, order);
    traj.t_ns.push_back(t_ns);
    traj.poses.push_back(makePose({v[0], v[1], v[2]}, q));
  });
  requirePoses(traj, file);
  return traj;
}

Trajectory readTrajectory(const fs::path& file, TrajectoryFormat format,
                          const std::optional<fs::path>& times_file, StampOrder order) {
  if (format == TrajectoryFormat::kKitti) return readKitti(file, times_file, order);
  if (times_file) {
    throw InvalidInput(fmt::format("{}: a times file only applies to the kitti format, not {}",
                                   times_file->string(), toString(format)));
  }
  return format == TrajectoryFormat::kTum ? readTum(file, order) : readEurocCsv(file, order);
}

StampOrderSummary summarizeStampOrder(const std::vector<std::int64_t>& t_ns) {
  StampOrderSummary s;
  for (std::size_t i = 1; i < t_ns.size(); ++i) {
    if (t_ns[i] > t_ns[i - 1]) continue;
    if (s.repeated + s.steps_back == 0) s.first_index = i;
    ++(t_ns[i] == t_ns[i - 1] ? s.repeated : s.steps_back);
  }
  return s;
}

void writeTum(const fs::path& file, const Trajectory& traj) {
  requireTimestamps(traj, file, "tum");
  writeFileAtomic(file, [&](std::ostream& out) {
    for (std::size_t i = 0; i < traj.size(); ++i) {
      const Eigen::Vector3d t = traj.poses[i].translation();
      const Eigen::Quaterniond q = quaternionOf(traj.poses[i]);
      out << fmt::format("{} {:.9f} {:.9f} {:.9f} {:.9f} {:.9f} {:.9f} {:.9f}\n",
                         formatSeconds(traj.t_ns[i]), t.x(), t.y(), t.z(), q.x(), q.y(), q.z(),
                         q.w());
    }
  });
}

void writeKitti(const fs::path& file, const Trajectory& traj) {
  writeFileAtomic(file, [&](std::ostream& out) {
    for (const Eigen::Isometry3d& pose : traj.poses) {
      const auto& m = pose.matrix();
      for (int i = 0; i < 12; ++i) {
        out << fmt::format("{:.12e}", m(i / 4, i % 4)) << (i == 11 ? '\n' : ' ');
      }
    }
  });
}

void writeKittiTimes(const fs::path& file, const Trajectory& traj) {
  requireTimestamps(traj, file, "kitti times");
  writeFileAtomic(file, [&](std::ostream& out) {
    for (const std::int64_t t_ns : traj.t_ns) out << formatSeconds(t_ns) << '\n';
  });
}

void writeEurocCsv(const fs::path& file, const Trajectory& traj) {
  requireTimestamps(traj, file, "euroc");
  writeFileAtomic(file, [&](std::ostream& out) {
    out << "#timestamp [ns],p_x [m],p_y [m],p_z [m],q_w [],q_x [],q_y [],q_z []\n";
    for (std::size_t i = 0; i < traj.size(); ++i) {
      const Eigen::Vector3d t = traj.poses[i].translation();
      const Eigen::Quaterniond q = quaternionOf(traj.poses[i]);
      out << fmt::format("{},{:.9f},{:.9f},{:.9f},{:.9f},{:.9f},{:.9f},{:.9f}\n", traj.t_ns[i],
                         t.x(), t.y(), t.z(), q.w(), q.x(), q.y(), q.z());
    }
  });
}

void writeTrajectory(const fs::path& file, const Trajectory& traj, TrajectoryFormat format) {
  switch (format) {
    case TrajectoryFormat::kTum:
      return writeTum(file, traj);
    case TrajectoryFormat::kKitti:
      return writeKitti(file, traj);
    case TrajectoryFormat::kEuroc:
      return writeEurocCsv(file, traj);
  }
}

TrajectoryFormat detectTrajectoryFormat(const fs::path& file) {
  LineReader reader(file);
  std::string line;
  while (reader.next(line)) {
    if (isBlankOrComment(line)) continue;
    if (line.find(',') != std::string::npos) return TrajectoryFormat::kEuroc;
    const std::size_t fields = splitWhitespace(line).size();
    if (fields == 8) return TrajectoryFormat::kTum;
    if (fields == 12) return TrajectoryFormat::kKitti;
    reader.fail("cannot tell the trajectory format from " + std::to_string(fields) +
                " fields (TUM has 8, KITTI 12, EuRoC is comma separated)");
  }
  throw InputError(file, 0, "no poses");
}

}  // namespace gvio::io
