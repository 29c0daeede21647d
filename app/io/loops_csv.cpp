#include "io/loops_csv.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <climits>
#include <cmath>
#include <stdexcept>

#include "io/atomic_write.hpp"
#include "io/input_error.hpp"
#include "io/text.hpp"

namespace gvio::io {
namespace {

constexpr std::size_t kFields = 11;

bool isReasonToken(std::string_view s) {
  return !s.empty() &&
         std::all_of(s.begin(), s.end(), [](char c) { return (c >= 'a' && c <= 'z') || c == '_'; });
}

// "nan" stands for a quantity that was not measured, whatever its sign bit.
std::string formatQuantity(double v) {
  return std::isfinite(v) ? fmt::format("{:.6f}", v) : std::string("nan");
}

// The writer's "nan", and the spellings Python and pandas write for it ("NaN", "-nan").
bool isNanToken(std::string_view s) {
  if (!s.empty() && (s.front() == '-' || s.front() == '+')) s.remove_prefix(1);
  return s.size() == 3 && std::tolower(static_cast<unsigned char>(s[0])) == 'n' &&
         std::tolower(static_cast<unsigned char>(s[1])) == 'a' &&
         std::tolower(static_cast<unsigned char>(s[2])) == 'n';
}

double parseQuantity(std::string_view token, const LineReader& at, std::string_view what) {
  if (isNanToken(token)) return LoopCsvRow::kNaN;
  return parseFinite(token, at, what);
}

int parseCount(std::string_view token, const LineReader& at, std::string_view what) {
  const std::int64_t v = parseInt64(token, at, what);
  if (v < 0) at.fail(fmt::format("negative {} '{}'", what, token));
  if (v > INT_MAX) at.fail(fmt::format("{} '{}' is too large", what, token));
  return static_cast<int>(v);
}

// The reason must agree with the verdict: "ok" for an accepted loop and only for one.
void checkReason(const LoopCsvRow& row, const LineReader& at) {
  if (!isReasonToken(row.reason)) {
    at.fail(fmt::format("reason '{}': expected a token of a-z and _", row.reason));
  }
  if (row.accepted != (row.reason == "ok")) {
    at.fail(row.accepted ? fmt::format("accepted loop with reason '{}' (expected ok)", row.reason)
                         : std::string("rejected loop with reason 'ok'"));
  }
}

LoopCsvRow parseRow(const std::vector<std::string_view>& f, const LineReader& in) {
  LoopCsvRow r;
  r.query_t_ns = parseSecondsNs(f[0], in, "query_t_s");
  r.candidate_t_ns = parseSecondsNs(f[1], in, "candidate_t_s");
  r.distance_m = parseQuantity(f[2], in, "distance_m");
  r.search_radius_m = parseQuantity(f[3], in, "search_radius_m");
  r.matches = parseCount(f[4], in, "matches");
  r.inliers = parseCount(f[5], in, "inliers");
  r.reprojection_px = parseQuantity(f[6], in, "reprojection_px");
  r.correction_m = parseQuantity(f[7], in, "correction_m");
  r.correction_deg = parseQuantity(f[8], in, "correction_deg");
  if (f[9] != "accepted" && f[9] != "rejected") {
    in.fail(fmt::format("verdict '{}': expected accepted or rejected", f[9]));
  }
  r.accepted = f[9] == "accepted";
  r.reason = std::string(f[10]);
  checkReason(r, in);
  return r;
}

}  // namespace

std::string loopsCsvLine(const LoopCsvRow& r) {
  if (r.matches < 0 || r.inliers < 0 || !isReasonToken(r.reason) ||
      r.accepted != (r.reason == "ok")) {
    throw std::invalid_argument(
        fmt::format("loop {} -> {}: negative count or reason '{}' not valid for its verdict",
                    formatSeconds(r.query_t_ns), formatSeconds(r.candidate_t_ns), r.reason));
  }
  return fmt::format("{},{},{},{},{},{},{},{},{},{},{}", formatSeconds(r.query_t_ns),
                     formatSeconds(r.candidate_t_ns), formatQuantity(r.distance_m),
                     formatQuantity(r.search_radius_m), r.matches, r.inliers,
                     formatQuantity(r.reprojection_px), formatQuantity(r.correction_m),
                     formatQuantity(r.correction_deg), r.accepted ? "accepted" : "rejected",
                     r.reason);
}

void writeLoopsCsv(const std::filesystem::path& file, const std::vector<LoopCsvRow>& rows) {
  std::string text(kLoopsCsvHeader);
  text += '\n';
  for (const LoopCsvRow& r : rows) {
    try {
      text += loopsCsvLine(r) + '\n';
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(file.string() + ": " + e.what());
    }
  }
  writeTextAtomic(file, text);
}

std::vector<LoopCsvRow> readLoopsCsv(const std::filesystem::path& file) {
  LineReader in(file);
  std::string line;
  if (!in.next(line)) in.fail(fmt::format("empty file, expected the header {}", kLoopsCsvHeader));
  if (trim(line) != kLoopsCsvHeader) {
    in.fail(fmt::format("header '{}': expected {}", trim(line), kLoopsCsvHeader));
  }
  std::vector<LoopCsvRow> rows;
  while (in.next(line)) {
    if (trim(line).empty()) continue;
    const auto f = splitDelimited(line, ',');
    if (f.size() != kFields) {
      in.fail(fmt::format("expected {} fields, got {}", kFields, f.size()));
    }
    rows.push_back(parseRow(f, in));
  }
  return rows;
}

}  // namespace gvio::io
