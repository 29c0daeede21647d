#pragma once
// What every reader's output must satisfy, whatever the input: finite numbers, ordered streams,
// sizes that agree. A reader that cannot deliver this must refuse the file instead.
#include <filesystem>
#include <vector>

#include "io/dataset.hpp"
#include "odometry/measurements.hpp"
#include "odometry/trajectory.hpp"

namespace gvio::fuzz {

void checkTrajectory(const Trajectory& traj, bool increasing, double rotation_tolerance = 1e-6);
void checkFixes(const std::vector<GnssFix>& fixes);
void checkImu(const std::vector<ImuSample>& imu);
void checkCamera(const CameraModel& camera);
void checkImuNoise(const ImuNoise& noise);
void checkDataset(const io::Dataset& ds);

// The whole dataset as `gvio run` opens it (its calibration files given), checked, and every
// frame's images loaded as the run loads them.
void readWholeDataset(const std::filesystem::path& dataset,
                      std::vector<std::filesystem::path> calib_files = {});

}  // namespace gvio::fuzz
