#include "export/georef.hpp"

#include <fstream>
#include <nlohmann/json.hpp>

#include "io/input_error.hpp"

namespace gvio::exporter {

Georef readGeoref(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw io::InputError(file, 0, "cannot read");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw io::InputError(file, 0, std::string("not valid JSON: ") + e.what());
  }
  Georef g;
  try {
    const nlohmann::json& o = j.at("enu_origin");
    g.enu_origin = {o.at("lat_deg").get<double>(), o.at("lon_deg").get<double>(),
                    o.at("h_ellipsoid_m").get<double>()};
    if (!fusion::isValidLla(g.enu_origin)) {
      throw io::InputError(file, 0, "enu_origin is not a valid lat/lon/h");
    }
    const fusion::Utm standard = fusion::llaToUtm(g.enu_origin);
    g.utm_zone = standard.zone;
    g.utm_north = standard.north;
    if (j.contains("utm")) {
      g.utm_zone = j["utm"].at("zone").get<int>();
      g.utm_north = j["utm"].at("north").get<bool>();
      if (g.utm_zone < 1 || g.utm_zone > 60) {
        throw io::InputError(file, 0, "utm.zone " + std::to_string(g.utm_zone) + " not in 1..60");
      }
    }
  } catch (const nlohmann::json::exception& e) {
    // e.g. "[json.exception.out_of_range.403] key 'lat_deg' not found"
    throw io::InputError(file, 0, std::string("malformed georef: ") + e.what());
  } catch (const io::InputError&) {
    throw;
  } catch (const InvalidInput& e) {  // origin outside UTM's latitude band
    throw io::InputError(file, 0, e.what());
  }
  return g;
}

}  // namespace gvio::exporter
