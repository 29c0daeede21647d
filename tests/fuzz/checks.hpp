#pragma once
// What every reader's output must satisfy, whatever the input: finite numbers, ordered streams,
// sizes that agree. A reader that cannot deliver this must refuse the file instead.
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

}  // namespace gvio::fuzz
