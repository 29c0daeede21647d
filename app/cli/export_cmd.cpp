// gvio export: one file of a run folder in another format (app/export/run_export.hpp).
#include <spdlog/spdlog.h>

#include "cli/app.hpp"
#include "export/run_export.hpp"
#include "fleet/merged_map.hpp"
#include "fleet/merged_tiles3d.hpp"
#include "io/run_dir.hpp"
#include "odometry/error.hpp"

namespace gvio::cli {
namespace {

struct ExportCliOptions {
  std::string run, to;
  std::optional<std::string> out;
};

int runExport(const ExportCliOptions& o) {
  // Checked here rather than with CLI11's IsMember, whose failure message takes two lines.
  const auto format = exporter::parseExportFormat(o.to);
  if (!format) {
    throw InvalidInput("--to '" + o.to + "': unknown format; one of " +
                       exporter::exportFormatList());
  }
  const std::filesystem::path out =
      o.out ? std::filesystem::path(*o.out) : exporter::defaultExportPath(o.run, *format);
  if (fleet::isMergedMap(o.run)) {
    if (*format != exporter::ExportFormat::k3dTiles) {
      throw InvalidInput("--run " + o.run +
                         " is a merged map: its tiles are LAS and PCD already; it exports --to "
                         "3dtiles");
    }
    const exporter::Tiles3dSummary s = fleet::exportMergedTiles3d(o.run, out);
    spdlog::info("wrote {}: {} points in {} tiles, {} levels", out.string(), s.points, s.tiles,
                 s.depth + 1);
    return 0;
  }
  if (const auto warning = io::incompleteRunWarning(o.run)) spdlog::warn("{}", *warning);
  const exporter::ExportResult r = exporter::exportRun(o.run, *format, out);
  for (const auto& file : r.written) spdlog::info("wrote {}", file.string());
  spdlog::info("{} {} from {}", r.count, r.what, r.source.string());
  return 0;
}

}  // namespace

Command addExportCommand(CLI::App& app) {
  auto o = std::make_shared<ExportCliOptions>();
  CLI::App* sub = app.add_subcommand(
      "export",
      "Write a run's map or trajectory as PCD, PLY, LAS, 3D Tiles, OctoMap, TUM/KITTI/EuRoC "
      "or GeoJSON/KML/GPX");
  sub->add_option("--run", o->run, "Run folder (the --out of gvio run), or a merged map (3dtiles)")
      ->required();
  sub->add_option("--to", o->to, exporter::exportFormatList())->required();
  sub->add_option("--out", o->out,
                  "Output file, a folder for 3dtiles (default: RUN/export.<ext>, RUN/3dtiles)");
  return {sub, [o] { return runExport(*o); }};
}

}  // namespace gvio::cli
