#include "io/gnss_file.hpp"

#include <fmt/format.h>

#include <algorithm>

#include "io/euroc.hpp"
#include "io/input_error.hpp"
#include "io/nmea.hpp"
#include "io/rtklib_pos.hpp"
#include "io/text.hpp"

namespace gvio::io {
namespace {

char firstCharacter(const std::filesystem::path& file) {
  LineReader in(file);
  std::string line;
  while (in.next(line)) {
    const std::string_view text = trim(line);
    if (!text.empty()) return text.front();
  }
  throw InputError(file, 0, "empty GNSS file");
}

}  // namespace

GnssFileData readGnssFile(const std::filesystem::path& file, const ReaderConfig& config) {
  GnssFileData out;
  const char first = firstCharacter(file);
  if (first == '$') {
    NmeaLog log = readNmea(file, config);
    out.fixes = std::move(log.fixes);
    out.warnings = std::move(log.warnings);
    out.format = "nmea";
  } else if (first == '%') {
    PosFile pos = readRtklibPos(file, config);
    out.fixes = std::move(pos.fixes);
    out.warnings = std::move(pos.warnings);
    out.format = "rtklib-pos";
  } else {
    out.fixes = readGnssCsv(file, out.warnings);
    out.format = "csv";
  }
  return out;
}

void useGnssFile(Dataset& ds, const std::filesystem::path& file, const ReaderConfig& config) {
  GnssFileData data = readGnssFile(file, config);
  for (auto& w : data.warnings) ds.warnings.push_back(std::move(w));
  std::int64_t t0 = 0, t1 = -1;
  if (!ds.frames.empty()) {
    t0 = ds.frames.front().t_ns;
    t1 = ds.frames.back().t_ns;
  } else if (!ds.imu.empty()) {
    t0 = ds.imu.front().t_ns;
    t1 = ds.imu.back().t_ns;
  }
  const auto inside = std::count_if(data.fixes.begin(), data.fixes.end(),
                                    [&](const GnssFix& f) { return f.t_ns >= t0 && f.t_ns <= t1; });
  if (t1 >= t0 && !data.fixes.empty() && inside == 0) {
    ds.warnings.push_back(fmt::format(
        "{}: none of its {} fixes ({} .. {}) falls within the dataset ({} .. {}): are both clocks "
        "UTC?",
        file.string(), data.fixes.size(), formatKittiTimestamp(data.fixes.front().t_ns),
        formatKittiTimestamp(data.fixes.back().t_ns), formatKittiTimestamp(t0),
        formatKittiTimestamp(t1)));
  }
  ds.gnss = std::move(data.fixes);
  ds.gnss_source = file.string();
}

}  // namespace gvio::io
