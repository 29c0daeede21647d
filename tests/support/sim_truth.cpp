#include "support/sim_truth.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <ctime>
#include <fstream>
#include <regex>
#include <sstream>
#include <stdexcept>

#include "support/fixtures.hpp"

namespace gvio::test {
namespace fs = std::filesystem;
namespace {

// The first "key: value" in sim.yaml (the simulator's settings precede anything else).
std::string yamlValue(const std::string& yaml, const std::string& key) {
  const std::regex re("\\n\\s*" + key + ":\\s*([^\\n]+)");
  std::smatch m;
  if (!std::regex_search(yaml, m, re)) throw std::runtime_error("sim.yaml: no " + key);
  return m[1];
}

// "2011-10-03 12:55:34.010000000" (UTC) as seconds since 1970.
double utcSeconds(const std::string& stamp) {
  std::tm tm{};
  double sec = 0.0;
  if (std::sscanf(stamp.c_str(), "%d-%d-%d %d:%d:%lf", &tm.tm_year, &tm.tm_mon, &tm.tm_mday,
                  &tm.tm_hour, &tm.tm_min, &sec) != 6) {
    throw std::runtime_error("oxts/timestamps.txt: bad stamp '" + stamp + "'");
  }
  tm.tm_year -= 1900;
  tm.tm_mon -= 1;
  return static_cast<double>(timegm(&tm)) + sec;
}

}  // namespace

std::optional<LlaSample> SimTruth::bodyAt(double t_s, double tolerance_s) const {
  const auto it = std::lower_bound(oxts.begin(), oxts.end(), t_s,
                                   [](const LlaSample& s, double t) { return s.t_s < t; });
  const LlaSample* best = nullptr;
  if (it != oxts.end()) best = &*it;
  if (it != oxts.begin() && (best == nullptr || t_s - std::prev(it)->t_s < best->t_s - t_s)) {
    best = &*std::prev(it);
  }
  if (best == nullptr || std::abs(best->t_s - t_s) > tolerance_s) return std::nullopt;
  return *best;
}

std::string SimTruth::runOptions() const {
  return fmt::format(
      "--set fusion.origin={:.9f},{:.9f},{:.4f} --set 'fusion.lever_arm_b=[{},{},{}]'",
      origin_lat_deg, origin_lon_deg, origin_h_m, lever_arm_b.x(), lever_arm_b.y(),
      lever_arm_b.z());
}

SimTruth readSimTruth(const fs::path& dataset) {
  const std::string yaml = readText(dataset / "sim.yaml");
  SimTruth t;
  t.origin_lat_deg = std::stod(yamlValue(yaml, "origin_lat_deg"));
  t.origin_lon_deg = std::stod(yamlValue(yaml, "origin_lon_deg"));
  t.origin_h_m = std::stod(yamlValue(yaml, "origin_h_m"));
  const std::string arm = yamlValue(yaml, "gnss_lever_arm_m");
  if (std::sscanf(arm.c_str(), "[%lf, %lf, %lf]", &t.lever_arm_b.x(), &t.lever_arm_b.y(),
                  &t.lever_arm_b.z()) != 3) {
    throw std::runtime_error("sim.yaml: gnss_lever_arm_m '" + arm + "'");
  }
  std::ifstream stamps(dataset / "oxts" / "timestamps.txt");
  std::string line;
  for (int k = 0; std::getline(stamps, line); ++k) {
    if (line.empty()) continue;
    std::ifstream record(dataset / "oxts" / "data" / fmt::format("{:010d}.txt", k));
    LlaSample s;
    s.t_s = utcSeconds(line);
    if (!(record >> s.lat_deg >> s.lon_deg >> s.h_m)) {
      throw std::runtime_error(fmt::format("oxts/data/{:010d}.txt: no lat lon alt", k));
    }
    t.oxts.push_back(s);
  }
  if (t.oxts.empty()) throw std::runtime_error(dataset.string() + ": no oxts records");
  return t;
}

std::vector<LlaSample> readTrajectoryLla(const fs::path& file) {
  std::istringstream in(readText(file));
  std::vector<LlaSample> rows;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    LlaSample s;
    if (std::sscanf(line.c_str(), "%lf,%lf,%lf,%lf", &s.t_s, &s.lat_deg, &s.lon_deg, &s.h_m) != 4) {
      throw std::runtime_error(file.string() + ": bad row '" + line + "'");
    }
    rows.push_back(s);
  }
  return rows;
}

}  // namespace gvio::test
