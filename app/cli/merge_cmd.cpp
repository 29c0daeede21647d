// gvio merge: georeferenced runs as one grid of UTM tiles (app/fleet/merge_run.hpp).
#include "cli/app.hpp"
#include "fleet/merge_run.hpp"

namespace gvio::cli {
namespace {

struct MergeCliOptions {
  std::vector<std::string> runs;
  std::string out;
  std::optional<double> tile_size_m;
  ConfigOptions config;
};

int runMergeCommand(const MergeCliOptions& o) {
  fleet::MergeRequest request;
  for (const auto& r : o.runs) request.runs.emplace_back(r);
  request.out_dir = o.out;
  const auto config = o.config.load();
  request.config = config.merge;
  request.loops = config.loops;
  request.fusion = config.fusion.fusionFor(std::nullopt);  // the runs' VIO modes may differ
  if (o.tile_size_m) request.config.tile_size_m = *o.tile_size_m;
  fleet::runMerge(request);
  return 0;
}

}  // namespace

Command addMergeCommand(CLI::App& app) {
  auto o = std::make_shared<MergeCliOptions>();
  CLI::App* sub = app.add_subcommand(
      "merge", "Merge georeferenced runs into UTM tiles: LAS (point source ID = drive), PCD, .bt");
  sub->add_option("--runs", o->runs, "Run folders (gvio run --out), or fleet folders")
      ->required()
      ->expected(1, -1);
  sub->add_option("--out", o->out, "Map folder: tiles/, tiles.json, tiles.geojson, Autoware YAML")
      ->required();
  sub->add_option("--tile-size", o->tile_size_m, "Tile side in metres (default merge.tile_size_m)")
      ->check(CLI::Range(1.0, 10000.0));
  o->config.addTo(*sub);
  return {sub, [o] { return runMergeCommand(*o); }};
}

}  // namespace gvio::cli
