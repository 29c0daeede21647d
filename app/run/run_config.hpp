#pragma once
// gvio run's configuration: the plain structs of the libraries the run's stages use, grouped by
// YAML section (dataset, imu, vio, fusion, map, loops). app/cli binds them to YAML keys
// (cli/config.hpp); the stages in app/run read them, nothing here parses text files.
#include <optional>
#include <string>

#include "fusion/gnss_fusion.hpp"
#include "fusion/gnss_ins.hpp"
#include "io/reader_config.hpp"
#include "mapping/map_config.hpp"
#include "odometry/measurements.hpp"
#include "odometry/vio_config.hpp"
#include "run/loop_run.hpp"

namespace gvio::run {

struct ImuConfig {
  // Used when the dataset states its own noise (EuRoC imu0/sensor.yaml) unless false.
  bool prefer_dataset_noise = true;
  // Multiplies the dataset's stated densities and random walks (imu.* are used as written).
  // Stated figures come from a bench test (Allan variance, a datasheet); on a vehicle vibration
  // and temperature make the noise larger, and the usual practice is to inflate them. On
  // simulated drives whose noise is stated exactly, 1 is best over the style matrix, 1.4 and 2
  // worse (docs/benchmarks/vio-matrix.md, "The drive's own IMU noise").
  double dataset_noise_scale = 1.0;
  ImuNoise noise;

  struct Choice {
    ImuNoise noise;
    const char* source;  // "dataset" or "config"
  };
  // The noise the estimators use for a dataset that states `dataset_noise` (or not).
  [[nodiscard]] Choice choose(const std::optional<ImuNoise>& dataset_noise) const;
  void validate() const;  // throws InvalidInput naming the key
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
  // The graphs' VIO relative-motion noise (fusion.vio_drift_fraction, vio_sigma_floor_m,
  // vio_rot_floor_rad; fusion.vio_rot_drift_rad_per_m is one value for every mode): 0 = auto, the
  // figures measured for the run's VIO mode (fusionFor); a value set overrides them.
  double vio_drift_fraction = 0.0;
  double vio_sigma_floor_m = 0.0;
  double vio_rot_floor_rad = 0.0;
  // GNSS/INS without a camera (fusion.ins.*); its lever arm, time offset, gate, rejections and
  // outage length are fusion.*'s, and its IMU noise imu.*'s: see insConfig().
  fusion::InsConfig ins;

  // `fusion` with the VIO noise of `mode` (nullopt: not known, as in gvio merge: the model of
  // the modes that drift most) where the three fields above say auto.
  [[nodiscard]] fusion::FusionConfig fusionFor(std::optional<odometry::VioMode> mode) const;
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

struct RunConfig {
  io::ReaderConfig dataset;
  ImuConfig imu;
  VioConfig vio;
  FusionAppConfig fusion;
  MapAppConfig map;
  LoopStageConfig loops;  // loop closure and the global pose graph (loops.*)

  void validate() const;  // throws InvalidInput naming the key
};

}  // namespace gvio::run
