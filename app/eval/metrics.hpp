#pragma once
// Trajectory error metrics exactly as evo (M. Grupp, github.com/MichaelGrupp/evo, 1.36) computes
// them: nearest-stamp association, Umeyama alignment of the estimate onto the reference, APE and
// RPE with evo's pose relations and statistics.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "odometry/trajectory.hpp"

namespace gvio::eval {

enum class Alignment { kNone, kSe3, kSim3, kOrigin };
enum class Relation { kTranslation, kFull, kAngleDeg };
enum class DeltaUnit { kFrames, kMeters };

Alignment parseAlignment(const std::string& name);  // none|se3|sim3|origin, throws InvalidInput
Relation parseRelation(const std::string& name);    // trans|full|angle_deg
DeltaUnit parseDeltaUnit(const std::string& name);  // frames|m
std::string describe(Relation relation);            // "translation part (m)" ...

// evo's get_all_statistics(): population std, median of the sorted errors.
struct Stats {
  double rmse = 0.0, mean = 0.0, median = 0.0, std = 0.0, min = 0.0, max = 0.0, sse = 0.0;
  std::size_t n = 0;
};
Stats computeStats(const std::vector<double>& errors);  // throws InvalidInput when empty

struct Association {
  std::vector<std::size_t> ref, est;  // matched index pairs, in evo's order
};
// evo sync.associate_trajectories: the shorter trajectory's stamps are matched to the nearest
// stamp of the longer one (est stamps shifted by offset), accepted when |dt| <= max_diff.
Association associateByTime(const std::vector<std::int64_t>& ref_t_ns,
                            const std::vector<std::int64_t>& est_t_ns, std::int64_t max_diff_ns,
                            std::int64_t est_offset_ns);

// y = s R x + t minimising sum |y_i - (s R x_i + t)|^2 (Umeyama 1991, eqs. 34-43).
struct Sim3 {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  double s = 1.0;
};
// Throws InvalidInput when the covariance has rank < 2 (collinear or coincident points).
Sim3 umeyama(const std::vector<Eigen::Vector3d>& x, const std::vector<Eigen::Vector3d>& y,
             bool with_scale);

// evo's lie.relative_se3(a, b) = a^-1 b with the inverse taken as [R^T, -R^T t].
Eigen::Matrix4d relativeSe3(const Eigen::Matrix4d& a, const Eigen::Matrix4d& b);
// Rotation angle as scipy's Rotation.from_matrix(R).as_rotvec() gives it (well conditioned for
// small angles, unlike acos((tr R - 1) / 2)).
double rotationAngleRad(const Eigen::Matrix3d& R);

// Per-pose APE of `est` against `ref` (same length, already associated and aligned).
std::vector<double> apeErrors(const std::vector<Eigen::Matrix4d>& ref,
                              const std::vector<Eigen::Matrix4d>& est, Relation relation);

// evo filters.filter_pairs_by_index / filter_pairs_by_path (consecutive pairs) on `poses`.
std::vector<std::pair<std::size_t, std::size_t>> rpePairs(const std::vector<Eigen::Matrix4d>& poses,
                                                          double delta, DeltaUnit unit);
std::vector<double> rpeErrors(const std::vector<Eigen::Matrix4d>& ref,
                              const std::vector<Eigen::Matrix4d>& est,
                              const std::vector<std::pair<std::size_t, std::size_t>>& pairs,
                              Relation relation);

}  // namespace gvio::eval
