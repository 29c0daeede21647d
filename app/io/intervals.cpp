#include "io/intervals.hpp"

#include "io/text.hpp"

namespace gvio::io {

std::vector<std::pair<std::int64_t, std::int64_t>> readIntervals(
    const std::filesystem::path& file) {
  LineReader reader(file);
  std::vector<std::pair<std::int64_t, std::int64_t>> intervals;
  std::string line;
  while (reader.next(line)) {
    if (isBlankOrComment(line)) continue;
    const auto f = splitWhitespace(line);
    if (f.size() != 2)
      reader.fail("expected 't0 t1' (seconds), got " + std::to_string(f.size()) + " fields");
    const std::int64_t t0 = parseSecondsNs(f[0], reader, "interval start");
    const std::int64_t t1 = parseSecondsNs(f[1], reader, "interval end");
    if (t1 <= t0) reader.fail("interval end must be after its start");
    intervals.emplace_back(t0, t1);
  }
  return intervals;
}

}  // namespace gvio::io
