#include "io/pcl_checks.hpp"

#include <algorithm>
#include <cstdint>
#include <fstream>
#include <numeric>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "io/input_error.hpp"

namespace gvio::io {

namespace fs = std::filesystem;

namespace {

struct PcdHeader {
  std::vector<std::string> fields;
  std::vector<std::size_t> size, count;
  std::vector<char> type;
  std::size_t width = 0, height = 0;
  std::optional<std::size_t> points;
};

// Every value to the end of the line; nullopt when one does not parse (a COUNT of 10^82 overflows
// size_t: stopping there left COUNT empty, read as all 1, while PCL allocated 6 GB for it; found
// by fuzzing).
template <typename T>
std::optional<std::vector<T>> readAll(std::istringstream& in) {
  std::vector<T> v;
  T x;
  while (in >> x) v.push_back(x);
  if (!in.eof()) return std::nullopt;
  return v;
}

// A header line of printable ASCII and tabs (and CRs where `cr_allowed`): both readers of PCL
// misbehave on control bytes in their headers.
bool printable(const std::string& line, bool cr_allowed) {
  return std::none_of(line.begin(), line.end(), [&](char c) {
    const auto b = static_cast<unsigned char>(c);
    return (b < 0x20 && c != '\t' && !(cr_allowed && c == '\r')) || b > 0x7E;
  });
}

// ASCII data: `points` rows of `values` numbers each (blank lines aside).
bool asciiRowsFit(std::istream& in, std::size_t points, std::size_t values) {
  std::string row;
  std::size_t rows = 0;
  while (std::getline(in, row)) {
    std::istringstream ss(row);
    std::size_t n = 0;
    for (std::string token; ss >> token;) ++n;
    if (n == 0) continue;
    if (n != values || ++rows > points) return false;
  }
  return rows == points;
}

}  // namespace

std::size_t checkPcdFile(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file, 0, "cannot open for reading");
  PcdHeader h;
  std::string line;
  std::set<std::string> seen;
  for (std::size_t n = 1; n <= 64 && std::getline(in, line); ++n) {
    // PCL's header parser misbehaves on control bytes and repeated keys (a use after free, found
    // by fuzzing): a header is printable text with each key once.
    if (!printable(line, true)) {
      throw InputError(file, n, "PCD header line with a control or non-ASCII byte");
    }
    std::istringstream ss(line);
    std::string key;
    ss >> key;
    // PCL skips an empty line but crashes reading a file with a line of blanks (spaces, tabs or
    // CRs: a CRLF empty line too) in its header: a null dereference in PCDReader::read, found by
    // fuzzing.
    if (key.empty() && !line.empty()) {
      throw InputError(file, n, "PCD header line of blanks only");
    }
    if (key.empty() || key[0] == '#') continue;
    if (!seen.insert(key).second) throw InputError(file, n, "PCD header repeats " + key);
    if (key == "VERSION" || key == "VIEWPOINT") continue;
    bool ok = true;
    const auto all = [&ok, &ss]<typename T>(std::vector<T>& out) {
      auto values = readAll<T>(ss);
      ok = values.has_value();
      if (ok) out = std::move(*values);
    };
    if (key == "FIELDS") {
      all(h.fields);
    } else if (key == "SIZE") {
      all(h.size);
    } else if (key == "COUNT") {
      all(h.count);
    } else if (key == "TYPE") {
      all(h.type);
    } else if (key == "WIDTH") {
      ok = static_cast<bool>(ss >> h.width);
    } else if (key == "HEIGHT") {
      ok = static_cast<bool>(ss >> h.height);
    } else if (key == "POINTS") {
      h.points.emplace();
      ok = static_cast<bool>(ss >> *h.points);
    } else if (key != "DATA") {
      throw InputError(file, n, "not a PCD header line: '" + line.substr(0, 40) + "'");
    }
    if (!ok) throw InputError(file, n, "bad PCD header line '" + line + "'");
    if (key != "DATA") continue;
    std::string data;
    ss >> data;
    if (h.count.empty()) h.count.assign(h.fields.size(), 1);
    const std::size_t k = h.fields.size();
    bool valid = k > 0 && h.size.size() == k && h.type.size() == k && h.count.size() == k &&
                 h.points && *h.points == h.width * h.height;
    std::size_t step = 0;
    for (std::size_t i = 0; valid && i < k; ++i) {
      const std::size_t s = h.size[i];
      valid = (s == 1 || s == 2 || s == 4 || s == 8) && h.count[i] >= 1 && h.count[i] <= 1024 &&
              (h.type[i] == 'I' || h.type[i] == 'U' || (h.type[i] == 'F' && s >= 4));
      step += s * h.count[i];
    }
    if (!valid) {
      throw InputError(file, n,
                       "PCD header: FIELDS, SIZE, TYPE, COUNT, WIDTH x HEIGHT, POINTS disagree");
    }
    const std::size_t points = h.width * h.height;
    const auto data_at = static_cast<std::size_t>(in.tellg());
    const auto bytes = static_cast<std::size_t>(fs::file_size(file));
    const std::size_t left = bytes > data_at ? bytes - data_at : 0;
    // Bounds that keep points * step far from overflowing (2^40 points of up to 1 KiB); whether
    // the data holds them is checked below for each encoding.
    constexpr std::size_t kMaxPoints = std::size_t{1} << 40;
    if (h.width > kMaxPoints || h.height > kMaxPoints ||
        (h.width > 0 && h.height > kMaxPoints / h.width) || step > 1024) {
      throw InputError(file, n, "PCD header declares an impossible number or size of points");
    }
    if (data == "ascii") {
      valid =
          asciiRowsFit(in, points, std::accumulate(h.count.begin(), h.count.end(), std::size_t{0}));
    } else if (data == "binary") {
      valid = left >= points * step;
    } else if (data == "binary_compressed") {
      std::uint32_t sizes[2] = {0, 0};  // compressed, uncompressed
      in.read(reinterpret_cast<char*>(sizes), sizeof sizes);
      valid = points == 0 ||
              (in && sizes[0] <= left - std::min(left, sizeof sizes) && sizes[1] == points * step);
    } else {
      throw InputError(file, n,
                       "PCD DATA '" + data + "': expected ascii, binary or binary_compressed");
    }
    if (!valid) throw InputError(file, 0, "PCD data is shorter than its header says");
    return points;
  }
  throw InputError(file, 0, "not a PCD file (no DATA line in its header)");
}

namespace {

bool isPlyType(const std::string& t) {
  static const std::set<std::string> kTypes = {
      "char", "uchar", "short", "ushort", "int",   "uint",   "float",   "double",
      "int8", "uint8", "int16", "uint16", "int32", "uint32", "float32", "float64"};
  return kTypes.count(t) > 0;
}

}  // namespace

void checkPlyFile(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file, 0, "cannot open for reading");
  const auto bytes = static_cast<std::uint64_t>(fs::file_size(file));
  std::string line;
  auto next = [&]() {
    if (!std::getline(in, line)) return false;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    return true;
  };
  if (!next() || line != "ply") throw InputError(file, 1, "not a PLY file (no 'ply' line)");
  std::string element;
  bool format = false;
  for (std::size_t n = 2; n <= 10000 && next(); ++n) {
    auto bad = [&](const std::string& what) { throw InputError(file, n, "PLY header: " + what); };
    if (!printable(line, false)) bad("a control or non-ASCII byte");
    std::istringstream words(line);
    std::string key;
    words >> key;
    if (key == "end_header") {
      if (!format) bad("no format line");
      return;
    }
    if (key == "comment" || key == "obj_info") continue;
    if (key == "format") {
      std::string kind, version;
      words >> kind >> version;
      if (format ||
          (kind != "ascii" && kind != "binary_little_endian" && kind != "binary_big_endian") ||
          version != "1.0")
        bad("bad format line '" + line + "'");
      format = true;
    } else if (key == "element") {
      std::string count;
      words >> element >> count;
      const bool digits = !count.empty() && std::all_of(count.begin(), count.end(), [](char c) {
        return c >= '0' && c <= '9';
      });
      // Every element takes at least one byte: a larger count cannot be in the file.
      if (element.empty() || !digits || count.size() > 19 || std::stoull(count) > bytes)
        bad("bad element line '" + line + "'");
    } else if (key == "property") {
      std::string type, name;
      words >> type;
      if (element.empty()) bad("a property before any element");
      if (type == "list") {
        std::string count_type, item_type;
        words >> count_type >> item_type;
        if (!isPlyType(count_type) || !isPlyType(item_type))
          bad("bad list property '" + line + "'");
        if (element == "vertex") bad("a list property in the vertex element");
      } else if (!isPlyType(type)) {
        bad("unknown property type '" + type + "'");
      }
      words >> name;
      if (name.empty()) bad("a property without a name");
    } else {
      bad("not a header line: '" + line.substr(0, 40) + "'");
    }
  }
  throw InputError(file, 0, "PLY header without end_header");
}

void checkWrittenPly(const fs::path& written, const fs::path& file, std::uint64_t body_bytes) {
  std::ifstream in(written, std::ios::binary);
  std::string head(1 << 16, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  constexpr std::string_view kEnd = "end_header\n";
  const std::size_t end = head.find(kEnd);
  std::error_code ec;
  const std::uint64_t bytes = fs::file_size(written, ec);
  const std::uint64_t expected = end + kEnd.size() + body_bytes;
  if (ec || end == std::string::npos || bytes != expected) {
    throw InputError(file, 0,
                     "write failed (disk full or file size limit?): " +
                         std::to_string(ec ? 0 : bytes) + " bytes written, " +
                         (end == std::string::npos ? std::string("no whole header")
                                                   : std::to_string(expected) + " expected"));
  }
}

}  // namespace gvio::io
