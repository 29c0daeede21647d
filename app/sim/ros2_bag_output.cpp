#include "sim/ros2_bag_output.hpp"

#include <Eigen/Geometry>

#include "io/atomic_write.hpp"
#include "io/input_error.hpp"
#include "io/kalibr_writer.hpp"
#include "io/ros2/ros2_error.hpp"
#include "io/ros2/ros2_messages.hpp"
#include "io/ros_image.hpp"
#include "sim/bag_output.hpp"

namespace gvio::sim {
namespace {
namespace fs = std::filesystem;
namespace ros2 = io::ros2;

const char* const kImageTopics[] = {"/cam0/image_raw", "/cam1/image_raw"};
const char* const kInfoTopics[] = {"/cam0/camera_info", "/cam1/camera_info"};
constexpr const char* kImuTopic = "/imu0";
constexpr const char* kImuFrame = "imu";
constexpr const char* kGnssFrame = "gnss";

ros2::TransformMessage transform(std::int64_t t_ns, const std::string& child,
                                 const Eigen::Isometry3d& T_imu_child) {
  ros2::TransformMessage m;
  m.t = {t_ns, t_ns};
  m.frame_id = kImuFrame;
  m.child_frame_id = child;
  const Eigen::Quaterniond q(T_imu_child.rotation());
  m.rotation_xyzw = {q.x(), q.y(), q.z(), q.w()};
  m.translation = {T_imu_child.translation().x(), T_imu_child.translation().y(),
                   T_imu_child.translation().z()};
  return m;
}

// A rectified camera's CameraInfo: K, identity R, P = K [I | t] with t the camera's offset from
// the first camera in its frame (P's fourth column -fx * baseline for a right camera).
ros2::CameraInfoMessage cameraInfo(const CameraModel& cam, const CameraModel& first) {
  ros2::CameraInfoMessage m;
  m.frame_id = cam.name;
  m.width = static_cast<std::uint32_t>(cam.width_px);
  m.height = static_cast<std::uint32_t>(cam.height_px);
  m.distortion_model = "plumb_bob";
  m.d = {0.0, 0.0, 0.0, 0.0, 0.0};
  m.k = {cam.fx, 0.0, cam.cx, 0.0, cam.fy, cam.cy, 0.0, 0.0, 1.0};
  m.r = {1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0};
  const Eigen::Vector3d t = (cam.T_b_c.inverse() * first.T_b_c).translation();  // first in cam
  m.p = {cam.fx, 0.0, cam.cx, cam.fx * t.x(), 0.0, cam.fy, cam.cy, cam.fy * t.y(),
         0.0,    0.0, 1.0,    t.z()};
  return m;
}

}  // namespace

Ros2BagOutput::Ros2BagOutput(const fs::path& out, const SimConfig& config,
                             const std::vector<CameraModel>& cameras, std::vector<ImuSimSample> imu,
                             std::vector<GnssFix> fixes)
    : out_(out),
      cameras_(cameras),
      imu_(std::move(imu)),
      fixes_(std::move(fixes)),
      lever_arm_b_(config.gnss_lever_arm_m) {
  for (std::size_t c = 0; c < cameras_.size(); ++c) {
    cameras_[c].name = "cam" + std::to_string(c);  // the camera frames' names in the tf tree
    cameras_[c].T_b_c = asEurocWrites(cameras_[c].T_b_c);
  }
  try {
    writer_ = std::make_unique<ros2::Ros2BagWriter>(out, "drive",
                                                    config.ros2bag_storage == "sqlite3"
                                                        ? ros2::Ros2Storage::kSqlite3
                                                        : ros2::Ros2Storage::kMcap,
                                                    config.ros2bag_compression);
    for (std::size_t c = 0; c < cameras_.size(); ++c) {
      topics_.images[c] = writer_->addTopic(kImageTopics[c], ros2::kRos2ImageType);
      topics_.infos[c] = writer_->addTopic(kInfoTopics[c], ros2::kRos2CameraInfoType);
    }
    topics_.imu = writer_->addTopic(kImuTopic, ros2::kRos2ImuType);
    topics_.gnss = writer_->addTopic("/gnss/fix", ros2::kRos2NavSatFixType);
    topics_.tf = writer_->addTopic("/tf_static", ros2::kRos2TfType);
  } catch (const io::bag::BagError& e) {
    throw io::InputError(out, 0, e.what());
  }
}

Ros2BagOutput::~Ros2BagOutput() = default;

void Ros2BagOutput::writeSensorsUpTo(std::int64_t t_ns) {
  if (!tf_written_) {
    // /tf_static is latched: one message at the start holds every fixed link.
    const std::int64_t t0 = imu_.empty() ? t_ns : std::min(t_ns, imu_.front().measured.t_ns);
    std::vector<ros2::TransformMessage> links;
    for (const CameraModel& cam : cameras_) links.push_back(transform(t0, cam.name, cam.T_b_c));
    Eigen::Isometry3d T_imu_gnss = Eigen::Isometry3d::Identity();
    T_imu_gnss.translation() = lever_arm_b_;
    links.push_back(transform(t0, kGnssFrame, T_imu_gnss));
    writer_->write(topics_.tf, t0, ros2::encodeTfMessage(links));
    tf_written_ = true;
  }
  for (; next_imu_ < imu_.size() && imu_[next_imu_].measured.t_ns <= t_ns; ++next_imu_) {
    ros2::Ros2Imu m;
    m.imu = bagImuMessage(imu_[next_imu_]);
    m.frame_id = kImuFrame;
    writer_->write(topics_.imu, m.imu.t.header_ns, ros2::encodeImu(m));
  }
  for (; next_fix_ < fixes_.size() && fixes_[next_fix_].t_ns <= t_ns; ++next_fix_) {
    ros2::Ros2NavSatFix m;
    m.fix = bagFixMessage(fixes_[next_fix_]);
    m.service = 1;  // SERVICE_GPS
    m.frame_id = kGnssFrame;
    writer_->write(topics_.gnss, m.fix.t.header_ns, ros2::encodeNavSatFix(m));
  }
}

void Ros2BagOutput::writeImage(std::int64_t t_ns, std::size_t camera, const cv::Mat& gray) {
  try {
    writeSensorsUpTo(t_ns);
    ros2::Ros2Image image;
    image.image = io::grayToRosImage(gray, false);
    image.image.t = {t_ns, t_ns};
    image.frame_id = cameras_.at(camera).name;
    writer_->write(topics_.images[camera], t_ns, ros2::encodeImage(image));
    ros2::CameraInfoMessage info = cameraInfo(cameras_[camera], cameras_.front());
    info.t = {t_ns, t_ns};
    writer_->write(topics_.infos[camera], t_ns, ros2::encodeCameraInfo(info));
  } catch (const io::bag::BagError& e) {
    throw io::InputError(out_, 0, e.what());
  }
}

void Ros2BagOutput::finish(const ImuNoise& noise, double imu_rate_hz) {
  try {
    writeSensorsUpTo(std::numeric_limits<std::int64_t>::max());
    writer_->close();
  } catch (const io::bag::BagError& e) {
    throw io::InputError(out_, 0, e.what());
  }
  std::vector<std::string> topics;
  for (std::size_t c = 0; c < cameras_.size(); ++c) topics.emplace_back(kImageTopics[c]);
  io::writeTextAtomic(out_ / "camchain.yaml", io::kalibrCamchainYaml(cameras_, topics, 0.0));
  io::writeTextAtomic(out_ / "imu.yaml", io::kalibrImuYaml(noise, imu_rate_hz, kImuTopic));
}

}  // namespace gvio::sim
