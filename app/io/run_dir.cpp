#include "io/run_dir.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>

#include "io/input_error.hpp"
#include "io/text.hpp"
#include "io/trajectory_io.hpp"

namespace gvio::io {
namespace fs = std::filesystem;
namespace {

std::optional<Trajectory> optionalTum(const fs::path& file) {
  if (!fs::exists(file)) return std::nullopt;
  return readTum(file);
}

// A coordinate of a fix that was not fused: any number including nan/inf (the screening may have
// dropped it for exactly that), or empty. Returns false for text that is no number at all.
bool parseAnyNumber(std::string_view token, double& value) {
  if (token.empty()) {
    value = std::numeric_limits<double>::quiet_NaN();
    return true;
  }
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  return ec == std::errc() && end == token.data() + token.size();
}

std::optional<FixStatus> parseFixStatus(std::string_view s) {
  if (s == "used") return FixStatus::kUsed;
  if (s == "rejected") return FixStatus::kRejected;
  if (s == "skipped") return FixStatus::kSkipped;
  if (s == "unmatched") return FixStatus::kUnmatched;
  if (s == "unaligned") return FixStatus::kUnaligned;
  return std::nullopt;
}

// 1-based line of byte `offset` (nlohmann counts bytes from 1).
std::size_t lineOfByte(const std::string& text, std::size_t offset) {
  const std::size_t end = std::min(offset > 0 ? offset - 1 : 0, text.size());
  return 1 + static_cast<std::size_t>(std::count(text.begin(), text.begin() + end, '\n'));
}

// "t0_s" as the brief of report.json names it, or "t0" as `gvio run` has written it.
double outageTime(const nlohmann::json& o, const char* key_s, const char* key, std::size_t i,
                  const fs::path& file) {
  const nlohmann::json* v = nullptr;
  if (o.contains(key_s)) {
    v = &o[key_s];
  } else if (o.contains(key)) {
    v = &o[key];
  }
  if (v == nullptr || !v->is_number() || !std::isfinite(v->get<double>())) {
    throw InputError(file, 0,
                     "outages[" + std::to_string(i) + "]: needs a finite number \"" + key + "\"");
  }
  return v->get<double>();
}

}  // namespace

std::vector<GnssFixRecord> readGnssFixes(const fs::path& file) {
  LineReader in(file);
  std::string line;
  std::vector<std::string> header;
  while (header.empty() && in.next(line)) {
    if (isBlankOrComment(line)) continue;
    for (const auto f : splitDelimited(line, ',')) header.emplace_back(f);
  }
  if (header.empty()) in.fail("empty file, expected the header t_s,e_m,n_m,u_m,status");
  const std::array<const char*, 5> names = {"t_s", "e_m", "n_m", "u_m", "status"};
  std::array<std::size_t, 5> col{};
  for (std::size_t k = 0; k < names.size(); ++k) {
    col[k] = columnIndex(header, names[k], in, "t_s,e_m,n_m,u_m,status");
  }
  std::vector<GnssFixRecord> fixes;
  while (in.next(line)) {
    if (isBlankOrComment(line)) continue;
    const auto f = splitDelimited(line, ',');
    if (f.size() != header.size()) {
      in.fail("expected " + std::to_string(header.size()) + " fields, got " +
              std::to_string(f.size()));
    }
    GnssFixRecord r;
    const auto status = parseFixStatus(f[col[4]]);
    if (!status) {
      in.fail("status '" + std::string(f[col[4]]) +
              "': expected used, rejected, skipped, unmatched or unaligned");
    }
    r.status = *status;
    double v[4];
    for (std::size_t k = 0; k < 4; ++k) {
      if (r.status == FixStatus::kUsed || r.status == FixStatus::kRejected) {
        v[k] = parseFinite(f[col[k]], in, names[k]);
      } else if (!parseAnyNumber(f[col[k]], v[k])) {
        in.fail(std::string(names[k]) + " '" + std::string(f[col[k]]) + "' is not a number");
      }
    }
    r.t_s = v[0];
    r.p_enu = Eigen::Vector3d(v[1], v[2], v[3]);
    fixes.push_back(r);
  }
  return fixes;
}

std::vector<TimeSpan> readOutages(const fs::path& file) {
  const nlohmann::json j = readJsonObject(file);
  std::vector<TimeSpan> spans;
  if (!j.contains("outages") || j["outages"].is_null()) return spans;
  const auto& a = j["outages"];
  if (!a.is_array()) throw InputError(file, 0, "\"outages\" is not an array");
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (!a[i].is_object()) {
      throw InputError(file, 0, "outages[" + std::to_string(i) + "] is not an object");
    }
    TimeSpan s{outageTime(a[i], "t0_s", "t0", i, file), outageTime(a[i], "t1_s", "t1", i, file)};
    if (s.t1_s < s.t0_s) {
      throw InputError(file, 0, "outages[" + std::to_string(i) + "] ends before it starts");
    }
    spans.push_back(s);
  }
  return spans;
}

nlohmann::json readJsonObject(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file, 0, "cannot open for reading");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    throw InputError(file, lineOfByte(text, e.byte), "not valid JSON");
  } catch (const nlohmann::json::exception& e) {  // e.g. a number too large for a double
    throw InputError(file, 0, std::string("not valid JSON: ") + e.what());
  }
  if (!j.is_object()) throw InputError(file, 0, "expected a JSON object");
  return j;
}

std::optional<std::string> incompleteRunWarning(const fs::path& dir) {
  const fs::path file = dir / "report.json";
  std::ifstream in(file, std::ios::binary);
  if (!in) return std::nullopt;
  const nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
  if (!j.is_object() || !j.contains("status") || !j["status"].is_string()) return std::nullopt;
  const std::string status = j["status"].get<std::string>();
  // "partial": finished, its trajectory covering only part of the input (it said so when it ran).
  if (status == "complete" || status == "partial") return std::nullopt;
  // Only words of gvio's own are echoed: the file may hold anything.
  const auto word = [](const std::string& w) {
    return !w.empty() && w.size() <= 32 && std::all_of(w.begin(), w.end(), [](char c) {
      return (c >= 'a' && c <= 'z') || c == '_';
    });
  };
  std::string how = word(status) ? "status \"" + status + "\"" : "an unknown status";
  if (j.contains("stage") && j["stage"].is_string() && word(j["stage"].get<std::string>())) {
    how += " in stage " + j["stage"].get<std::string>();
  }
  return file.string() + ": the run did not complete (" + how +
         "): files it had not replaced yet are from an earlier run";
}

RunFiles readRunDir(const fs::path& dir, const RunReadOptions& options) {
  if (!fs::is_directory(dir)) throw InputError(dir, 0, "run folder not found");
  RunFiles run;
  run.dir = dir;
  run.fused = optionalTum(dir / "trajectory.tum");
  run.vio = optionalTum(dir / "trajectory_vio.tum");
  if (!run.fused && !run.vio) {
    throw InputError(dir, 0, "no trajectory.tum or trajectory_vio.tum in the run folder");
  }
  const auto& reference = options.reference;
  run.truth = reference ? std::optional<Trajectory>(
                              readTrajectory(*reference, detectTrajectoryFormat(*reference)))
                        : optionalTum(dir / "groundtruth.tum");
  if (options.gnss_fixes && fs::exists(dir / "gnss_fixes.csv")) {
    run.gnss_fixes = readGnssFixes(dir / "gnss_fixes.csv");
  }
  if (options.outages && fs::exists(dir / "report.json")) {
    run.outages = readOutages(dir / "report.json");
  }
  if (options.loops && fs::exists(dir / "loops.csv")) run.loops = readLoopsCsv(dir / "loops.csv");
  if (options.cloud && fs::exists(dir / "map.pcd")) run.cloud = readMapCloud(dir / "map.pcd");
  if (options.occupancy) {
    for (const char* name : {"map.ot", "map.bt"}) {  // the ColorOcTree carries colour: prefer it
      if (fs::exists(dir / name)) {
        run.occupancy = readOccupancy(dir / name);
        break;
      }
    }
  }
  return run;
}

RunFiles readRunDir(const fs::path& dir, const std::optional<fs::path>& reference) {
  RunReadOptions options;
  options.reference = reference;
  return readRunDir(dir, options);
}

}  // namespace gvio::io
