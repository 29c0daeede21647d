#include "io/nmea.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <iterator>
#include <map>
#include <optional>

#include "fusion/gnss_covariance.hpp"
#include "io/input_error.hpp"
#include "io/text.hpp"

namespace gvio::io {
namespace {

constexpr std::int64_t kNsPerSecond = 1'000'000'000;
constexpr std::int64_t kNsPerDay = 86'400 * kNsPerSecond;

// A GGA fix before it is dated: GGA carries only the time of day.
struct PendingFix {
  std::size_t line = 0;
  std::int64_t tod_ns = 0;
  GnssFix fix;
};
struct RmcDate {
  std::size_t line = 0;
  std::int64_t tod_ns = 0;
  std::int64_t day = 0;  // days since 1970-01-01
};
struct GstSigma {
  std::size_t line = 0;
  double sigma_h_m = 0.0;
  double sigma_v_m = 0.0;
  Eigen::Matrix2d shape_en = Eigen::Matrix2d::Identity();  // from the error ellipse, when stated
};
struct Skipped {
  std::size_t count = 0;
  std::size_t first_line = 0;
  void add(std::size_t line) {
    if (count++ == 0) first_line = line;
  }
};

// Everything collected in one pass; dating and sigmas need the whole file (RMC/GST may follow).
struct Collected {
  std::vector<PendingFix> gga;
  std::vector<RmcDate> rmc;                   // in line order
  std::multimap<std::int64_t, GstSigma> gst;  // by time of day
  Skipped bad_checksum;
  Skipped no_fix;
  // Per sentence type ("RMC", "GGA", "P" for vendor sentences, ...): all seen, and those whose
  // checksum failed.
  std::map<std::string, std::size_t, std::less<>> seen, failed;
  std::size_t vendor = 0;  // proprietary ($P...) sentences
};

bool allDigits(std::string_view s) {
  return std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

std::optional<double> toDouble(std::string_view s) {
  double value = 0.0;
  const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (s.empty() || ec != std::errc() || ptr != s.data() + s.size() || !std::isfinite(value)) {
    return std::nullopt;
  }
  return value;
}

std::optional<int> toInt(std::string_view s) {
  int value = 0;
  if (s.empty() || !allDigits(s)) return std::nullopt;
  const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (ec != std::errc()) return std::nullopt;
  return value;
}

// "hhmmss" or "hhmmss.sss" to nanoseconds since midnight (second 60 allowed: leap second).
std::optional<std::int64_t> parseTimeOfDay(std::string_view s) {
  if (s.size() < 6 || !allDigits(s.substr(0, 6))) return std::nullopt;
  if (s.size() > 6 && (s[6] != '.' || !allDigits(s.substr(7)))) return std::nullopt;
  const int hours = *toInt(s.substr(0, 2));
  const int minutes = *toInt(s.substr(2, 2));
  std::int64_t seconds_ns = 0;
  if (!secondsToNs(s.substr(4), seconds_ns)) return std::nullopt;
  if (hours > 23 || minutes > 59 || seconds_ns >= 61 * kNsPerSecond) return std::nullopt;
  return (hours * 3600LL + minutes * 60LL) * kNsPerSecond + seconds_ns;
}

// "ddmmyy" to days since the epoch; two-digit years 80-99 are 19xx (GPS started in 1980).
std::optional<std::int64_t> parseDate(std::string_view s) {
  if (s.size() != 6 || !allDigits(s)) return std::nullopt;
  const int day = *toInt(s.substr(0, 2));
  const int month = *toInt(s.substr(2, 2));
  const int yy = *toInt(s.substr(4, 2));
  if (day < 1 || day > 31 || month < 1 || month > 12) return std::nullopt;
  return daysFromCivil(yy >= 80 ? 1900 + yy : 2000 + yy, static_cast<unsigned>(month),
                       static_cast<unsigned>(day));
}

// "ddmm.mmmm" / "dddmm.mmmm" plus hemisphere to signed degrees. The split between degrees and
// minutes is two digits left of the decimal point, done on the text so minutes stay exact.
std::optional<double> parseCoordinate(std::string_view value, std::string_view hemisphere,
                                      char positive, char negative, double limit_deg) {
  const auto dot = value.find('.');
  const std::size_t int_len = dot == std::string_view::npos ? value.size() : dot;
  if (int_len < 2 || int_len > 5 || !allDigits(value.substr(0, int_len))) return std::nullopt;
  if (dot != std::string_view::npos && !allDigits(value.substr(dot + 1))) return std::nullopt;
  const auto degree_digits = value.substr(0, int_len - 2);
  const int degrees = degree_digits.empty() ? 0 : *toInt(degree_digits);
  const auto minutes = toDouble(value.substr(int_len - 2));
  if (!minutes || *minutes >= 60.0) return std::nullopt;
  const double angle = degrees + *minutes / 60.0;
  if (angle > limit_deg || hemisphere.size() != 1) return std::nullopt;
  if (hemisphere[0] == positive) return angle;
  if (hemisphere[0] == negative) return -angle;
  return std::nullopt;
}

[[noreturn]] void malformed(const LineReader& at, std::string_view type, std::string_view what,
                            std::string_view value) {
  at.fail("malformed " + std::string(type) + ": " + std::string(what) + " '" + std::string(value) +
          "'");
}

void parseGga(const std::vector<std::string_view>& f, const LineReader& at, Collected& out) {
  if (f.size() < 10) at.fail("malformed GGA: " + std::to_string(f.size()) + " fields, need 10+");
  // Receivers without a fix emit GGA with quality 0 (or none) and often empty time and position.
  const auto quality = f[6].empty() ? std::optional<int>(0) : toInt(f[6]);
  if (!quality || *quality > 9) malformed(at, "GGA", "fix quality", f[6]);
  if (*quality == 0 || f[2].empty() || f[4].empty()) {
    out.no_fix.add(at.lineNumber());
    return;
  }
  PendingFix p;
  p.line = at.lineNumber();
  const auto tod = parseTimeOfDay(f[1]);
  if (!tod) malformed(at, "GGA", "time", f[1]);
  p.tod_ns = *tod;
  const auto lat = parseCoordinate(f[2], f[3], 'N', 'S', 90.0);
  if (!lat) malformed(at, "GGA", "latitude", std::string(f[2]) + "," + std::string(f[3]));
  const auto lon = parseCoordinate(f[4], f[5], 'E', 'W', 180.0);
  if (!lon) malformed(at, "GGA", "longitude", std::string(f[4]) + "," + std::string(f[5]));
  const auto sats = f[7].empty() ? std::optional<int>(0) : toInt(f[7]);
  if (!sats) malformed(at, "GGA", "number of satellites", f[7]);
  const auto hdop = f[8].empty() ? std::optional<double>(0.0) : toDouble(f[8]);
  if (!hdop || *hdop < 0.0) malformed(at, "GGA", "HDOP", f[8]);
  const auto alt = toDouble(f[9]);
  if (!alt) malformed(at, "GGA", "altitude", f[9]);
  // An empty geoid separation means the receiver has no geoid model: the altitude is ellipsoidal.
  const std::string_view sep_text = f.size() > 11 ? f[11] : std::string_view();
  const auto sep = sep_text.empty() ? std::optional<double>(0.0) : toDouble(sep_text);
  if (!sep) malformed(at, "GGA", "geoid separation", sep_text);
  p.fix.lat_deg = *lat;
  p.fix.lon_deg = *lon;
  p.fix.h_ellipsoid_m = *alt + *sep;
  p.fix.quality = *quality;
  p.fix.hdop = *hdop;
  p.fix.num_sats = *sats;
  out.gga.push_back(p);
}

void parseRmc(const std::vector<std::string_view>& f, const LineReader& at, Collected& out) {
  if (f.size() < 10) at.fail("malformed RMC: " + std::to_string(f.size()) + " fields, need 10+");
  // The date is usable even without a fix (status V); without time or date there is nothing.
  if (f[1].empty() || f[9].empty()) return;
  const auto tod = parseTimeOfDay(f[1]);
  if (!tod) malformed(at, "RMC", "time", f[1]);
  const auto day = parseDate(f[9]);
  if (!day) malformed(at, "RMC", "date", f[9]);
  out.rmc.push_back({at.lineNumber(), *tod, *day});
}

// The shape of GST's error ellipse (fields 3-5: 1-sigma semi-major and semi-minor axes, the
// major axis's orientation clockwise from true north); a circle where the receiver leaves them
// empty or zero (many do, stating only the latitude and longitude sigmas).
Eigen::Matrix2d gstEllipseShape(const std::vector<std::string_view>& f, const LineReader& at) {
  if (f[3].empty() || f[4].empty() || f[5].empty()) return Eigen::Matrix2d::Identity();
  const auto major = toDouble(f[3]);
  const auto minor = toDouble(f[4]);
  const auto orientation = toDouble(f[5]);
  if (!major || *major < 0.0) malformed(at, "GST", "semi-major axis sigma", f[3]);
  if (!minor || *minor < 0.0) malformed(at, "GST", "semi-minor axis sigma", f[4]);
  if (!orientation || std::abs(*orientation) > 360.0) {
    malformed(at, "GST", "ellipse orientation", f[5]);
  }
  if (*major <= 0.0 || *minor <= 0.0) return Eigen::Matrix2d::Identity();
  return fusion::horizontalShape(fusion::ellipseCovariance(*major, *minor, *orientation));
}

void parseGst(const std::vector<std::string_view>& f, const LineReader& at, Collected& out) {
  if (f.size() < 9) at.fail("malformed GST: " + std::to_string(f.size()) + " fields, need 9+");
  if (f[1].empty() || f[6].empty() || f[7].empty() || f[8].empty()) return;
  const auto tod = parseTimeOfDay(f[1]);
  if (!tod) malformed(at, "GST", "time", f[1]);
  const auto lat = toDouble(f[6]);
  const auto lon = toDouble(f[7]);
  const auto alt = toDouble(f[8]);
  if (!lat || *lat < 0.0) malformed(at, "GST", "latitude sigma", f[6]);
  if (!lon || *lon < 0.0) malformed(at, "GST", "longitude sigma", f[7]);
  if (!alt || *alt < 0.0) malformed(at, "GST", "altitude sigma", f[8]);
  const double sigma_h = std::sqrt((*lat * *lat + *lon * *lon) / 2.0);
  // Some receivers fill GST with zeros when they have no estimate; a zero sigma would claim a
  // perfect fix, so such a GST is ignored and the HDOP model applies.
  if (sigma_h <= 0.0 || *alt <= 0.0) return;
  out.gst.emplace(*tod, GstSigma{at.lineNumber(), sigma_h, *alt, gstEllipseShape(f, at)});
}

// Body of a sentence whose "*HH" checksum is present and right; nullopt otherwise.
std::optional<std::string_view> verifiedBody(std::string_view sentence) {
  const auto star = sentence.find('*');
  if (star == std::string_view::npos || sentence.size() != star + 3) return std::nullopt;
  unsigned expected = 0;
  const char* hex = sentence.data() + star + 1;
  const auto [ptr, ec] = std::from_chars(hex, hex + 2, expected, 16);
  if (ec != std::errc() || ptr != hex + 2) return std::nullopt;
  const auto body = sentence.substr(1, star - 1);
  if (nmeaChecksum(body) != expected) return std::nullopt;
  return body;
}

// The sentence type of an address: "GGA" of "GPGGA" (2-letter talker + 3-letter type), "P" for a
// proprietary (vendor) sentence, "" for anything else.
std::string_view sentenceType(std::string_view address) {
  if (address.starts_with('P')) return "P";
  return address.size() == 5 ? address.substr(2) : std::string_view();
}

// The body of a sentence as written, without its checksum, when that is wrong or missing.
std::string_view bodyAsWritten(std::string_view sentence) {
  const auto star = sentence.find('*');
  return sentence.substr(1, star == std::string_view::npos ? std::string_view::npos : star - 1);
}

void parseSentence(std::string_view sentence, const LineReader& at, NmeaLog& log, Collected& out,
                   const ReaderConfig& config) {
  ++log.sentences;
  auto body = verifiedBody(sentence);
  const std::string_view written = body ? *body : bodyAsWritten(sentence);
  const std::string_view type = sentenceType(written.substr(0, written.find(',')));
  ++out.seen[std::string(type)];
  if (!body) {
    out.bad_checksum.add(at.lineNumber());
    ++out.failed[std::string(type)];
    if (config.nmea_checksum != "warn") return;
    body = written;  // read as written
  }
  const auto fields = splitDelimited(*body, ',');
  if (type == "P") ++out.vendor;
  if (type == "GGA") return parseGga(fields, at, out);
  if (type == "RMC") return parseRmc(fields, at, out);
  if (type == "GST") return parseGst(fields, at, out);
  ++log.other_sentences;
}

// The record among [first, last) whose line is nearest `line`: a log longer than a day repeats
// times of day, and the matching sentence is the one of the same epoch, next to the GGA.
template <typename It, typename LineOf>
It nearestByLine(It first, It last, std::size_t line, LineOf line_of) {
  auto distance = [&](It it) {
    const std::size_t l = line_of(*it);
    return l > line ? l - line : line - l;
  };
  It best = first;
  for (It it = first; it != last; ++it) {
    if (distance(it) < distance(best)) best = it;
  }
  return best;
}

// Day (since the epoch) of a GGA: the RMC of the same epoch if any, else the nearest RMC before
// it (a later time of day there means midnight passed in between), else the nearest one after.
std::int64_t dayOf(const PendingFix& gga, const std::vector<RmcDate>& rmc,
                   const std::multimap<std::int64_t, std::size_t>& rmc_by_tod) {
  const auto [lo, hi] = rmc_by_tod.equal_range(gga.tod_ns);
  if (lo != hi) {
    const auto it =
        nearestByLine(lo, hi, gga.line, [&](const auto& entry) { return rmc[entry.second].line; });
    return rmc[it->second].day;
  }
  const auto after = std::lower_bound(rmc.begin(), rmc.end(), gga.line,
                                      [](const RmcDate& r, std::size_t l) { return r.line < l; });
  if (after != rmc.begin()) {
    const RmcDate& before = *std::prev(after);
    return before.day + (before.tod_ns > gga.tod_ns ? 1 : 0);
  }
  return after->day - (after->tod_ns < gga.tod_ns ? 1 : 0);
}

// GST sigmas of the same epoch when present, else HDOP x UERE (HDOP 1 when not reported).
void setSigmas(GnssFix& fix, std::size_t line, std::int64_t tod_ns, const Collected& in,
               const ReaderConfig& config) {
  const auto [lo, hi] = in.gst.equal_range(tod_ns);
  if (lo != hi) {
    const auto it =
        nearestByLine(lo, hi, line, [](const auto& entry) { return entry.second.line; });
    fix.sigma_h_m = it->second.sigma_h_m;
    fix.sigma_v_m = it->second.sigma_v_m;
    fix.shape_en = it->second.shape_en;
    return;
  }
  const double hdop = fix.hdop > 0.0 ? fix.hdop : 1.0;
  fix.sigma_h_m = hdop * config.uereM(fix.quality);
  fix.sigma_v_m = fix.sigma_h_m * config.nmea_vertical_factor;
}

std::vector<GnssFix> datedFixes(const std::filesystem::path& file, const Collected& in,
                                const ReaderConfig& config) {
  std::vector<GnssFix> fixes;
  if (in.gga.empty()) return fixes;
  if (in.rmc.empty()) {
    throw InputError(file, 0, "no RMC sentence: the date of the GGA fixes is unknown");
  }
  std::multimap<std::int64_t, std::size_t> rmc_by_tod;
  for (std::size_t i = 0; i < in.rmc.size(); ++i) rmc_by_tod.emplace(in.rmc[i].tod_ns, i);
  fixes.reserve(in.gga.size());
  for (const PendingFix& p : in.gga) {
    GnssFix fix = p.fix;
    fix.t_ns = dayOf(p, in.rmc, rmc_by_tod) * kNsPerDay + p.tod_ns;
    if (!fixes.empty() && fix.t_ns <= fixes.back().t_ns) {
      throw InputError(file, p.line,
                       "timestamp not increasing (" + formatSeconds(fix.t_ns) + " s after " +
                           formatSeconds(fixes.back().t_ns) + " s)");
    }
    setSigmas(fix, p.line, p.tod_ns, in, config);
    fixes.push_back(fix);
  }
  return fixes;
}

void warnSkipped(NmeaLog& log, const std::filesystem::path& file, const Skipped& skipped,
                 std::string_view singular, std::string_view plural, std::string_view why) {
  if (skipped.count == 0) return;
  log.warnings.push_back(file.string() + ": " + std::to_string(skipped.count) + " " +
                         std::string(skipped.count == 1 ? singular : plural) + " " +
                         std::string(why) + " skipped (first at line " +
                         std::to_string(skipped.first_line) + ")");
}

// "1748 of 1748 RMC, 2 of 1750 GGA sentences failed their checksum (first at line 2)".
std::string failedSummary(const Collected& in) {
  std::string parts;
  for (const auto& [type, count] : in.failed) {
    if (!parts.empty()) parts += ", ";
    const std::string name = type == "P" ? "vendor ($P...)" : type.empty() ? "unknown" : type;
    parts += std::to_string(count) + " of " + std::to_string(in.seen.at(type)) + " " + name;
  }
  return parts + " sentences failed their checksum (first at line " +
         std::to_string(in.bad_checksum.first_line) + ")";
}

// refuse: a few failed sentences are line noise; more, or most of one type, is a logger that
// writes wrong checksums (or a file that is not what it seems), and reading on would either drop
// every sentence of that type or trust them unchecked: the user decides (warn or skip).
void checkChecksums(const std::filesystem::path& file, const NmeaLog& log, const Collected& in,
                    const ReaderConfig& config) {
  if (config.nmea_checksum != "refuse" || in.bad_checksum.count == 0) return;
  bool systematic = 100 * in.bad_checksum.count > log.sentences;
  for (const auto& [type, count] : in.failed)
    systematic = systematic || 2 * count > in.seen.at(type);
  if (!systematic) return;
  std::size_t gga = 0;
  if (const auto it = in.seen.find("GGA"); it != in.seen.end()) gga = it->second;
  throw InputError(
      file, 0,
      failedSummary(in) + "; of " + std::to_string(log.sentences) + " sentences, " +
          std::to_string(gga) + " GGA (" + std::to_string(in.no_fix.count) +
          " without a position), " + std::to_string(in.vendor) +
          " vendor: set dataset.nmea_checksum: warn to read them as written, or skip to leave "
          "them out");
}

}  // namespace

std::uint8_t nmeaChecksum(std::string_view body) {
  std::uint8_t sum = 0;
  for (const char c : body) sum ^= static_cast<std::uint8_t>(c);
  return sum;
}

std::string withNmeaChecksum(std::string_view body) {
  static constexpr char kHex[] = "0123456789ABCDEF";
  const std::uint8_t sum = nmeaChecksum(body);
  return "$" + std::string(body) + "*" + kHex[sum >> 4] + kHex[sum & 0x0F];
}

NmeaLog readNmea(const std::filesystem::path& file, const ReaderConfig& config) {
  LineReader reader(file);
  NmeaLog log;
  Collected collected;
  std::string raw;
  while (reader.next(raw)) {
    std::string_view line = raw;
    if (reader.lineNumber() == 1 && line.starts_with("\xEF\xBB\xBF")) line.remove_prefix(3);
    line = trim(line);
    if (line.empty()) continue;
    if (line.front() != '$') {
      reader.fail("not an NMEA sentence (expected a line starting with '$')");
    }
    parseSentence(line, reader, log, collected, config);
  }
  checkChecksums(file, log, collected, config);
  log.fixes = datedFixes(file, collected, config);
  log.bad_checksum = collected.bad_checksum.count;
  log.no_fix = collected.no_fix.count;
  log.vendor_sentences = collected.vendor;
  if (config.nmea_checksum == "warn" && collected.bad_checksum.count > 0) {
    log.warnings.push_back(file.string() + ": " + failedSummary(collected) +
                           ", read as written (dataset.nmea_checksum: warn)");
  } else {
    warnSkipped(log, file, collected.bad_checksum, "sentence", "sentences",
                "with a bad or missing checksum");
  }
  warnSkipped(log, file, collected.no_fix, "GGA sentence", "GGA sentences", "without a fix");
  return log;
}

}  // namespace gvio::io
