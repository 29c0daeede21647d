#pragma once
// `gvio simulate`: a drive's poses in, a complete synthetic dataset with exact truth out.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "fusion/geodesy.hpp"
#include "io/dataset.hpp"
#include "io/reader_config.hpp"
#include "sim/body_orientation.hpp"
#include "sim/gnss_synth.hpp"
#include "sim/imu_synth.hpp"
#include "sim/sim_config.hpp"
#include "sim/trajectory_fit.hpp"

namespace gvio::sim {

struct SimRequest {
  std::filesystem::path trajectory;
  // auto|tum|kitti|reference (KITTI = odometry cam0 poses; reference: a GNSS/INS reference CSV,
  // io/reference_csv.hpp, georeferenced: the simulator's ENU origin becomes its first epoch)
  std::string trajectory_format = "auto";
  std::optional<std::filesystem::path> times;
  // Where the body's orientation comes from: the file's (checked against the direction of travel,
  // with a warning) or derived from the path (heading and pitch from the direction of travel).
  OrientationSource orientation = OrientationSource::kFile;
  io::DatasetFormat output = io::DatasetFormat::kKittiRaw;  // kitti-raw, euroc or rosbag
  std::optional<double> seconds;                            // simulate only the first S seconds
  bool stereo = true;
  GnssNoise gnss = GnssNoise::kSpp;
  // A real receiver's solution (RTKLIB .pos, NMEA, GNSS CSV) whose errors against the reference
  // trajectory are replayed instead of the `gnss` model (sim/gnss_replay.hpp); needs a reference
  // CSV as the trajectory.
  std::optional<std::filesystem::path> gnss_errors_from;
  io::ReaderConfig gnss_reader;  // how gnss_errors_from is read (dataset.*, as gvio run reads it)
  std::vector<std::pair<double, double>> outages_s;  // seconds since the drive's start
  std::uint64_t seed = 1;
  // The street world's seed (buildings, furniture, textures); nullopt: derived from `seed`. Two
  // drives of one route with one world seed see the same streets (a fleet).
  std::optional<std::uint64_t> world_seed;
  std::filesystem::path out;
  bool force = false;
  std::string config_yaml;  // the effective configuration, recorded in sim.yaml
};

struct SimSummary {
  std::size_t frames = 0, imu_samples = 0, gnss_fixes = 0, world_triangles = 0;
  // --gnss-errors-from: the solution's epochs not replayed (outside the reference or in its gaps).
  std::size_t gnss_outside_reference = 0;
  fusion::Lla origin;  // the ENU origin driven in (sim.origin_*, or a reference CSV's first epoch)
  double duration_s = 0.0, path_length_m = 0.0;
  FitReport fit;
  ImuNoiseDraw imu_noise;       // the drive's IMU noise (sim.imu_noise_scale_*)
  TurnOnBias imu_turn_on_bias;  // its biases at the start (sim.imu_turn_on_*)
  std::string egl;              // EGL path and renderer used
};

using ProgressFn = std::function<void(std::size_t done, std::size_t total)>;

// `imu_noise` is the nominal noise (imu.*), scaled per drive as sim.imu_noise_scale_* say.
// Throws InvalidInput/InputError for bad requests (unreadable trajectory, < 4 poses, outage
// outside the drive, non-empty output without force, ...).
SimSummary simulate(const SimRequest& request, const SimConfig& config, const ImuNoise& imu_noise,
                    const ProgressFn& progress);

}  // namespace gvio::sim
