#include "view/view_plots.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "io/input_error.hpp"
#include "io/text.hpp"

namespace gvio::view {
namespace {

using nlohmann::json;

std::size_t strideFor(std::size_t n, std::size_t max_points) {
  return std::max<std::size_t>(1, (n + max_points - 1) / std::max<std::size_t>(max_points, 1));
}

Eigen::Vector3d pointAt(const json& p, std::size_t k) {
  return {p[3 * k].get<double>(), p[3 * k + 1].get<double>(), p[3 * k + 2].get<double>()};
}

double round6(double v) {
  return std::round(v * 1e6) / 1e6;
}

// The truth's horizontal position at t (linear between its stamps), NaN outside it.
struct TruthTrack {
  std::vector<double> t;
  std::vector<Eigen::Vector2d> p;
  [[nodiscard]] Eigen::Vector2d at(double s) const {
    if (t.empty() || s < t.front() || s > t.back()) return Eigen::Vector2d::Constant(NAN);
    const auto hi = std::lower_bound(t.begin(), t.end(), s);
    const auto k = static_cast<std::size_t>(hi - t.begin());
    if (k == 0) return p.front();
    const double w = (s - t[k - 1]) / std::max(t[k] - t[k - 1], 1e-12);
    return p[k - 1] + w * (p[k] - p[k - 1]);
  }
};

}  // namespace

json tracks2d(const json& trajectories, const SceneGeo& geo, std::size_t max_points) {
  json out = json::array();
  const fusion::EnuFrame enu(geo.enu_origin);
  for (const json& traj : trajectories) {
    const json& p = traj["p"];
    const std::size_t n = p.size() / 3;
    json lat_lon = json::array(), utm = json::array();
    const std::size_t stride = strideFor(n, max_points);
    for (std::size_t k = 0; k < n; k = (k + stride < n || k == n - 1) ? k + stride : n - 1) {
      const Eigen::Vector3d q = pointAt(p, k);
      fusion::Lla lla;
      fusion::Utm u{geo.utm_zone, geo.utm_north, 0.0, 0.0};
      if (geo.kind == SceneGeo::Kind::kEnu) {
        lla = enu.toLla(q);
        u = fusion::llaToUtm(lla, geo.utm_zone, geo.utm_north);
      } else {
        u.easting_m = geo.utm_origin.x() + q.x();
        u.northing_m = geo.utm_origin.y() + q.y();
        lla = fusion::utmToLla(u, geo.utm_origin.z() + q.z());
      }
      lat_lon.push_back(round6(lla.lat_deg) + 0.0);
      lat_lon.push_back(round6(lla.lon_deg) + 0.0);
      utm.push_back(std::round(u.easting_m * 100) / 100);
      utm.push_back(std::round(u.northing_m * 100) / 100);
      if (k == n - 1) break;
    }
    out.push_back(
        {{"name", traj["name"]}, {"lat_lon", std::move(lat_lon)}, {"utm", std::move(utm)}});
  }
  return out;
}

json horizontalErrors(const json& trajectories, std::size_t max_points) {
  TruthTrack truth;
  for (const json& traj : trajectories) {
    if (traj["name"] != "truth" || traj["t"].empty()) continue;
    for (std::size_t k = 0; k < traj["t"].size(); ++k) {
      truth.t.push_back(traj["t"][k].get<double>());
      const Eigen::Vector3d q = pointAt(traj["p"], k);
      truth.p.emplace_back(q.x(), q.y());
    }
  }
  if (truth.t.empty()) return nullptr;
  json series = json::array();
  json t_out = json::array();
  // One time axis: the fused trajectory's stamps (thinned); each series sampled at them.
  std::vector<double> times;
  for (const json& traj : trajectories) {
    if (traj["name"] == "fused") {
      for (const json& s : traj["t"]) times.push_back(s.get<double>());
    }
  }
  if (times.empty()) return nullptr;
  const std::size_t stride = strideFor(times.size(), max_points);
  std::vector<double> sampled;
  for (std::size_t k = 0; k < times.size(); k += stride) sampled.push_back(times[k]);
  for (const double s : sampled) t_out.push_back(std::round((s - truth.t.front()) * 1e3) / 1e3);
  for (const json& traj : trajectories) {
    if (traj["name"] == "truth" || traj["t"].empty()) continue;
    std::vector<double> t;
    for (const json& s : traj["t"]) t.push_back(s.get<double>());
    json errors = json::array();
    for (const double s : sampled) {
      const auto hi = std::lower_bound(t.begin(), t.end(), s);
      const auto k = static_cast<std::size_t>(hi - t.begin());
      if (k >= t.size() || std::abs(t[k] - s) > 1e-3) {  // no pose of this one at that stamp
        errors.push_back(nullptr);
        continue;
      }
      const Eigen::Vector3d q = pointAt(traj["p"], k);
      const Eigen::Vector2d d = truth.at(s) - Eigen::Vector2d(q.x(), q.y());
      errors.push_back(d.allFinite() ? json(std::round(d.norm() * 1e3) / 1e3) : json(nullptr));
    }
    series.push_back({{"name", traj["name"]}, {"horizontal_m", std::move(errors)}});
  }
  return {{"t", std::move(t_out)}, {"series", std::move(series)}};
}

json consistencyScores(const std::filesystem::path& csv) {
  io::LineReader reader(csv);
  std::string line;
  if (!reader.next(line)) reader.fail("empty; expected gvio consistency --images' keyframes.csv");
  std::vector<std::string> header;
  for (const auto f : io::splitDelimited(line, ',')) header.emplace_back(io::trim(f));
  const auto column = [&](const char* name) { return io::columnIndex(header, name, reader); };
  const std::size_t ct = column("t_from_start_s"), cx = column("x_m"), cy = column("y_m"),
                    cz = column("z_m"), cn = column("ncc"), cd = column("depth_agreement"),
                    cf = column("flagged");
  json t = json::array(), p = json::array(), ncc = json::array(), depth = json::array(),
       flagged = json::array();
  const auto number = [&](std::string_view s) {
    const std::string v(io::trim(s));
    if (v == "nan" || v.empty()) return json(nullptr);
    try {
      std::size_t used = 0;
      const double d = std::stod(v, &used);
      if (used != v.size()) reader.fail("'" + v + "' is not a number");
      return std::isfinite(d) ? json(d) : json(nullptr);
    } catch (const std::logic_error&) {
      reader.fail("'" + v + "' is not a number");
    }
  };
  while (reader.next(line)) {
    if (io::trim(line).empty()) continue;
    const auto f = io::splitDelimited(line, ',');
    // The columns read come before the quoted reasons (which may hold commas).
    if (f.size() <= std::max({ct, cx, cy, cz, cn, cd, cf})) reader.fail("too few fields");
    t.push_back(number(f[ct]));
    for (const std::size_t c : {cx, cy, cz}) p.push_back(number(f[c]));
    ncc.push_back(number(f[cn]));
    depth.push_back(number(f[cd]));
    flagged.push_back(io::trim(f[cf]) == "1" || io::trim(f[cf]) == "true");
  }
  return {{"t", std::move(t)},
          {"p", std::move(p)},
          {"ncc", std::move(ncc)},
          {"depth_agreement", std::move(depth)},
          {"flagged", std::move(flagged)}};
}

}  // namespace gvio::view
