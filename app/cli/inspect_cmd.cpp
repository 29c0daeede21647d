// gvio inspect: read and validate a whole dataset (every text line, every image), then summarise
// it, so a broken dataset is caught before a long run.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <iostream>

#include "cli/app.hpp"
#include "io/atomic_write.hpp"
#include "io/dataset_sources.hpp"
#include "io/dataset_summary.hpp"

namespace gvio::cli {
namespace {

struct InspectOptions {
  std::string dataset;
  std::string format = "auto";
  std::optional<std::string> json;
  std::optional<std::string> gnss_file;
  std::vector<std::string> calib;
  bool quick = false;
  ConfigOptions config;
};

// Decodes every image (only the first frame's with --quick) and checks its size.
std::size_t checkImages(const io::Dataset& ds, bool quick, ProgressStyle style) {
  const std::size_t frames = quick ? std::min<std::size_t>(1, ds.frames.size()) : ds.frames.size();
  Progress progress("inspect images", frames, "frames", style);
  std::size_t images = 0;
  for (std::size_t i = 0; i < frames; ++i) {
    for (std::size_t c = 0; c < ds.cameras.size(); ++c) {
      (void)io::loadFrameImage(ds, i, c);
      ++images;
    }
    progress.update(i + 1);
  }
  progress.finish();
  return images;
}

int runInspect(const InspectOptions& opt, const CommonOptions& common) {
  const AppConfig config = opt.config.load();
  io::DatasetSources sources{opt.dataset,
                             io::parseDatasetFormat(opt.format),
                             {opt.calib.begin(), opt.calib.end()},
                             std::nullopt};
  if (opt.gnss_file) sources.gnss_file = *opt.gnss_file;
  sources.require_calibration = false;  // a summary needs no intrinsics
  io::Dataset ds = io::openDataset(sources, config.dataset);
  for (const auto& w : ds.warnings) spdlog::warn("{}", w);
  const std::size_t images = checkImages(ds, opt.quick, common.progressStyle());
  const run::ImuConfig::Choice imu_noise = config.imu.choose(ds.imu_noise);
  auto summary =
      io::summarizeDataset(ds, config.dataset.gap_factor, imu_noise.noise, imu_noise.source);
  summary["images_checked"] = images;
  std::cout << io::formatSummary(summary)
            << fmt::format("images    {} decoded and size-checked{}\n", images,
                           opt.quick ? " (--quick: first frame only)" : "");
  if (opt.json) io::writeTextAtomic(*opt.json, summary.dump(2) + "\n");
  return 0;
}

}  // namespace

Command addInspectCommand(CLI::App& app, const CommonOptions& common) {
  auto opt = std::make_shared<InspectOptions>();
  CLI::App* sub = app.add_subcommand("inspect", "Validate a dataset and summarise its sensors");
  sub->add_option(
         "--dataset", opt->dataset,
         "Dataset folder (KITTI raw drive, EuRoC, comma2k19), ROS 1 bag, ROS 2 bag (folder, .mcap, "
         ".db3) or NMEA log")
      ->required();
  sub->add_option("--format", opt->format, "Dataset format")
      ->check(
          CLI::IsMember({"auto", "kitti-raw", "euroc", "nmea", "comma2k19", "rosbag", "ros2bag"}));
  sub->add_option("--json", opt->json, "Also write the summary as JSON to this file");
  sub->add_option("--calib", opt->calib,
                  "Kalibr calibration replacing the dataset's (camchain.yaml and/or imu.yaml)");
  sub->add_option("--gnss-file", opt->gnss_file,
                  "GNSS fixes from this file instead of the dataset's: NMEA, RTKLIB .pos or CSV");
  sub->add_flag("--quick", opt->quick,
                "Decode only the first frame's images (text files are always fully checked)");
  opt->config.addTo(*sub);
  return {sub, [opt, &common] { return runInspect(*opt, common); }};
}

}  // namespace gvio::cli
