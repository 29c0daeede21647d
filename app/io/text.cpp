#include "io/text.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>

#include "io/input_error.hpp"

namespace gvio::io {

namespace {

// The user sees one line: control characters quoted from the input (a parser's "unknown escape
// character" names the byte it met) are written as escapes.
std::string oneLine(const std::string& message) {
  std::string out;
  out.reserve(message.size());
  for (const char c : message) {
    const auto byte = static_cast<unsigned char>(c);
    if (byte == '\n') {
      out += "\\n";
    } else if (byte == '\r') {
      out += "\\r";
    } else if (byte < 0x20 || byte == 0x7F) {
      out += fmt::format("\\x{:02x}", byte);
    } else {
      out += c;
    }
  }
  return out;
}

}  // namespace

InputError::InputError(const std::filesystem::path& file, std::size_t line,
                       const std::string& message)
    : InvalidInput(file.string() + (line > 0 ? ":" + std::to_string(line) : std::string()) + ": " +
                   oneLine(message)) {}

LineReader::LineReader(const std::filesystem::path& file) : path_(file) {
  std::error_code ec;
  if (!std::filesystem::exists(file, ec)) throw InputError(file, 0, "file not found");
  if (std::filesystem::is_directory(file, ec))
    throw InputError(file, 0, "is a directory, expected a file");
  in_.open(file);
  if (!in_) throw InputError(file, 0, "cannot open for reading");
}

bool LineReader::next(std::string& line) {
  if (!std::getline(in_, line)) {
    if (in_.bad()) throw InputError(path_, line_number_ + 1, "read error");
    return false;
  }
  ++line_number_;
  if (!line.empty() && line.back() == '\r') line.pop_back();
  return true;
}

void LineReader::fail(const std::string& message) const {
  throw InputError(path_, line_number_, message);
}

bool fileStartsWith(const std::filesystem::path& file, std::string_view prefix) {
  std::ifstream in(file, std::ios::binary);
  std::string head(prefix.size(), '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  return in.gcount() == static_cast<std::streamsize>(head.size()) && head == prefix;
}

std::string_view trim(std::string_view s) {
  const auto first = s.find_first_not_of(" \t");
  if (first == std::string_view::npos) return {};
  const auto last = s.find_last_not_of(" \t");
  return s.substr(first, last - first + 1);
}

bool isBlankOrComment(std::string_view line, char comment) {
  const auto t = trim(line);
  return t.empty() || t.front() == comment;
}

std::vector<std::string_view> splitDelimited(std::string_view line, char delim) {
  std::vector<std::string_view> fields;
  std::size_t start = 0;
  while (true) {
    const auto pos = line.find(delim, start);
    fields.push_back(trim(line.substr(start, pos == std::string_view::npos ? pos : pos - start)));
    if (pos == std::string_view::npos) break;
    start = pos + 1;
  }
  return fields;
}

std::size_t columnIndex(const std::vector<std::string>& header, std::string_view name,
                        const LineReader& at, std::string_view expected) {
  const auto it = std::find(header.begin(), header.end(), name);
  if (it == header.end()) {
    std::string message = "header has no column '" + std::string(name) + "'";
    if (!expected.empty()) message += " (expected " + std::string(expected) + ")";
    at.fail(message);
  }
  return static_cast<std::size_t>(it - header.begin());
}

std::vector<std::string_view> splitWhitespace(std::string_view line) {
  std::vector<std::string_view> fields;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    const std::size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
    if (i > start) fields.push_back(line.substr(start, i - start));
  }
  return fields;
}

double parseFinite(std::string_view token, const LineReader& at, std::string_view what) {
  double value = 0.0;
  const char* end = token.data() + token.size();
  // from_chars rejects a leading '+', which some writers emit.
  const char* begin = (!token.empty() && token.front() == '+') ? token.data() + 1 : token.data();
  const auto [ptr, ec] = std::from_chars(begin, end, value);
  if (token.empty() || ec != std::errc() || ptr != end) {
    at.fail("malformed " + std::string(what) + " '" + std::string(token) + "'");
  }
  if (!std::isfinite(value))
    at.fail("non-finite " + std::string(what) + " '" + std::string(token) + "'");
  return value;
}

std::int64_t parseInt64(std::string_view token, const LineReader& at, std::string_view what) {
  std::int64_t value = 0;
  const char* end = token.data() + token.size();
  const auto [ptr, ec] = std::from_chars(token.data(), end, value);
  if (token.empty() || ec != std::errc() || ptr != end) {
    at.fail("malformed " + std::string(what) + " '" + std::string(token) +
            "' (expected an integer)");
  }
  return value;
}

bool secondsToNs(std::string_view token, std::int64_t& t_ns) {
  if (token.empty()) return false;
  if (token.find_first_of("eE") != std::string_view::npos) {
    double seconds = 0.0;
    const auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), seconds);
    if (ec != std::errc() || ptr != token.data() + token.size() || !std::isfinite(seconds) ||
        std::abs(seconds) > 9.2e9) {
      return false;
    }
    t_ns = std::llround(seconds * 1e9);
    return true;
  }
  std::size_t i = 0;
  const bool negative = token[0] == '-';
  if (token[0] == '-' || token[0] == '+') i = 1;
  std::int64_t whole = 0;
  std::size_t digits = 0;
  for (; i < token.size() && token[i] != '.'; ++i, ++digits) {
    if (token[i] < '0' || token[i] > '9' || whole > 9'200'000'000LL) return false;
    whole = whole * 10 + (token[i] - '0');
  }
  std::int64_t frac_ns = 0;
  int frac_digits = 0;
  bool round_up = false;
  if (i < token.size()) {  // token[i] == '.'
    for (++i; i < token.size(); ++i, ++digits) {
      if (token[i] < '0' || token[i] > '9') return false;
      if (frac_digits < 9) {
        frac_ns = frac_ns * 10 + (token[i] - '0');
        ++frac_digits;
      } else if (frac_digits == 9) {
        round_up = token[i] >= '5';  // round half up on the 10th digit
        ++frac_digits;
      }
    }
  }
  // int64 nanoseconds reach 9.22e9 s (year 2262); anything beyond cannot be represented.
  if (digits == 0 || whole > 9'200'000'000LL) return false;
  for (int d = std::min(frac_digits, 9); d < 9; ++d) frac_ns *= 10;
  const std::int64_t magnitude = whole * 1'000'000'000LL + frac_ns + (round_up ? 1 : 0);
  t_ns = negative ? -magnitude : magnitude;
  return true;
}

std::int64_t parseSecondsNs(std::string_view token, const LineReader& at, std::string_view what) {
  std::int64_t t_ns = 0;
  if (!secondsToNs(token, t_ns)) {
    at.fail("malformed " + std::string(what) + " '" + std::string(token) + "'");
  }
  return t_ns;
}

std::int64_t daysFromCivil(int year, unsigned month, unsigned day) {
  year -= month <= 2 ? 1 : 0;
  const int era = (year >= 0 ? year : year - 399) / 400;
  const auto yoe = static_cast<unsigned>(year - era * 400);
  const unsigned doy = (153 * (month + (month > 2 ? -3 : 9)) + 2) / 5 + day - 1;
  const unsigned doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return static_cast<std::int64_t>(era) * 146097 + static_cast<std::int64_t>(doe) - 719468;
}

CivilDate civilFromDays(std::int64_t days) {
  days += 719468;
  const std::int64_t era = (days >= 0 ? days : days - 146096) / 146097;
  const auto doe = static_cast<unsigned>(days - era * 146097);
  const unsigned yoe = (doe - doe / 1460 + doe / 36524 - doe / 146096) / 365;
  const unsigned doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
  const unsigned mp = (5 * doy + 2) / 153;
  CivilDate d;
  d.day = doy - (153 * mp + 2) / 5 + 1;
  d.month = mp < 10 ? mp + 3 : mp - 9;
  d.year = static_cast<int>(static_cast<std::int64_t>(yoe) + era * 400 + (d.month <= 2 ? 1 : 0));
  return d;
}

std::string formatKittiTimestamp(std::int64_t t_ns) {
  constexpr std::int64_t kDayNs = 86'400'000'000'000LL;
  const std::int64_t days = (t_ns >= 0 ? t_ns : t_ns - kDayNs + 1) / kDayNs;
  const std::int64_t in_day = t_ns - days * kDayNs;
  const CivilDate d = civilFromDays(days);
  const std::int64_t s = in_day / 1'000'000'000LL;
  return fmt::format("{:04d}-{:02d}-{:02d} {:02d}:{:02d}:{:02d}.{:09d}", d.year, d.month, d.day,
                     s / 3600, (s / 60) % 60, s % 60, in_day % 1'000'000'000LL);
}

bool kittiTimestampToNs(std::string_view text, std::int64_t& t_ns) {
  text = trim(text);
  // Fixed layout: "YYYY-MM-DD hh:mm:ss" then an optional fraction.
  if (text.size() < 19 || text[4] != '-' || text[7] != '-' || text[10] != ' ' || text[13] != ':' ||
      text[16] != ':') {
    return false;
  }
  auto field = [&](std::size_t pos, std::size_t len, int& out) {
    const auto [ptr, ec] = std::from_chars(text.data() + pos, text.data() + pos + len, out);
    return ec == std::errc() && ptr == text.data() + pos + len;
  };
  int year = 0, month = 0, day = 0, hour = 0, minute = 0, second = 0;
  if (!field(0, 4, year) || !field(5, 2, month) || !field(8, 2, day) || !field(11, 2, hour) ||
      !field(14, 2, minute) || !field(17, 2, second)) {
    return false;
  }
  if (month < 1 || month > 12 || day < 1 || day > 31 || hour > 23 || minute > 59 || second > 60) {
    return false;
  }
  // int64 nanoseconds since 1970 span 1677-09-21 to 2262-04-11: a year outside would overflow,
  // and so could a time-zone shift near the ends. Recorded drives lie well inside.
  if (year < 1900 || year > 2200) return false;
  std::int64_t frac_ns = 0;
  if (text.size() > 19) {
    if (text[19] != '.') return false;
    std::string digits = std::string(text.substr(19));  // ".fffffffff"
    if (!secondsToNs("0" + digits, frac_ns)) return false;
  }
  const std::int64_t days =
      daysFromCivil(year, static_cast<unsigned>(month), static_cast<unsigned>(day));
  t_ns = ((days * 24 + hour) * 60 + minute) * 60 * 1'000'000'000LL + second * 1'000'000'000LL +
         frac_ns;
  return true;
}

std::string formatSeconds(std::int64_t t_ns) {
  const bool negative = t_ns < 0;
  const std::uint64_t magnitude =
      negative ? static_cast<std::uint64_t>(-(t_ns + 1)) + 1 : static_cast<std::uint64_t>(t_ns);
  std::string frac = std::to_string(magnitude % 1'000'000'000ULL);
  frac.insert(0, 9 - frac.size(), '0');
  return (negative ? "-" : "") + std::to_string(magnitude / 1'000'000'000ULL) + "." + frac;
}

}  // namespace gvio::io
