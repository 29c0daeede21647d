#pragma once
// `gvio export`: one file of a run folder (DESIGN.md section 4) in the asked format.
//   pcd, ply       the map cloud (map.pcd, else map.ply), every field, ENU float32 as in the run
//   3dtiles        the map cloud as OGC 3D Tiles (a folder: tileset.json + tiles/*.pnts, ECEF;
//                  export/tiles3d_writer.hpp), needs georef.json
//   las            the map cloud in UTM (zone of the ENU origin) + ellipsoidal height, needs
//                  georef.json
//   bt, ot         map.bt / map.ot, read with OctoMap and written again
//   tum, kitti,    trajectory.tum (body in ENU); falls back to trajectory_vio.tum (VIO world
//   euroc          frame, not georeferenced) with a warning; kitti also writes <stem>_times.txt
//   geojson, kml,  trajectory.tum in WGS 84 through georef.json's ENU origin
//   gpx
// A merged map exports to 3dtiles only: fleet/merged_tiles3d.hpp.
#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace gvio::exporter {

enum class ExportFormat {
  kPcd,
  kPly,
  kLas,
  k3dTiles,
  kBt,
  kOt,
  kTum,
  kKitti,
  kEuroc,
  kGeoJson,
  kKml,
  kGpx
};

std::optional<ExportFormat> parseExportFormat(std::string_view name);
std::string toString(ExportFormat format);
// "pcd, ply, las, 3dtiles, bt, ot, tum, kitti, euroc, geojson, kml, gpx"
std::string exportFormatList();
// The file extension, with the dot (".txt" for KITTI poses, ".csv" for EuRoC).
std::string extension(ExportFormat format);
// DIR/export.<ext> (DIR/3dtiles/ for 3D Tiles, a folder): never one of the run's own files, so
// exporting cannot overwrite its input.
std::filesystem::path defaultExportPath(const std::filesystem::path& run_dir, ExportFormat format);
// The KITTI times file written beside `poses`: <stem>_times.txt.
std::filesystem::path kittiTimesPath(const std::filesystem::path& poses);

struct ExportResult {
  std::vector<std::filesystem::path> written;  // the output, then any companion (KITTI times)
  std::filesystem::path source;                // the run file it came from
  std::size_t count = 0;                       // points, tree nodes or poses written
  std::string what;                            // "points", "nodes", "poses"
};

// Throws InputError naming the offending file (run folder missing, input file missing or
// malformed, empty map, output folder missing or unwritable).
ExportResult exportRun(const std::filesystem::path& run_dir, ExportFormat format,
                       const std::filesystem::path& out);

}  // namespace gvio::exporter
