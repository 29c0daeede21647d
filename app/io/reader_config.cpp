#include "io/reader_config.hpp"

#include <cmath>

#include "odometry/error.hpp"

namespace gvio::io {
namespace {

void requirePositive(double value, const char* key) {
  if (!std::isfinite(value) || value <= 0.0) {
    throw InvalidInput(std::string("config: ") + key + " must be a positive number (got " +
                       std::to_string(value) + ")");
  }
}

}  // namespace

double ReaderConfig::uereM(int quality) const {
  switch (quality) {
    case 2:
      return nmea_uere_dgps_m;
    case 4:
      return nmea_uere_rtk_fixed_m;
    case 5:
      return nmea_uere_rtk_float_m;
    default:
      return nmea_uere_spp_m;
  }
}

void ReaderConfig::validate() const {
  if (kitti_gnss_source != "auto" && kitti_gnss_source != "nmea" && kitti_gnss_source != "oxts") {
    throw InvalidInput("config: dataset.kitti_gnss_source must be auto, nmea or oxts (got '" +
                       kitti_gnss_source + "')");
  }
  if (!(gap_factor > 1.0) || !std::isfinite(gap_factor)) {
    throw InvalidInput("config: dataset.gap_factor must be > 1 (got " + std::to_string(gap_factor) +
                       ")");
  }
  requirePositive(nmea_uere_spp_m, "dataset.nmea_uere_spp_m");
  requirePositive(nmea_uere_dgps_m, "dataset.nmea_uere_dgps_m");
  requirePositive(nmea_uere_rtk_float_m, "dataset.nmea_uere_rtk_float_m");
  requirePositive(nmea_uere_rtk_fixed_m, "dataset.nmea_uere_rtk_fixed_m");
  requirePositive(nmea_vertical_factor, "dataset.nmea_vertical_factor");
  if (nmea_checksum != "refuse" && nmea_checksum != "warn" && nmea_checksum != "skip") {
    throw InvalidInput("config: dataset.nmea_checksum must be refuse, warn or skip (got '" +
                       nmea_checksum + "')");
  }
  if (gnss_ellipse != "stated" && gnss_ellipse != "circle") {
    throw InvalidInput("config: dataset.gnss_ellipse must be stated or circle (got '" +
                       gnss_ellipse + "')");
  }
  requirePositive(comma2k19_sigma_h_m, "dataset.comma2k19_sigma_h_m");
  requirePositive(comma2k19_sigma_v_m, "dataset.comma2k19_sigma_v_m");
  if (!std::isfinite(stereo_sync_tolerance_s) || stereo_sync_tolerance_s < 0.0) {
    throw InvalidInput("config: dataset.stereo_sync_tolerance_s must be >= 0 (got " +
                       std::to_string(stereo_sync_tolerance_s) + ")");
  }
  if (topic_cam0.empty() && !topic_cam1.empty()) {
    throw InvalidInput("config: dataset.topics.cam1 is set but dataset.topics.cam0 is not");
  }
}

}  // namespace gvio::io
