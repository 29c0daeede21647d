#pragma once
// report.json "sources": where a run's inputs came from (absolute paths, the dataset's format as
// detected), so that commands needing the recorded images (`gvio render --view camera`) reopen
// the dataset exactly as the run did: same reader, same calibration files, same rectification.
#include <filesystem>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "io/dataset.hpp"
#include "io/dataset_sources.hpp"

namespace gvio::io {

// {"dataset", "format", "calib_files", "gnss_file"}; relative paths made absolute.
nlohmann::json sourcesJson(const DatasetSources& sources, DatasetFormat detected);

struct RunSources {
  std::optional<DatasetSources> dataset;  // nullopt: the report has no "sources" (older gvio)
  std::string mode;  // report.json "mode": which cameras the run rectified together
};

// The sources and VIO mode of the run whose report is `report_file`. Throws InputError naming the
// file when it is not a VIO run's report or its "sources" are malformed.
RunSources readRunSources(const std::filesystem::path& report_file);

}  // namespace gvio::io
