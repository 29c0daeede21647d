#include "io/run_sources.hpp"

#include <string>

#include "io/input_error.hpp"
#include "io/run_dir.hpp"
#include "odometry/error.hpp"

namespace gvio::io {
namespace fs = std::filesystem;
namespace {

std::string absolutePath(const fs::path& p) {
  return fs::absolute(p).lexically_normal().string();
}

// A non-empty string field (a path or a name).
std::string stringField(const nlohmann::json& j, const char* key, const fs::path& file) {
  if (!j.contains(key) || !j[key].is_string() || j[key].get<std::string>().empty()) {
    throw InputError(file, 0, std::string("\"") + key + "\" is not a non-empty string");
  }
  return j[key].get<std::string>();
}

}  // namespace

nlohmann::json sourcesJson(const DatasetSources& sources, DatasetFormat detected) {
  nlohmann::json calib = nlohmann::json::array();
  for (const fs::path& f : sources.calib_files) calib.push_back(absolutePath(f));
  return {{"dataset", absolutePath(sources.dataset)},
          {"format", toString(detected)},
          {"calib_files", calib},
          {"gnss_file", sources.gnss_file ? nlohmann::json(absolutePath(*sources.gnss_file))
                                          : nlohmann::json(nullptr)}};
}

RunSources readRunSources(const fs::path& report_file) {
  const nlohmann::json report = readJsonObject(report_file);
  RunSources run;
  run.mode = stringField(report, "mode", report_file);
  if (!report.contains("sources")) return run;
  const nlohmann::json& j = report["sources"];
  if (!j.is_object()) throw InputError(report_file, 0, "\"sources\" is not an object");
  DatasetSources& s = run.dataset.emplace();
  s.dataset = stringField(j, "dataset", report_file);
  const std::string format = stringField(j, "format", report_file);
  try {
    s.format = parseDatasetFormat(format);
  } catch (const InvalidInput&) {
    s.format.reset();
  }
  if (!s.format) throw InputError(report_file, 0, "unknown \"sources.format\": " + format);
  if (j.contains("calib_files")) {
    if (!j["calib_files"].is_array()) {
      throw InputError(report_file, 0, "\"sources.calib_files\" is not an array");
    }
    for (const auto& f : j["calib_files"]) {
      if (!f.is_string()) throw InputError(report_file, 0, "\"sources.calib_files\": not a path");
      s.calib_files.emplace_back(f.get<std::string>());
    }
  }
  if (j.contains("gnss_file") && !j["gnss_file"].is_null()) {
    s.gnss_file = stringField(j, "gnss_file", report_file);
  }
  return run;
}

}  // namespace gvio::io
