#pragma once
// Rotation matrices typed into calibration files: KITTI prints them to 7 digits, EuRoC-style
// sensor.yaml files to as many as their authors chose.
#include <Eigen/Core>
#include <optional>

namespace gvio::io {

// The rotation a calibration file meant: nullopt unless `R` is finite, right-handed and
// orthonormal within 1e-3 (a typo, not rounding); otherwise the nearest rotation (SVD) when its
// rounding exceeds 1e-9, so that every pose built from it is rigid, else `R` itself.
std::optional<Eigen::Matrix3d> calibrationRotation(const Eigen::Matrix3d& R);

}  // namespace gvio::io
