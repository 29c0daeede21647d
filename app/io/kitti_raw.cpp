#include "io/kitti_raw.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>

#include "fusion/gnss_screening.hpp"
#include "io/dataset.hpp"
#include "io/input_error.hpp"
#include "io/kitti_calib.hpp"
#include "io/nmea.hpp"
#include "io/text.hpp"
#include "io/trajectory_io.hpp"

namespace gvio::io {
namespace fs = std::filesystem;
namespace {

// Fields of one oxts/data/*.txt record (devkit dataformat.txt, 30 values).
constexpr std::size_t kOxtsFields = 30;
constexpr std::size_t kLat = 0, kLon = 1, kAlt = 2, kAf = 14, kWf = 20, kPosAccuracy = 23,
                      kNumSats = 26;  // 25 is navstat (devkit dataformat.txt)

// timestamps.txt: one "YYYY-MM-DD hh:mm:ss.fffffffff" per line, strictly increasing.
std::vector<std::int64_t> readKittiTimestamps(const fs::path& file) {
  LineReader reader(file);
  std::vector<std::int64_t> stamps;
  std::string line;
  while (reader.next(line)) {
    if (trim(line).empty()) reader.fail("empty line (expected a timestamp)");
    std::int64_t t_ns = 0;
    if (!kittiTimestampToNs(line, t_ns)) reader.fail("malformed timestamp '" + line + "'");
    if (!stamps.empty() && t_ns <= stamps.back()) {
      reader.fail(t_ns == stamps.back() ? "duplicate timestamp" : "timestamp not increasing");
    }
    stamps.push_back(t_ns);
  }
  if (stamps.empty()) throw InputError(file, 0, "no timestamps");
  return stamps;
}

fs::path indexedFile(const fs::path& dir, std::size_t index, const char* ext) {
  return dir / fmt::format("{:010d}{}", index, ext);
}

// The data file of the index-th timestamp must exist. Its error names the line of timestamps.txt
// that lists it too: either file may be the one at fault (found by fuzzing timestamps.txt: a line
// more than the records named only the record).
void requireListed(const fs::path& file, const fs::path& stamps, std::size_t index,
                   const char* what) {
  if (fs::is_regular_file(file)) return;
  throw InputError(
      file, 0,
      fmt::format("{} not found (listed by line {} of {})", what, index + 1, stamps.string()));
}

std::vector<double> readOxtsRecord(const fs::path& file) {
  LineReader reader(file);
  std::string line;
  while (reader.next(line) && trim(line).empty()) {
  }
  if (reader.lineNumber() == 0 || trim(line).empty())
    throw InputError(file, 0, "empty oxts record");
  const auto fields = splitWhitespace(line);
  if (fields.size() != kOxtsFields) {
    reader.fail(fmt::format("expected {} fields, got {}", kOxtsFields, fields.size()));
  }
  std::vector<double> values;
  values.reserve(kOxtsFields);
  for (const auto f : fields) values.push_back(parseFinite(f, reader, "oxts value"));
  return values;
}

std::vector<int> presentCameras(const fs::path& drive_dir) {
  std::vector<int> ids;
  for (int id = 0; id < 4; ++id) {
    if (fs::is_directory(drive_dir / fmt::format("image_{:02d}", id))) ids.push_back(id);
  }
  return ids;
}

// The devkit names drives *_sync (rectified images, 10 Hz oxts) or *_extract (raw images,
// ~100 Hz oxts). Other folder names (the simulator's) are judged by the oxts rate.
std::string driveVariant(const fs::path& drive_dir, const std::vector<std::int64_t>& oxts_t_ns) {
  const std::string name = drive_dir.filename().string();
  if (name.ends_with("_sync")) return "sync";
  if (name.ends_with("_extract")) return "extract";
  if (oxts_t_ns.size() < 2) return "extract";
  const double mean_dt_s = 1e-9 * static_cast<double>(oxts_t_ns.back() - oxts_t_ns.front()) /
                           static_cast<double>(oxts_t_ns.size() - 1);
  return mean_dt_s < 0.05 ? "extract" : "sync";
}

void readFrames(const fs::path& drive_dir, const std::vector<int>& ids, Dataset& ds) {
  std::vector<std::int64_t> t0;
  for (std::size_t k = 0; k < ids.size(); ++k) {
    const fs::path cam_dir = drive_dir / fmt::format("image_{:02d}", ids[k]);
    const auto stamps = readKittiTimestamps(cam_dir / "timestamps.txt");
    if (k == 0) {
      t0 = stamps;
    } else if (stamps.size() != t0.size()) {
      throw InputError(
          cam_dir / "timestamps.txt", 0,
          fmt::format("{} timestamps, but image_{:02d} has {}", stamps.size(), ids[0], t0.size()));
    }
  }
  ds.frames.resize(t0.size());
  for (std::size_t i = 0; i < t0.size(); ++i) {
    ds.frames[i].t_ns = t0[i];  // the stereo pair is triggered together: cam 0 stamps the frame
    for (const int id : ids) {
      const fs::path image =
          indexedFile(drive_dir / fmt::format("image_{:02d}", id) / "data", i, ".png");
      requireListed(image, drive_dir / fmt::format("image_{:02d}", id) / "timestamps.txt", i,
                    "image file");
      ds.frames[i].image_paths.push_back(image);
    }
  }
}

void addOxtsGnss(const std::vector<double>& rec, std::int64_t t_ns, const fs::path& file,
                 std::size_t& skipped, Dataset& ds) {
  // pos_accuracy is the OXTS unit's own north/east position accuracy; it is the only sigma
  // KITTI records, so it serves for the vertical too.
  if (rec[kPosAccuracy] <= 0.0 || fusion::latLonOutOfRange(rec[kLat], rec[kLon])) {
    if (skipped++ == 0) spdlog::debug("{}: unusable GNSS fields, fix skipped", file.string());
    return;
  }
  GnssFix fix;
  fix.t_ns = t_ns;
  fix.lat_deg = rec[kLat];
  fix.lon_deg = rec[kLon];
  fix.h_ellipsoid_m = rec[kAlt];
  fix.sigma_h_m = rec[kPosAccuracy];
  fix.sigma_v_m = rec[kPosAccuracy];
  fix.num_sats = static_cast<int>(rec[kNumSats]);
  ds.gnss.push_back(fix);
}

void readOxts(const fs::path& drive_dir, bool gnss_from_oxts, Dataset& ds) {
  const fs::path oxts_dir = drive_dir / "oxts";
  const auto stamps = readKittiTimestamps(oxts_dir / "timestamps.txt");
  std::size_t skipped_gnss = 0;
  ds.imu.reserve(stamps.size());
  for (std::size_t i = 0; i < stamps.size(); ++i) {
    const fs::path file = indexedFile(oxts_dir / "data", i, ".txt");
    requireListed(file, oxts_dir / "timestamps.txt", i, "file");
    const auto rec = readOxtsRecord(file);
    ImuSample s;
    s.t_ns = stamps[i];
    s.acc_b_mps2 = Eigen::Vector3d(rec[kAf], rec[kAf + 1], rec[kAf + 2]);
    s.gyr_b_radps = Eigen::Vector3d(rec[kWf], rec[kWf + 1], rec[kWf + 2]);
    ds.imu.push_back(s);
    if (gnss_from_oxts) addOxtsGnss(rec, stamps[i], file, skipped_gnss, ds);
  }
  if (skipped_gnss > 0) {
    ds.warnings.push_back(
        fmt::format("{}: {} oxts records with unusable GNSS fields skipped as fixes",
                    oxts_dir.string(), skipped_gnss));
  }
  if (gnss_from_oxts) ds.gnss_source = (oxts_dir / "data").string();
}

}  // namespace

bool looksLikeKittiRaw(const fs::path& dir) {
  return fs::is_regular_file(dir / "oxts" / "timestamps.txt") ||
         fs::is_regular_file(dir / "image_00" / "timestamps.txt");
}

Dataset readKittiRaw(const fs::path& drive_dir, const ReaderConfig& config) {
  if (!fs::is_directory(drive_dir)) throw InputError(drive_dir, 0, "dataset folder not found");
  Dataset ds;
  ds.format = DatasetFormat::kKittiRaw;
  ds.root = drive_dir;
  const fs::path nmea = drive_dir / "gnss" / "fixes.nmea";
  const bool use_nmea = config.kitti_gnss_source == "nmea" ||
                        (config.kitti_gnss_source == "auto" && fs::is_regular_file(nmea));
  const bool has_oxts = fs::is_directory(drive_dir / "oxts");
  if (has_oxts) readOxts(drive_dir, !use_nmea, ds);
  std::vector<std::int64_t> oxts_t_ns;
  for (const auto& s : ds.imu) oxts_t_ns.push_back(s.t_ns);
  ds.variant = driveVariant(drive_dir, oxts_t_ns);

  const auto ids = presentCameras(drive_dir);
  if (ids.empty() && !has_oxts) {
    throw InputError(drive_dir, 0, "no image_0X/ nor oxts/ folder: not a KITTI raw drive");
  }
  if (!ids.empty()) {
    const KittiCalibPaths calib = findKittiCalib(drive_dir);
    ds.cameras = readKittiCameras(calib, ids, ds.variant == "sync");
    readFrames(drive_dir, ids, ds);
    checkFirstImageSizes(ds, std::vector<fs::path>(ds.cameras.size(), calib.cam_to_cam));
  }
  if (use_nmea) {
    NmeaLog log = readNmea(nmea, config);
    ds.gnss = std::move(log.fixes);
    ds.gnss_source = nmea.string();
    ds.warnings.insert(ds.warnings.end(), log.warnings.begin(), log.warnings.end());
  }
  if (has_oxts && ds.variant == "sync") {
    ds.warnings.push_back(fmt::format(
        "{}: oxts at ~10 Hz (sync drive): too slow for IMU preintegration, use stereo-only VIO",
        (drive_dir / "oxts").string()));
  }
  const fs::path gt = drive_dir / "groundtruth.tum";
  if (fs::is_regular_file(gt)) {
    ds.groundtruth = readTum(gt);
    ds.groundtruth_source = gt.string();
  }
  return ds;
}

}  // namespace gvio::io
