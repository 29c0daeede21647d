#pragma once
// Options of the dataset readers (YAML section `dataset:`). Plain struct with defaults.
#include <string>

namespace gvio::io {

struct ReaderConfig {
  // KITTI raw: where GNSS comes from. auto = gnss/fixes.nmea when present, else oxts lat/lon/alt.
  std::string kitti_gnss_source = "auto";  // auto | nmea | oxts
  // A gap in a sensor stream is reported when a period exceeds gap_factor x the median period.
  double gap_factor = 2.5;
  // NMEA GGA carries no standard deviation: without a GST sentence the 1-sigma horizontal error is
  // HDOP x this user-equivalent range error, chosen by fix quality.
  double nmea_uere_spp_m = 1.5;
  double nmea_uere_dgps_m = 0.7;
  double nmea_uere_rtk_float_m = 0.3;
  double nmea_uere_rtk_fixed_m = 0.02;
  // Vertical sigma = horizontal sigma x this (VDOP is typically 1.5-2 x HDOP).
  double nmea_vertical_factor = 2.0;
  // Sentences whose checksum is wrong or missing. refuse: a few (at most 1 % of the sentences and
  // at most half of any one type: line noise) are left out with a warning, more refuse the log
  // with the counts per type (a logger that writes every RMC with a wrong checksum); warn: read
  // as they are, with a warning and the counts; skip: always left out, with a warning.
  std::string nmea_checksum = "refuse";  // refuse | warn | skip
  // The horizontal error ellipse a GNSS source states (RTKLIB sdn/sde/sdne, NMEA GST's ellipse, a
  // NavSatFix's full covariance): stated = fused as the receiver states it; circle = each fix a
  // circle of its horizontal sigma (sqrt of half the stated covariance's trace).
  std::string gnss_ellipse = "stated";  // stated | circle
  // comma2k19's u-blox CSV has no accuracy columns: 1-sigma horizontal (per axis) and vertical.
  double comma2k19_sigma_h_m = 1.0;
  double comma2k19_sigma_v_m = 2.0;
  // ROS bags (dataset.topics.*): the topic of each role; empty = the only topic of the role's
  // message type (two image topics that differ only in 0/1, 1/2, left/right or l/r are a stereo
  // pair), or the one the Kalibr camchain's rostopic names.
  std::string topic_cam0, topic_cam1, topic_imu, topic_gnss;
  // Two cameras' images are one stereo frame when their stamps differ by at most this.
  double stereo_sync_tolerance_s = 0.003;

  void validate() const;  // throws InvalidInput naming the key
  // The 1-sigma horizontal UERE of an NMEA fix quality (the nmea_uere_* above; SPP for any
  // quality not named there): NMEA's HDOP model, and the floor under a stated sigma.
  [[nodiscard]] double uereM(int quality) const;
};

}  // namespace gvio::io
