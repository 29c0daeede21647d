// gvio simulate: a synthetic KITTI-style (or EuRoC) drive with exact truth from a real trajectory.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <regex>

#include "cli/app.hpp"
#include "odometry/error.hpp"
#include "sim/simulator.hpp"
#include "sim/world.hpp"

namespace gvio::cli {
namespace {

struct SimulateCliOptions {
  sim::SimRequest request;
  std::string format = "kitti-raw", camera = "stereo", gnss = "spp";
  std::vector<std::string> outages;
  std::optional<std::string> times, world_style, gnss_errors_from;
  std::string orientation = "file";
  std::string trajectory, out;
  ConfigOptions config;
};

std::pair<double, double> parseOutage(const std::string& text) {
  static const std::regex kRange(R"(\s*([0-9.eE+-]+)\s*:\s*([0-9.eE+-]+)\s*)");
  std::smatch m;
  double a = 0.0, b = 0.0;
  try {
    if (!std::regex_match(text, m, kRange)) throw std::invalid_argument(text);
    a = std::stod(m[1]);
    b = std::stod(m[2]);
  } catch (const std::exception&) {
    throw gvio::InvalidInput("--gnss-outage '" + text +
                             "': expected T0:T1 in seconds since the start");
  }
  return {a, b};
}

int runSimulate(SimulateCliOptions& o, const CommonOptions& common) {
  AppConfig config = o.config.load();
  if (o.world_style) {  // checked here, not by CLI11: a bad value is one line, exit 2
    if (!sim::parseWorldStyle(*o.world_style)) {
      throw gvio::InvalidInput(fmt::format("--world-style '{}': expected one of {}", *o.world_style,
                                           sim::kWorldStyleNames));
    }
    config.sim.world_style = *o.world_style;
  }
  const auto orientation = sim::parseOrientationSource(o.orientation);
  if (!orientation) {  // as --world-style: one line, exit 2
    throw gvio::InvalidInput(fmt::format("--orientation '{}': expected {}", o.orientation,
                                         sim::kOrientationSourceNames));
  }
  sim::SimRequest& r = o.request;
  r.orientation = *orientation;
  r.config_yaml = dumpConfigYaml(config);
  r.trajectory = o.trajectory;
  r.out = o.out;
  if (o.times) r.times = *o.times;
  r.output = *io::parseDatasetFormat(o.format);
  r.stereo = o.camera == "stereo";
  r.gnss = sim::parseGnssNoise(o.gnss);
  if (o.gnss_errors_from) r.gnss_errors_from = *o.gnss_errors_from;
  r.gnss_reader = config.dataset;
  for (const auto& text : o.outages) r.outages_s.push_back(parseOutage(text));
  std::optional<Progress> progress;  // created once the frame count is known
  const sim::SimSummary s =
      sim::simulate(r, config.sim, config.imu.noise, [&](std::size_t done, std::size_t n) {
        if (!progress) progress.emplace("simulate", n, "frames", common.progressStyle());
        progress->update(done);
      });
  if (progress) progress->finish();
  fmt::print(
      "simulated {:.1f} s, {:.0f} m: {} {} frames, {} IMU samples, {} GNSS fixes, {} world {} "
      "triangles\n",
      s.duration_s, s.path_length_m, s.frames, r.stereo ? "stereo" : "mono", s.imu_samples,
      s.gnss_fixes, config.sim.world_style, s.world_triangles);
  const ImuNoise& n = s.imu_noise.noise;
  fmt::print(
      "IMU noise: acc {:.3g} m/s^2/sqrt(Hz), gyr {:.3g} rad/s/sqrt(Hz), acc walk {:.3g}, gyr "
      "walk {:.3g} (x {:.3g}, {:.3g}, {:.3g}, {:.3g} of imu.*)\n",
      n.acc_noise_density, n.gyr_noise_density, n.acc_random_walk, n.gyr_random_walk,
      s.imu_noise.scale[0], s.imu_noise.scale[1], s.imu_noise.scale[2], s.imu_noise.scale[3]);
  if (const auto& b = s.imu_turn_on_bias; !b.acc_mps2.isZero(0.0) || !b.gyr_radps.isZero(0.0)) {
    fmt::print(
        "IMU turn-on bias: acc [{:.3g}, {:.3g}, {:.3g}] m/s^2, gyr [{:.3g}, {:.3g}, {:.3g}] "
        "rad/s\n",
        b.acc_mps2.x(), b.acc_mps2.y(), b.acc_mps2.z(), b.gyr_radps.x(), b.gyr_radps.y(),
        b.gyr_radps.z());
  }
  fmt::print(
      "trajectory fit residual: position rms {:.4f} m (max {:.4f}), rotation rms {:.3f} deg (max "
      "{:.3f})\n",
      s.fit.position_rms_m, s.fit.position_max_m, s.fit.rotation_rms_deg, s.fit.rotation_max_deg);
  fmt::print("rendered with EGL {}\nwrote {}\n", s.egl, r.out.string());
  return 0;
}

}  // namespace

Command addSimulateCommand(CLI::App& app, const CommonOptions& common) {
  auto o = std::make_shared<SimulateCliOptions>();
  CLI::App* sub =
      app.add_subcommand("simulate", "Simulate a stereo/mono + IMU + GNSS drive with exact truth");
  sub->add_option("--trajectory", o->trajectory,
                  "Poses to drive: TUM (body, z up), KITTI odometry (cam0) or a GNSS/INS "
                  "reference CSV (GPS TOW, week, lat, lon, height, roll, pitch, heading: driven "
                  "where it was recorded)")
      ->required();
  sub->add_option("--trajectory-format", o->request.trajectory_format,
                  "auto guesses from the first line")
      ->check(CLI::IsMember({"auto", "tum", "kitti", "reference"}));
  sub->add_option("--times", o->times, "Times file of a KITTI trajectory (seconds per line)");
  sub->add_option("--orientation", o->orientation,
                  "file (default): the file's body orientation, warned about when its x axis is "
                  "not the direction of travel; motion: a vehicle's, heading from the direction of "
                  "travel, pitch from the climb, roll zero");
  sub->add_option("--format", o->format,
                  "Output layout: kitti-raw, euroc, rosbag (drive.bag + Kalibr camchain.yaml "
                  "and imu.yaml) or ros2bag (the folder is a ROS 2 bag: metadata.yaml + "
                  "drive_0.mcap with CameraInfo and /tf_static; sim.ros2bag_storage sqlite3 for "
                  "drive_0.db3)")
      ->check(CLI::IsMember({"kitti-raw", "euroc", "rosbag", "ros2bag"}));
  sub->add_option("--seconds", o->request.seconds, "Simulate only the first S seconds");
  sub->add_option("--camera", o->camera, "stereo or mono")
      ->check(CLI::IsMember({"stereo", "mono"}));
  sub->add_option("--gnss-noise", o->gnss, "GNSS error model")
      ->check(CLI::IsMember({"none", "spp", "rtk"}));
  sub->add_option("--gnss-errors-from", o->gnss_errors_from,
                  "A real receiver's solution (RTKLIB .pos, NMEA, GNSS CSV) of the reference "
                  "--trajectory's drive: each epoch it solved becomes a fix with its real error "
                  "(fix - reference), sigmas and quality; its gaps stay gaps")
      ->excludes(sub->get_option("--gnss-noise"));
  sub->add_option("--gnss-outage", o->outages,
                  "T0:T1 seconds since the start without fixes (repeatable)")
      ->take_all()
      ->allow_extra_args(false);
  sub->add_option("--world-style", o->world_style,
                  "street (default), open_road, sparse_texture, repetitive or vegetation "
                  "(overrides sim.world_style)");
  sub->add_option("--seed", o->request.seed, "Random seed: same seed, byte-identical output")
      ->check(countValidator("SEED"));
  sub->add_option("--world-seed", o->request.world_seed,
                  "Seed of the street world alone (default: --seed): drives of one route with one "
                  "world seed and different --seed see the same streets with their own noise")
      ->check(countValidator("SEED"));
  sub->add_option("--out", o->out, "Output folder (must be empty unless --force)")->required();
  sub->add_flag("--force", o->request.force,
                "Overwrite the simulator's files in a non-empty output folder");
  o->config.addTo(*sub);
  return {sub, [o, &common] { return runSimulate(*o, common); }};
}

}  // namespace gvio::cli
