#pragma once
// The application's configuration: plain structs of the libraries and readers, bound to dotted
// YAML keys ("dataset.gap_factor") by one schema that serves the YAML file, --set and the dump.
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "fleet/fleet_config.hpp"
#include "run/run_config.hpp"
#include "sim/gnss_error.hpp"
#include "sim/sim_config.hpp"

namespace gvio::cli {

using run::FusionAppConfig;
using run::ImuConfig;
using run::MapAppConfig;
using run::VioConfig;

// Every section of the configuration: gvio run's (run::RunConfig), the simulator's, the fleet's
// and the merge's.
struct AppConfig : run::RunConfig {
  sim::SimConfig sim;
  fleet::FleetConfig fleet;
  fleet::MergeConfig merge;

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

// The configuration a finished run used: RUN/config.yaml when present (an older run may have
// none: the defaults then), as loadConfig reads a --config file.
AppConfig loadRunConfig(const std::filesystem::path& run_dir);

// The effective configuration as YAML, every key with its value (reproducible runs).
std::string dumpConfigYaml(const AppConfig& config);

// --gnss-noise: a preset (rtk | spp) or a YAML file of sim::GnssErrorModel's fields (white_h_m,
// white_v_m, bias_m, bias_tau_s, outlier_probability, outlier_min_m, outlier_max_m,
// reported_sigma_h_m, reported_sigma_v_m, quality) over the spp preset; unknown keys warn.
// Throws InvalidInput/InputError (file and line) for a bad spec or value.
sim::GnssErrorModel loadGnssNoiseModel(const std::string& spec);

}  // namespace gvio::cli
