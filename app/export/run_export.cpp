#include "export/run_export.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <array>

#include "export/geo_tracks.hpp"
#include "export/georef.hpp"
#include "export/las_writer.hpp"
#include "export/map_files.hpp"
#include "export/tiles3d_writer.hpp"
#include "fusion/geodesy.hpp"
#include "io/input_error.hpp"
#include "io/trajectory_io.hpp"

namespace gvio::exporter {
namespace {
namespace fs = std::filesystem;

struct FormatInfo {
  ExportFormat format;
  std::string_view name, extension;
};

constexpr std::array<FormatInfo, 12> kFormats = {{{ExportFormat::kPcd, "pcd", ".pcd"},
                                                  {ExportFormat::kPly, "ply", ".ply"},
                                                  {ExportFormat::kLas, "las", ".las"},
                                                  {ExportFormat::k3dTiles, "3dtiles", ""},
                                                  {ExportFormat::kBt, "bt", ".bt"},
                                                  {ExportFormat::kOt, "ot", ".ot"},
                                                  {ExportFormat::kTum, "tum", ".tum"},
                                                  {ExportFormat::kKitti, "kitti", ".txt"},
                                                  {ExportFormat::kEuroc, "euroc", ".csv"},
                                                  {ExportFormat::kGeoJson, "geojson", ".geojson"},
                                                  {ExportFormat::kKml, "kml", ".kml"},
                                                  {ExportFormat::kGpx, "gpx", ".gpx"}}};

const FormatInfo& info(ExportFormat format) {
  for (const auto& f : kFormats) {
    if (f.format == format) return f;
  }
  return kFormats.front();
}

constexpr const char* kMadeByRun = "written by `gvio run`";
constexpr const char* kMadeByGnss = "written by `gvio run` when GNSS fusion registers the drive";

fs::path requireFile(const fs::path& file, const std::string& made_by) {
  if (!fs::exists(file)) throw io::InputError(file, 0, "not found (" + made_by + ")");
  return file;
}

fs::path mapCloudFile(const fs::path& run) {
  if (fs::exists(run / "map.pcd")) return run / "map.pcd";
  if (fs::exists(run / "map.ply")) return run / "map.ply";
  throw io::InputError(run / "map.pcd", 0,
                       std::string("not found, nor map.ply (") + kMadeByRun + " with mapping)");
}

// The run folder's name ("run" for "out/run/"), for track names.
std::string runName(const fs::path& run) {
  const fs::path dir = fs::absolute(run).lexically_normal();
  return (dir.has_filename() ? dir : dir.parent_path()).filename().string();
}

Trajectory readPoses(const fs::path& file) {
  Trajectory t = io::readTum(file);
  if (t.empty()) throw io::InputError(file, 0, "no poses");
  return t;
}

ExportResult exportTrajectory(const fs::path& run, ExportFormat format, const fs::path& out) {
  ExportResult r;
  r.source = run / "trajectory.tum";
  if (!fs::exists(r.source) && fs::exists(run / "trajectory_vio.tum")) {
    r.source = run / "trajectory_vio.tum";
    spdlog::warn(
        "{}: no trajectory.tum; exporting trajectory_vio.tum, which is in the VIO world "
        "frame, not georeferenced",
        run.string());
  }
  const Trajectory traj = readPoses(requireFile(r.source, kMadeByRun));
  const auto trajectory_format = format == ExportFormat::kTum     ? io::TrajectoryFormat::kTum
                                 : format == ExportFormat::kKitti ? io::TrajectoryFormat::kKitti
                                                                  : io::TrajectoryFormat::kEuroc;
  io::writeTrajectory(out, traj, trajectory_format);
  r.written.push_back(out);
  if (format == ExportFormat::kKitti) {
    io::writeKittiTimes(kittiTimesPath(out), traj);
    r.written.push_back(kittiTimesPath(out));
  }
  r.count = traj.size();
  r.what = "poses";
  return r;
}

ExportResult exportTrack(const fs::path& run, ExportFormat format, const fs::path& out) {
  ExportResult r;
  r.source = requireFile(run / "trajectory.tum", kMadeByGnss);
  const Georef georef = readGeoref(requireFile(run / "georef.json", kMadeByGnss));
  const Trajectory traj = readPoses(r.source);
  const fusion::EnuFrame enu(georef.enu_origin);
  std::vector<TrackPoint> track;
  track.reserve(traj.size());
  for (std::size_t k = 0; k < traj.size(); ++k) {
    track.push_back({traj.t_ns[k], enu.toLla(traj.poses[k].translation())});
  }
  const TrackFormat track_format = format == ExportFormat::kGeoJson ? TrackFormat::kGeoJson
                                   : format == ExportFormat::kKml   ? TrackFormat::kKml
                                                                    : TrackFormat::kGpx;
  writeTrack(out, track, track_format, "gvio " + runName(run));
  r.written.push_back(out);
  r.count = track.size();
  r.what = "poses";
  return r;
}

// The cloud's finite points with LAS's intensity and point source (the drive) scaling.
std::vector<TilesPoint> tilesPoints(const pcl::PCLPointCloud2& cloud, const fs::path& source) {
  const LasPointAt point_at = lasPointSource(cloud);
  const std::size_t n = static_cast<std::size_t>(cloud.width) * cloud.height;
  std::vector<TilesPoint> points;
  points.reserve(n);
  for (std::size_t k = 0; k < n; ++k) {
    if (const std::optional<LasPoint> p = point_at(k)) {
      points.push_back({p->p_enu, p->intensity, p->point_source_id});
    }
  }
  if (points.empty()) throw io::InputError(source, 0, "the map has no finite point");
  return points;
}

ExportResult exportCloud(const fs::path& run, ExportFormat format, const fs::path& out) {
  ExportResult r;
  r.source = mapCloudFile(run);
  const pcl::PCLPointCloud2 cloud = readPointCloud2(r.source);
  r.what = "points";
  if (format == ExportFormat::kLas) {
    const Georef georef = readGeoref(requireFile(run / "georef.json", kMadeByGnss));
    r.count = writeMapLas(out, cloud, georef, r.source).points;
  } else if (format == ExportFormat::k3dTiles) {
    const Georef georef = readGeoref(requireFile(run / "georef.json", kMadeByGnss));
    const Tiles3dSummary s = writeTiles3d(out, georef.enu_origin, tilesPoints(cloud, r.source));
    r.count = s.points;
    r.what = fmt::format("points in {} tiles, {} levels", s.tiles, s.depth + 1);
  } else {
    if (format == ExportFormat::kPcd) writePcd(out, cloud);
    if (format == ExportFormat::kPly) writePly(out, cloud);
    r.count = static_cast<std::size_t>(cloud.width) * cloud.height;
  }
  r.written.push_back(out);
  return r;
}

ExportResult exportOctree(const fs::path& run, ExportFormat format, const fs::path& out) {
  ExportResult r;
  const bool binary = format == ExportFormat::kBt;
  r.source =
      requireFile(run / (binary ? "map.bt" : "map.ot"), std::string(kMadeByRun) + " with mapping");
  const OctreeSummary s = binary ? copyOctreeBinary(r.source, out) : copyOctreeFull(r.source, out);
  r.written.push_back(out);
  r.count = s.nodes;
  r.what = s.type + " nodes";
  return r;
}

void checkOutput(const fs::path& out, ExportFormat format) {
  if (fs::is_directory(out) && format != ExportFormat::k3dTiles)
    throw io::InputError(out, 0, "is a folder; --out names a file");
  const fs::path parent = fs::absolute(out).parent_path();
  if (!fs::is_directory(parent)) throw io::InputError(out, 0, "output folder does not exist");
}

}  // namespace

std::optional<ExportFormat> parseExportFormat(std::string_view name) {
  for (const auto& f : kFormats) {
    if (f.name == name) return f.format;
  }
  return std::nullopt;
}

std::string toString(ExportFormat format) {
  return std::string(info(format).name);
}

std::string exportFormatList() {
  std::string list;
  for (const auto& f : kFormats) list += (list.empty() ? "" : ", ") + std::string(f.name);
  return list;
}

std::string extension(ExportFormat format) {
  return std::string(info(format).extension);
}

fs::path defaultExportPath(const fs::path& run_dir, ExportFormat format) {
  if (format == ExportFormat::k3dTiles) return run_dir / "3dtiles";
  return run_dir / ("export" + extension(format));
}

fs::path kittiTimesPath(const fs::path& poses) {
  return poses.parent_path() / (poses.stem().string() + "_times.txt");
}

ExportResult exportRun(const fs::path& run_dir, ExportFormat format, const fs::path& out_arg) {
  if (!fs::is_directory(run_dir)) throw io::InputError(run_dir, 0, "run folder not found");
  // A folder given as "tiles/" is the folder "tiles".
  const fs::path out =
      format == ExportFormat::k3dTiles && !out_arg.has_filename() ? out_arg.parent_path() : out_arg;
  checkOutput(out, format);
  switch (format) {
    case ExportFormat::kPcd:
    case ExportFormat::kPly:
    case ExportFormat::kLas:
    case ExportFormat::k3dTiles:
      return exportCloud(run_dir, format, out);
    case ExportFormat::kBt:
    case ExportFormat::kOt:
      return exportOctree(run_dir, format, out);
    case ExportFormat::kTum:
    case ExportFormat::kKitti:
    case ExportFormat::kEuroc:
      return exportTrajectory(run_dir, format, out);
    case ExportFormat::kGeoJson:
    case ExportFormat::kKml:
    case ExportFormat::kGpx:
      return exportTrack(run_dir, format, out);
  }
  throw std::logic_error("unhandled export format");
}

}  // namespace gvio::exporter
