#pragma once
// The application's configuration: plain structs of the libraries and readers, bound to dotted
// YAML keys ("dataset.gap_factor") by one schema that serves the YAML file, --set and the dump.
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "fusion/gnss_fusion.hpp"
#include "fusion/gnss_ins.hpp"
#include "io/reader_config.hpp"
#include "mapping/map_config.hpp"
#include "odometry/measurements.hpp"
#include "odometry/vio_config.hpp"
#include "sim/gnss_error.hpp"
#include "sim/sim_config.hpp"

namespace gvio::cli {

struct ImuConfig {
  // Used when the dataset states its own noise (EuRoC imu0/sensor.yaml) unless false.
  bool prefer_dataset_noise = true;
  ImuNoise noise;
};

// gvio run's estimator (YAML section `vio:`). The IMU noise comes from `imu:` (or the dataset),
// the tracker's stereo flag from the mode, so those two fields of `estimator` are set per run.
struct VioConfig {
  // auto | stereo-imu | mono-imu | stereo; auto picks from the dataset's sensors at run time.
  std::string mode = "auto";
  odometry::EstimatorConfig estimator;

  void validate() const;  // throws InvalidInput naming the key
};

// gvio run's GNSS fusion (YAML section `fusion:`); the mode comes from --gnss.
struct FusionAppConfig {
  // Origin of the local ENU frame: "first-fix", or "lat,lon,h" (deg, deg, ellipsoidal m).
  std::string origin = "first-fix";
  fusion::FusionConfig fusion;
  // GNSS/INS without a camera (fusion.ins.*); its lever arm, time offset, gate, rejections and
  // outage length are fusion.*'s, and its IMU noise imu.*'s: see insConfig().
  fusion::InsConfig ins;

  // `ins` with the shared fusion.* values and `imu_noise` filled in.
  [[nodiscard]] fusion::InsConfig insConfig(const ImuNoise& imu_noise) const;
  // The origin as given, nullopt for first-fix; throws InvalidInput for malformed text.
  [[nodiscard]] std::optional<fusion::Lla> originLla() const;
  void validate() const;  // throws InvalidInput naming the key
};

// gvio run's map (YAML section `map:`): sparse landmarks, dense stereo, OctoMap occupancy.
struct MapAppConfig {
  bool enabled = true;  // false: no map files (the run is trajectories only)
  mapping::MapConfig map;
};

struct AppConfig {
  io::ReaderConfig dataset;
  ImuConfig imu;
  VioConfig vio;
  FusionAppConfig fusion;
  MapAppConfig map;
  sim::SimConfig sim;

  void validate() const;  // throws InvalidInput naming the key
};

struct ConfigKey {
  std::string name;                           // dotted, e.g. "imu.acc_noise_density"
  std::function<void(std::string_view)> set;  // throws InvalidInput on a bad value
  std::function<std::string()> get;           // current value as YAML text
};

// Every configurable key of `config`, bound to its fields.
std::vector<ConfigKey> configKeys(AppConfig& config);

struct ConfigSources {
  std::optional<std::filesystem::path> file;  // --config
  std::vector<std::string> overrides;         // --set key=value, applied after the file
};

// Defaults, then the YAML file (unknown keys warn with file:line), then the overrides (an unknown
// key is an error there: it was typed on purpose), then validate(). Throws InvalidInput/InputError.
// Unknown file keys are appended to `unknown_keys` when given.
AppConfig loadConfig(const ConfigSources& sources,
                     std::vector<std::string>* unknown_keys = nullptr);

// The effective configuration as YAML, every key with its value (reproducible runs).
std::string dumpConfigYaml(const AppConfig& config);

// --gnss-noise: a preset (rtk | spp) or a YAML file of sim::GnssErrorModel's fields (white_h_m,
// white_v_m, bias_m, bias_tau_s, outlier_probability, outlier_min_m, outlier_max_m,
// reported_sigma_h_m, reported_sigma_v_m, quality) over the spp preset; unknown keys warn.
// Throws InvalidInput/InputError (file and line) for a bad spec or value.
sim::GnssErrorModel loadGnssNoiseModel(const std::string& spec);

}  // namespace gvio::cli
