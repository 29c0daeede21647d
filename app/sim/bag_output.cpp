#include "sim/bag_output.hpp"

#include <fmt/format.h>

#include <charconv>
#include <string>

#include "io/atomic_write.hpp"
#include "io/input_error.hpp"
#include "io/kalibr_writer.hpp"
#include "io/ros_image.hpp"
#include "sim/gnss_synth.hpp"

namespace gvio::sim {
namespace {
namespace fs = std::filesystem;

const char* const kImageTopics[] = {"/cam0/image_raw", "/cam1/image_raw"};
constexpr const char* kImuTopic = "/imu0";
constexpr const char* kGnssTopic = "/gnss/fix";

io::bag::Stamps stamps(std::int64_t t_ns) {
  return {t_ns, t_ns};
}

// x rounded to `decimals` decimal places: the very double a text reader gets from the EuRoC
// writer's "{:.<decimals>f}" (through the same decimal text: x * 10^d in binary can round the
// other way at a tie).
double rounded(double x, int decimals) {
  const std::string text = fmt::format("{:.{}f}", x, decimals);
  double value = 0.0;
  std::from_chars(text.data(), text.data() + text.size(), value);
  return value;
}

// NMEA quality to NavSatFix status: RTK fixed and float are GBAS fixes (as ROS drivers report
// them), DGPS an SBAS fix, anything else a plain fix.
int navSatStatus(int quality) {
  if (quality == 4 || quality == 5) return 2;
  if (quality == 2) return 1;
  return 0;
}

}  // namespace

io::bag::ImuMessage bagImuMessage(const ImuSimSample& s) {
  io::bag::ImuMessage m;
  m.t = stamps(s.measured.t_ns);
  for (int i = 0; i < 3; ++i) {
    m.acc_mps2[static_cast<std::size_t>(i)] = rounded(s.measured.acc_b_mps2[i], 12);
    m.gyr_radps[static_cast<std::size_t>(i)] = rounded(s.measured.gyr_b_radps[i], 12);
  }
  return m;
}

io::bag::NavSatFixMessage bagFixMessage(const GnssFix& f) {
  io::bag::NavSatFixMessage m;
  m.t = stamps(f.t_ns);
  m.status = navSatStatus(f.quality);
  m.lat_deg = rounded(f.lat_deg, 10);
  m.lon_deg = rounded(f.lon_deg, 10);
  m.alt_m = rounded(f.h_ellipsoid_m, 4);
  const double sigma_h = rounded(f.sigma_h_m, 4), sigma_v = rounded(f.sigma_v_m, 4);
  if (f.shape_en == Eigen::Matrix2d::Identity()) {
    m.covariance_enu_m2 = {sigma_h * sigma_h, 0, 0, 0, sigma_h * sigma_h, 0, 0, 0,
                           sigma_v * sigma_v};
    m.covariance_type = 2;  // COVARIANCE_TYPE_DIAGONAL_KNOWN
    return m;
  }
  const Eigen::Matrix2d cov = sigma_h * sigma_h * f.shape_en;  // a replayed receiver's ellipse
  m.covariance_enu_m2 = {cov(0, 0), cov(0, 1), 0, cov(1, 0), cov(1, 1), 0, 0, 0, sigma_v * sigma_v};
  m.covariance_type = 3;  // COVARIANCE_TYPE_KNOWN
  return m;
}

Eigen::Isometry3d asEurocWrites(const Eigen::Isometry3d& T_b_c) {
  Eigen::Isometry3d T = T_b_c;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) T.matrix()(r, c) = rounded(T_b_c.matrix()(r, c), 12);
  }
  return T;
}

BagOutput::BagOutput(const fs::path& out)
    : out_(out), temporary_(out / (std::string(kBagFileName) + ".tmp")) {
  try {
    writer_ = std::make_unique<io::bag::BagWriter>(temporary_.string(), io::bag::Compression::kLz4);
  } catch (const io::bag::BagError& e) {
    throw io::InputError(temporary_, 0, e.what());
  }
}

void BagOutput::writeImage(std::int64_t t_ns, std::size_t camera, const cv::Mat& gray) {
  io::bag::ImageMessage m = io::grayToRosImage(gray, false);
  m.t = stamps(t_ns);
  try {
    writer_->write(kImageTopics[camera], m);
  } catch (const io::bag::BagError& e) {
    throw io::InputError(temporary_, 0, e.what());
  }
}

void BagOutput::finish(const std::vector<ImuSimSample>& imu, const std::vector<GnssFix>& fixes,
                       const std::vector<CameraModel>& cameras, const ImuNoise& noise,
                       double imu_rate_hz) {
  try {
    for (const ImuSimSample& s : imu) writer_->write(kImuTopic, bagImuMessage(s));
    for (const GnssFix& f : fixes) writer_->write(kGnssTopic, bagFixMessage(f));
    writer_->close();
  } catch (const io::bag::BagError& e) {
    throw io::InputError(temporary_, 0, e.what());
  }
  std::error_code ec;
  fs::rename(temporary_, out_ / kBagFileName, ec);
  if (ec) throw io::InputError(out_ / kBagFileName, 0, "cannot write the bag: " + ec.message());
  std::vector<CameraModel> calibrated = cameras;
  std::vector<std::string> topics;
  for (std::size_t c = 0; c < calibrated.size(); ++c) {
    calibrated[c].T_b_c = asEurocWrites(calibrated[c].T_b_c);
    topics.emplace_back(kImageTopics[c]);
  }
  io::writeTextAtomic(out_ / "camchain.yaml", io::kalibrCamchainYaml(calibrated, topics, 0.0));
  io::writeTextAtomic(out_ / "imu.yaml", io::kalibrImuYaml(noise, imu_rate_hz, kImuTopic));
  // The bag's fixes again as RTKLIB writes a solution: what a rig's post-processed GNSS looks like
  // beside its bag (`gvio run --gnss-file drive.pos`).
  io::writeTextAtomic(out_ / "drive.pos", toRtklibPos(fixes));
}

}  // namespace gvio::sim
