#include "io/bag_dataset.hpp"

#include <fmt/format.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "fusion/gnss_covariance.hpp"
#include "fusion/gnss_screening.hpp"
#include "io/input_error.hpp"
#include "io/ros_image.hpp"

namespace gvio::io {
namespace fs = std::filesystem;
namespace {

// The roles' topics, chosen from the bag's topics and the config.
struct TopicChoice {
  std::vector<std::string> cameras;  // 0, 1 or 2 image topics, left first
  std::string imu, gnss;             // empty: none
};

bool isImageType(const std::string& type) {
  return type == bag::kImageType || type == bag::kCompressedImageType;
}

std::vector<std::string> topicsOfType(const std::vector<bag::TopicInfo>& topics,
                                      bool (*accept)(const std::string&)) {
  std::vector<std::string> out;
  for (const auto& t : topics) {
    if (accept(t.datatype) && t.messages > 0) out.push_back(t.name);
  }
  return out;
}

// Two topics are a stereo pair when they are the same name but for one left/right token.
bool stereoPair(const std::string& a, const std::string& b) {
  static const std::pair<const char*, const char*> kTokens[] = {
      {"left", "right"}, {"0", "1"}, {"1", "2"}, {"l", "r"}};
  for (const auto& [l, r] : kTokens) {
    for (std::size_t pos = a.find(l); pos != std::string::npos; pos = a.find(l, pos + 1)) {
      std::string swapped = a;
      swapped.replace(pos, std::string(l).size(), r);
      if (swapped == b) return true;
    }
  }
  return false;
}

std::string joined(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

std::string onlyTopic(const fs::path& file, const std::vector<std::string>& candidates,
                      const std::string& named, const char* role, const char* key) {
  if (!named.empty()) return named;
  if (candidates.size() > 1) {
    throw InputError(file, 0,
                     fmt::format("{} {} topics ({}): name one with --set dataset.topics.{}=TOPIC",
                                 candidates.size(), role, joined(candidates), key));
  }
  return candidates.empty() ? std::string() : candidates.front();
}

TopicChoice chooseTopics(const fs::path& file, const std::vector<bag::TopicInfo>& topics,
                         const ReaderConfig& config) {
  TopicChoice c;
  if (!config.topic_cam0.empty()) {
    c.cameras.push_back(config.topic_cam0);
    if (!config.topic_cam1.empty()) c.cameras.push_back(config.topic_cam1);
  } else {
    std::vector<std::string> images = topicsOfType(topics, isImageType);
    std::sort(images.begin(), images.end());
    if (images.size() > 2 || (images.size() == 2 && !stereoPair(images[0], images[1]))) {
      throw InputError(file, 0,
                       fmt::format("image topics {} are not one camera or a left/right pair: name "
                                   "them with --set dataset.topics.cam0=TOPIC (and cam1), or give "
                                   "--calib with a camchain naming each camera's rostopic",
                                   joined(images)));
    }
    c.cameras = images;
  }
  c.imu =
      onlyTopic(file, topicsOfType(topics, [](const std::string& t) { return t == bag::kImuType; }),
                config.topic_imu, "IMU", "imu");
  c.gnss = onlyTopic(
      file, topicsOfType(topics, [](const std::string& t) { return t == bag::kNavSatFixType; }),
      config.topic_gnss, "NavSatFix", "gnss");
  return c;
}

// A stream's messages in header-stamp order: (stamp, index in bag order). Header stamps of 0 are
// replaced by the receive time; repeated stamps keep their first message.
std::vector<std::pair<std::int64_t, std::size_t>> ordered(const std::vector<bag::Stamps>& stamps,
                                                          BagTopicUse& use) {
  std::vector<std::pair<std::int64_t, std::size_t>> out;
  out.reserve(stamps.size());
  std::int64_t latest = std::numeric_limits<std::int64_t>::min();
  for (std::size_t i = 0; i < stamps.size(); ++i) {
    std::int64_t t = stamps[i].header_ns;
    if (t == 0) {
      t = stamps[i].receive_ns;
      ++use.zero_stamps;
    }
    if (t < latest) ++use.out_of_order;
    latest = std::max(latest, t);
    out.emplace_back(t, i);
  }
  std::stable_sort(out.begin(), out.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  const auto last = std::unique(out.begin(), out.end(),
                                [](const auto& a, const auto& b) { return a.first == b.first; });
  use.duplicate_stamps = static_cast<std::size_t>(out.end() - last);
  out.erase(last, out.end());
  return out;
}

template <typename Message>
std::vector<bag::Stamps> stampsOf(const std::vector<Message>& messages) {
  std::vector<bag::Stamps> out;
  out.reserve(messages.size());
  for (const auto& m : messages) out.push_back(m.t);
  return out;
}

BagTopicUse topicUse(const std::vector<bag::TopicInfo>& topics, const std::string& role,
                     const std::string& name) {
  BagTopicUse use;
  use.role = role;
  use.topic = name;
  for (const auto& t : topics) {
    if (t.name == name) {
      use.type = t.datatype;
      use.messages = t.messages;
    }
  }
  return use;
}

// The attitude an Imu message reports, when its covariance says it is valid (Imu.msg: element 0
// = -1 for none; an all-zero covariance is "unknown": no yaw sigma, not used) and the quaternion
// is a rotation.
std::optional<fusion::ImuAttitude> reportedAttitude(const bag::ImuMessage& m, std::int64_t t_ns) {
  const auto& cov = m.orientation_covariance;
  const std::optional<Eigen::Matrix3d> R = messageRotation(m.orientation_xyzw);
  if (cov[0] < 0.0 || !std::isfinite(cov[8]) || !(cov[8] > 0.0) || !R) return std::nullopt;
  return fusion::ImuAttitude{t_ns, *R, std::sqrt(cov[8])};
}

void readImu(const fs::path& file, const BagSource& reader, const std::string& topic, Dataset& ds) {
  const std::vector<bag::ImuMessage> messages = reader.readImu(topic);
  BagTopicUse& use = ds.bag_topics.back();
  for (const auto& [t_ns, i] : ordered(stampsOf(messages), use)) {
    const bag::ImuMessage& m = messages[i];
    ImuSample s;
    s.t_ns = t_ns;
    s.acc_b_mps2 = {m.acc_mps2[0], m.acc_mps2[1], m.acc_mps2[2]};
    s.gyr_b_radps = {m.gyr_radps[0], m.gyr_radps[1], m.gyr_radps[2]};
    if (!s.acc_b_mps2.allFinite() || !s.gyr_b_radps.allFinite()) {
      throw InputError(file, 0,
                       fmt::format("topic {}: message {} holds a non-finite value", topic, i));
    }
    ds.imu.push_back(s);
    if (const auto attitude = reportedAttitude(m, t_ns)) ds.imu_attitude.push_back(*attitude);
  }
  use.used = ds.imu.size();
}

// NavSatFix status to NMEA quality: FIX 1 (SPP), SBAS 2 (DGPS), GBAS 4 or 5 (drivers report RTK
// fixed and float alike as GBAS: a stated sigma under 0.1 m counts as fixed).
void readGnss(const BagSource& reader, const std::string& topic, const ReaderConfig& config,
              Dataset& ds) {
  const std::vector<bag::NavSatFixMessage> messages = reader.readNavSatFix(topic);
  BagTopicUse& use = ds.bag_topics.back();
  std::size_t no_fix = 0;
  for (const auto& [t_ns, i] : ordered(stampsOf(messages), use)) {
    const bag::NavSatFixMessage& m = messages[i];
    // No fix (status -1, or NaN as drivers write for none), or a position off the globe (a
    // damaged message; a fuzz finding): skipped and counted, as the EuRoC GNSS reader does.
    if (m.status < 0 || !std::isfinite(m.lat_deg) || !std::isfinite(m.lon_deg) ||
        !std::isfinite(m.alt_m) || fusion::latLonOutOfRange(m.lat_deg, m.lon_deg)) {
      ++no_fix;
      continue;
    }
    GnssFix fix;
    fix.t_ns = t_ns;
    fix.lat_deg = m.lat_deg;
    fix.lon_deg = m.lon_deg;
    fix.h_ellipsoid_m = m.alt_m;  // REP 145 / NavSatFix: above the WGS84 ellipsoid
    const auto& cov = m.covariance_enu_m2;
    const bool stated = m.covariance_type > 0 && std::isfinite(cov[0]) && std::isfinite(cov[4]) &&
                        std::isfinite(cov[8]) && cov[0] > 0.0 && cov[4] > 0.0 && cov[8] > 0.0;
    const double stated_h = stated ? std::sqrt(0.5 * (cov[0] + cov[4])) : 0.0;
    fix.quality = m.status == 0 ? 1 : m.status == 1 ? 2 : (stated && stated_h < 0.1 ? 4 : 5);
    const double floor_h = config.uereM(fix.quality);
    Eigen::Matrix2d cov_en = Eigen::Matrix2d::Zero();  // none stated: the floor's circle
    if (stated) {  // east-north correlation only where the whole covariance is known
      const double en = m.covariance_type == 3 && std::isfinite(cov[1]) ? cov[1] : 0.0;
      cov_en << cov[0], en, en, cov[4];
    }
    const fusion::HorizontalError h = fusion::flooredHorizontal(cov_en, floor_h);
    fix.sigma_h_m = h.sigma_m;
    fix.shape_en = h.shape_en;
    fix.sigma_v_m =
        std::max(stated ? std::sqrt(cov[8]) : 0.0, floor_h * config.nmea_vertical_factor);
    ds.gnss.push_back(fix);
  }
  use.used = ds.gnss.size();
  if (no_fix > 0) {
    ds.warnings.push_back(
        fmt::format("{}: topic {}: {} messages without a fix skipped (status -1, or a position "
                    "not finite or out of range)",
                    ds.root.string(), topic, no_fix));
  }
  if (!ds.gnss.empty()) ds.gnss_source = ds.root.string() + ":" + topic;
}

class BagImages final : public ImageStore {
 public:
  BagImages(fs::path file, std::shared_ptr<const BagSource> reader, std::vector<std::string> topics)
      : file_(std::move(file)), reader_(std::move(reader)), topics_(std::move(topics)) {}

  // Message index of each camera's image, per frame.
  std::vector<std::vector<std::size_t>> messages;

  cv::Mat load(std::size_t frame, std::size_t camera, const CameraModel& model) const override {
    const std::string& topic = topics_.at(camera);
    const std::size_t index = messages.at(frame).at(camera);
    const auto fail = [&](const std::string& what) {
      return InputError(file_, 0, fmt::format("topic {}: image {}: {}", topic, index, what));
    };
    cv::Mat gray;
    try {
      gray = rosImageToGray(reader_->readImage(topic, index));
    } catch (const bag::BagError& e) {
      throw fail(e.what());
    } catch (const InvalidInput& e) {
      throw fail(e.what());
    }
    if (gray.cols != model.width_px || gray.rows != model.height_px) {
      throw fail(fmt::format("{}x{} pixels, calibrated for {}x{}", gray.cols, gray.rows,
                             model.width_px, model.height_px));
    }
    return gray;
  }

  std::string source(std::size_t camera) const override {
    return file_.string() + ":" + topics_.at(camera);
  }

 private:
  fs::path file_;
  std::shared_ptr<const BagSource> reader_;
  std::vector<std::string> topics_;
};

// Frames: the first camera's images in stamp order, each paired with the second camera's image
// nearest in time within the sync tolerance (unpaired ones are dropped and counted).
void readFrames(const fs::path& file, const std::shared_ptr<const BagSource>& reader,
                const std::vector<std::string>& topics, const ReaderConfig& config,
                const std::vector<bag::TopicInfo>& infos, Dataset& ds) {
  auto store = std::make_shared<BagImages>(file, reader, topics);
  std::vector<std::vector<std::pair<std::int64_t, std::size_t>>> streams;
  for (std::size_t c = 0; c < topics.size(); ++c) {
    ds.bag_topics.push_back(topicUse(infos, "cam" + std::to_string(c), topics[c]));
    streams.push_back(ordered(reader->imageStamps(topics[c]), ds.bag_topics.back()));
  }
  const auto tolerance_ns =
      static_cast<std::int64_t>(std::llround(config.stereo_sync_tolerance_s * 1e9));
  std::size_t j = 0;
  for (const auto& [t_ns, index] : streams[0]) {
    std::vector<std::size_t> message{index};
    if (streams.size() == 2) {
      const auto& right = streams[1];
      while (j + 1 < right.size() &&
             std::llabs(right[j + 1].first - t_ns) <= std::llabs(right[j].first - t_ns)) {
        ++j;
      }
      if (j >= right.size() || std::llabs(right[j].first - t_ns) > tolerance_ns) continue;
      message.push_back(right[j].second);
    }
    FrameRecord frame;
    frame.t_ns = t_ns;
    ds.frames.push_back(frame);
    store->messages.push_back(std::move(message));
  }
  for (std::size_t c = 0; c < topics.size(); ++c) {
    ds.bag_topics[ds.bag_topics.size() - topics.size() + c].used = ds.frames.size();
  }
  if (streams.size() == 2 && ds.frames.size() < streams[0].size()) {
    ds.warnings.push_back(fmt::format(
        "{}: {} of {} images on {} have no image on {} within {} s: those frames are dropped",
        file.string(), streams[0].size() - ds.frames.size(), streams[0].size(), topics[0],
        topics[1], config.stereo_sync_tolerance_s));
  }
  // The cameras as far as the bag tells: names and image sizes (from each topic's first image,
  // which also checks its encoding now rather than mid-run); intrinsics come from --calib.
  for (std::size_t c = 0; c < topics.size(); ++c) {
    CameraModel cam;
    cam.name = "cam" + std::to_string(c);
    if (!ds.frames.empty()) {
      const std::size_t first = store->messages.front()[c];
      try {
        const cv::Mat image = rosImageToGray(reader->readImage(topics[c], first));
        cam.width_px = image.cols;
        cam.height_px = image.rows;
      } catch (const std::exception& e) {
        throw InputError(file, 0,
                         fmt::format("topic {}: image {}: {}", topics[c], first, e.what()));
      }
    }
    ds.cameras.push_back(cam);
  }
  if (!ds.frames.empty()) ds.image_store = std::move(store);
}

}  // namespace

std::optional<Eigen::Matrix3d> messageRotation(const std::array<double, 4>& xyzw) {
  const Eigen::Quaterniond q(xyzw[3], xyzw[0], xyzw[1], xyzw[2]);
  const double norm = q.norm();
  if (!std::isfinite(norm) || std::abs(norm - 1.0) > 1e-3) return std::nullopt;
  return q.normalized().toRotationMatrix();
}

void readBagDataset(const fs::path& file, const std::shared_ptr<const BagSource>& source,
                    const ReaderConfig& config, Dataset& ds) {
  try {
    const std::vector<bag::TopicInfo> infos = source->topics();
    const TopicChoice topics = chooseTopics(file, infos, config);
    ds.variant = fmt::format("{}, {} camera(s)", ds.variant, topics.cameras.size());
    if (!topics.cameras.empty()) readFrames(file, source, topics.cameras, config, infos, ds);
    if (!topics.imu.empty()) {
      ds.bag_topics.push_back(topicUse(infos, "imu", topics.imu));
      readImu(file, *source, topics.imu, ds);
    }
    if (!topics.gnss.empty()) {
      ds.bag_topics.push_back(topicUse(infos, "gnss", topics.gnss));
      readGnss(*source, topics.gnss, config, ds);
    }
  } catch (const bag::BagError& e) {
    throw InputError(file, 0, e.what());
  }
  for (const BagTopicUse& use : ds.bag_topics) {
    if (use.out_of_order + use.duplicate_stamps + use.zero_stamps == 0) continue;
    ds.warnings.push_back(fmt::format(
        "{}: topic {}: {} messages out of order (sorted by header stamp), {} repeated stamps "
        "(dropped), {} zero header stamps (receive time used)",
        file.string(), use.topic, use.out_of_order, use.duplicate_stamps, use.zero_stamps));
  }
}

}  // namespace gvio::io
