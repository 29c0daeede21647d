#include "eval/position_report.hpp"

#include <fmt/format.h>

#include "eval/position_errors.hpp"
#include "eval/stats_text.hpp"
#include "io/atomic_write.hpp"
#include "io/geo_track.hpp"
#include "io/text.hpp"

namespace gvio::eval {

namespace {

nlohmann::json axisJson(const AxisStats& a) {
  nlohmann::json j = statsJson(a.stats);
  j["p95"] = a.p95;
  return j;
}

}  // namespace

std::string positionReport(const EvalResult& r, const EvalInputs& in, nlohmann::json& json) {
  const fusion::Lla& origin = *in.enu_origin;
  json["enu_origin"] = {{"lat_deg", origin.lat_deg},
                        {"lon_deg", origin.lon_deg},
                        {"h_ellipsoid_m", origin.h_ellipsoid_m}};
  const PositionErrors all = positionErrors(r);
  json["horizontal"] = axisJson(all.horizontal);
  json["vertical"] = axisJson(all.vertical);
  std::string out = fmt::format("in local ENU at {:.8f}, {:.8f}, {:.3f} m\n", origin.lat_deg,
                                origin.lon_deg, origin.h_ellipsoid_m);
  out += statsTable("horizontal error (m)", all.horizontal.stats, all.horizontal.p95);
  out += "\n" + statsTable("vertical error |dz| (m)", all.vertical.stats, all.vertical.p95);
  const std::vector<int> quality = in.est.geo ? in.est.geo->quality : std::vector<int>{};
  json["by_quality"] = nlohmann::json::array();
  const auto groups = positionErrorsByQuality(r, quality);
  if (!groups.empty()) {
    out += fmt::format("\n{:<16} {:>7} {:>10} {:>10} {:>10} {:>10}\n", "estimate quality", "n",
                       "h median", "h rmse", "h p95", "v rmse");
  }
  for (const auto& [q, e] : groups) {
    out += fmt::format("{:<16} {:>7} {:>10.4f} {:>10.4f} {:>10.4f} {:>10.4f}\n", io::qualityName(q),
                       e.horizontal.stats.n, e.horizontal.stats.median, e.horizontal.stats.rmse,
                       e.horizontal.p95, e.vertical.stats.rmse);
    json["by_quality"].push_back({{"quality", q},
                                  {"name", io::qualityName(q)},
                                  {"horizontal", axisJson(e.horizontal)},
                                  {"vertical", axisJson(e.vertical)}});
  }
  return out;
}

void writeErrorsCsv(const std::string& file, const EvalResult& r,
                    const std::vector<int>& est_quality) {
  std::string csv = "t_s,ape,dx_m,dy_m,dz_m,quality\n";
  for (std::size_t i = 0; i < r.ref.size(); ++i) {
    const Eigen::Vector3d d = r.est[i].topRightCorner<3, 1>() - r.ref[i].topRightCorner<3, 1>();
    const std::string quality =
        est_quality.empty() ? "" : std::to_string(est_quality.at(r.est_index[i]));
    csv += fmt::format("{},{:.6f},{:.6f},{:.6f},{:.6f},{}\n",
                       r.t_ns.empty() ? std::to_string(i) : io::formatSeconds(r.t_ns[i]), r.ape[i],
                       d.x(), d.y(), d.z(), quality);
  }
  io::writeTextAtomic(file, csv);
}

}  // namespace gvio::eval
