#pragma once
// Interval lists ("t0 t1" per line, seconds), e.g. the GNSS outages shaded in evaluation plots.
#include <cstdint>
#include <filesystem>
#include <utility>
#include <vector>

namespace gvio::io {

// Throws InputError naming file and line for malformed lines, NaN, or t1 <= t0.
std::vector<std::pair<std::int64_t, std::int64_t>> readIntervals(const std::filesystem::path& file);

}  // namespace gvio::io
