#pragma once
// Line-oriented text parsing shared by every reader: line numbers for error messages, strict
// number parsing that rejects NaN/inf and trailing garbage.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

namespace gvio::io {

// Reads a text file line by line, stripping '\r', counting lines from 1.
class LineReader {
 public:
  explicit LineReader(const std::filesystem::path& file);  // throws InputError if unreadable

  bool next(std::string& line);  // false at end of file
  [[nodiscard]] std::size_t lineNumber() const { return line_number_; }
  [[nodiscard]] const std::filesystem::path& path() const { return path_; }

  // Throws InputError for the current line.
  [[noreturn]] void fail(const std::string& message) const;

 private:
  std::filesystem::path path_;
  std::ifstream in_;
  std::size_t line_number_ = 0;
};

std::string_view trim(std::string_view s);

// True when the file's first bytes are `prefix` (format detection by magic number); false for a
// file that cannot be read or is shorter.
bool fileStartsWith(const std::filesystem::path& file, std::string_view prefix);
bool isBlankOrComment(std::string_view line, char comment = '#');

// Splits on a single delimiter character, trimming each field.
std::vector<std::string_view> splitDelimited(std::string_view line, char delim);
// The index of the column called `name` in a CSV header (read by column name, so that columns a
// later writer adds are simply ignored); fails at `at`'s line, naming the column and, when given,
// the expected header.
std::size_t columnIndex(const std::vector<std::string>& header, std::string_view name,
                        const LineReader& at, std::string_view expected = {});
// Splits on runs of spaces/tabs.
std::vector<std::string_view> splitWhitespace(std::string_view line);

// Strict parsers: the whole token must be a finite number. They throw InputError via `at`.
double parseFinite(std::string_view token, const LineReader& at, std::string_view what);
std::int64_t parseInt64(std::string_view token, const LineReader& at, std::string_view what);

// Decimal seconds ("1403715273.262142976", "-0.5", "1.037359e-01") to integer nanoseconds,
// exact for plain decimals (no detour through double), rounded for exponent notation.
// Returns false when the token is not a finite number.
bool secondsToNs(std::string_view token, std::int64_t& t_ns);
std::int64_t parseSecondsNs(std::string_view token, const LineReader& at, std::string_view what);

// "YYYY-MM-DD hh:mm:ss.fffffffff" (KITTI raw timestamps.txt) as UTC nanoseconds since the epoch.
bool kittiTimestampToNs(std::string_view text, std::int64_t& t_ns);

// Days since 1970-01-01 of a proleptic Gregorian date (H. Hinnant's days_from_civil).
std::int64_t daysFromCivil(int year, unsigned month, unsigned day);

struct CivilDate {
  int year = 1970;
  unsigned month = 1, day = 1;
};
// The inverse (H. Hinnant's civil_from_days).
CivilDate civilFromDays(std::int64_t days);

// UTC nanoseconds as KITTI writes timestamps.txt: "YYYY-MM-DD hh:mm:ss.fffffffff".
std::string formatKittiTimestamp(std::int64_t t_ns);

// Nanoseconds as decimal seconds with 9 fractional digits, exact.
std::string formatSeconds(std::int64_t t_ns);

}  // namespace gvio::io
