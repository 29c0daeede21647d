#pragma once
// NMEA 0183 log reader: position fixes from GGA, the date from RMC, and (optionally) the error
// estimate from GST. Any talker (GP, GN, GL, GA, GB, ...) is accepted.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "io/reader_config.hpp"
#include "odometry/measurements.hpp"

namespace gvio::io {

struct NmeaLog {
  std::vector<GnssFix> fixes;         // strictly increasing t_ns (UTC ns since the Unix epoch)
  std::size_t sentences = 0;          // lines that looked like NMEA sentences ($...)
  std::size_t bad_checksum = 0;       // skipped: checksum missing or wrong
  std::size_t no_fix = 0;             // GGA with quality 0 (or an empty position) skipped
  std::size_t other_sentences = 0;    // valid sentences of other types (GSV, VTG, ...) ignored
  std::size_t vendor_sentences = 0;   // of which proprietary ($P...)
  std::vector<std::string> warnings;  // one line per kind of skip: count and first line number
};

// Reads every line of `file`. Sentences with a bad or missing checksum as config.nmea_checksum
// says (refused with the counts per type when more than line noise, read, or skipped); skips and
// counts GGA without a fix; throws InputError naming file and line on malformed GGA/RMC/GST fields,
// non-NMEA lines, timestamps that do not increase, or GGA fixes without any RMC to date them. A log
// without any GGA fix is valid and gives no fixes.
NmeaLog readNmea(const std::filesystem::path& file, const ReaderConfig& config);

// XOR of the characters of `body`, the part of a sentence between '$' and '*'.
std::uint8_t nmeaChecksum(std::string_view body);
// The full sentence "$" + body + "*HH" (uppercase hex), without a line ending.
std::string withNmeaChecksum(std::string_view body);

}  // namespace gvio::io
