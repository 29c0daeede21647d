#include "io/ros2/bag_calibration.hpp"

#include <fmt/format.h>

#include <cmath>

#include "io/bag_dataset.hpp"
#include "io/ros2/ros2_error.hpp"
#include "io/ros2/ros2_messages.hpp"
#include "io/ros2/tf_tree.hpp"

namespace gvio::io::ros2 {
namespace {

Eigen::Isometry3d isometry(const TransformMessage& m, const std::string& topic) {
  const std::optional<Eigen::Matrix3d> R = messageRotation(m.rotation_xyzw);
  const Eigen::Vector3d t(m.translation[0], m.translation[1], m.translation[2]);
  if (!R || !t.allFinite()) {
    const auto& q = m.rotation_xyzw;
    throw Ros2Error(
        fmt::format("{}: the transform {} -> {} is not a rigid motion (quaternion "
                    "norm {}, translation finite: {})",
                    topic, m.frame_id, m.child_frame_id,
                    Eigen::Quaterniond(q[3], q[0], q[1], q[2]).norm(), t.allFinite()));
  }
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = *R;
  T.translation() = t;
  return T;
}

bool sameTransform(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return (a.matrix() - b.matrix()).cwiseAbs().maxCoeff() < 1e-9;
}

// /tf_static's links, and those of /tf whose every sample is the same (a fixed joint published
// on /tf); the links of /tf that move are left out (a moving camera has no fixed extrinsic).
TfTree staticTree(const Ros2Bag& bag, std::vector<std::string>& warnings) {
  TfTree tree;
  for (const Ros2Topic& topic : bag.topics()) {
    if (topic.type != kRos2TfType) continue;
    const bool is_static = topic.name.ends_with("tf_static");
    std::vector<TfLink> links;
    std::vector<bool> moves;
    for (std::size_t i = 0; i < topic.messages.size(); ++i) {
      for (const TransformMessage& m : decodeMessage(bag, topic, i, decodeTfMessage)) {
        TfLink link{tfFrame(m.frame_id), tfFrame(m.child_frame_id), isometry(m, topic.name),
                    topic.name};
        std::size_t k = 0;
        while (k < links.size() && (links[k].parent != link.parent || links[k].child != link.child))
          ++k;
        if (k == links.size()) {
          links.push_back(link);
          moves.push_back(false);
        } else if (is_static) {
          links[k] = link;  // a later static transform replaces the earlier (tf2's static buffer)
        } else if (!sameTransform(links[k].T_parent_child, link.T_parent_child)) {
          moves[k] = true;
        }
      }
    }
    for (std::size_t k = 0; k < links.size(); ++k) {
      if (moves[k]) continue;
      if (!is_static) links[k].source = topic.name + " (constant)";
      if (const auto refused = tree.add(links[k])) warnings.push_back(topic.name + ": " + *refused);
    }
  }
  return tree;
}

// image_transport's layout: <ns>/image_raw[/compressed] beside <ns>/camera_info.
std::string cameraInfoTopic(std::string image_topic) {
  if (image_topic.ends_with("/compressed")) image_topic.resize(image_topic.size() - 11);
  const std::size_t slash = image_topic.find_last_of('/');
  return (slash == std::string::npos ? std::string() : image_topic.substr(0, slash)) +
         "/camera_info";
}

bool isRectifiedTopic(const std::string& image_topic) {
  const std::size_t slash = image_topic.find_last_of('/');
  return image_topic.substr(slash == std::string::npos ? 0 : slash + 1).starts_with("image_rect");
}

Eigen::Matrix3d matrix3(const std::array<double, 9>& m) {
  Eigen::Matrix3d out;
  out << m[0], m[1], m[2], m[3], m[4], m[5], m[6], m[7], m[8];
  return out;
}

// The intrinsics of `info` for images of `cam`'s size (the raw camera, or the rectified one).
void setIntrinsics(const CameraInfoMessage& info, bool rectified, const std::string& topic,
                   CameraModel& cam) {
  if (info.width != static_cast<std::uint32_t>(cam.width_px) ||
      info.height != static_cast<std::uint32_t>(cam.height_px)) {
    throw Ros2Error(fmt::format("{} is for {}x{} pixels, the images are {}x{}", topic, info.width,
                                info.height, cam.width_px, cam.height_px));
  }
  const bool full_roi =
      info.roi.width == 0 || (info.roi.width == info.width && info.roi.height == info.height);
  if (info.binning_x > 1 || info.binning_y > 1 || !full_roi) {
    throw Ros2Error(
        fmt::format("{}: binned or cropped images (binning {}x{}, region {}x{}) are "
                    "not supported: record full images",
                    topic, info.binning_x, info.binning_y, info.roi.width, info.roi.height));
  }
  cam.distortion.clear();
  cam.distortion_model = Distortion::kRadtan;
  if (rectified) {
    cam.fx = info.p[0], cam.fy = info.p[5], cam.cx = info.p[2], cam.cy = info.p[6];
    return;
  }
  cam.fx = info.k[0], cam.fy = info.k[4], cam.cx = info.k[2], cam.cy = info.k[5];
  const std::string& model = info.distortion_model;
  const std::size_t n = info.d.size();
  const bool none = std::all_of(info.d.begin(), info.d.end(), [](double d) { return d == 0.0; });
  if ((model == "plumb_bob" && (n == 5 || n == 4)) || (model == "rational_polynomial" && n == 8)) {
    if (!none) cam.distortion = info.d;
  } else if ((model == "equidistant" || model == "fisheye") && n == 4) {
    cam.distortion_model = Distortion::kEquidistant;
    cam.distortion = info.d;
  } else if (!(none && (model.empty() || model == "plumb_bob" || model == "none"))) {
    throw Ros2Error(
        fmt::format("{}: distortion model '{}' with {} coefficients is not supported "
                    "(plumb_bob 5, rational_polynomial 8, equidistant 4)",
                    topic, model, n));
  }
  if (!(cam.fx > 0.0 && cam.fy > 0.0 && std::isfinite(cam.cx) && std::isfinite(cam.cy))) {
    throw Ros2Error(topic + ": K holds no valid focal lengths (an uncalibrated camera?)");
  }
}

// T_c0_c1 from a stereo pair's CameraInfos: both rectified frames are parallel (R turns each raw
// frame into its rectified one) and camera 1's optical centre sits at (-Tx/fx', -Ty/fy', 0) in
// camera 0's rectified frame (CameraInfo.msg, P's fourth column).
std::optional<Eigen::Isometry3d> stereoFromProjections(const CameraInfoMessage& c0,
                                                       const CameraInfoMessage& c1) {
  if (c1.p[3] == 0.0 || c0.p[0] <= 0.0 || c1.p[0] <= 0.0 || c1.p[5] <= 0.0) return std::nullopt;
  const Eigen::Vector3d b(-c1.p[3] / c1.p[0] + c0.p[3] / c0.p[0],
                          -c1.p[7] / c1.p[5] + c0.p[7] / c0.p[5], 0.0);
  const Eigen::Matrix3d R0 = matrix3(c0.r), R1 = matrix3(c1.r);
  if (!b.allFinite() || (R0.transpose() * R0 - Eigen::Matrix3d::Identity()).norm() > 1e-6 ||
      (R1.transpose() * R1 - Eigen::Matrix3d::Identity()).norm() > 1e-6) {
    return std::nullopt;
  }
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R0.transpose() * R1;
  T.translation() = R0.transpose() * b;
  return T;
}

std::string roleTopic(const Dataset& ds, const std::string& role) {
  for (const BagTopicUse& use : ds.bag_topics) {
    if (use.role == role) return use.topic;
  }
  return {};
}

}  // namespace

namespace {

// The frame_id of a topic's first message (every type gvio reads carries a header).
std::string firstFrameId(const Ros2Bag& bag, const std::string& name) {
  const Ros2Topic* t = bag.topic(name);
  if (t == nullptr || t->messages.empty()) return {};
  if (t->type == kRos2ImuType) return decodeMessage(bag, *t, 0, decodeImu).frame_id;
  if (t->type == kRos2NavSatFixType) return decodeMessage(bag, *t, 0, decodeNavSatFix).frame_id;
  if (t->type == kRos2ImageType) return decodeMessage(bag, *t, 0, decodeImage).frame_id;
  if (t->type == kRos2CompressedImageType) {
    return decodeMessage(bag, *t, 0, decodeCompressedImage).frame_id;
  }
  return {};
}

std::string chain(const TfPath& path) {
  std::string frames;
  for (const std::string& f : path.frames) frames += (frames.empty() ? "" : " -> ") + f;
  std::string sources;
  for (const std::string& s : path.sources) sources += (sources.empty() ? "" : " + ") + s;
  return fmt::format("{}: {}", sources.empty() ? "identity" : sources, frames);
}

// Everything the bag says about the cameras, kept apart until it is known to be complete.
struct CameraCalibration {
  std::vector<CameraModel> cameras;
  std::vector<CalibrationSource> sources;
  std::string missing;  // why the cameras are not calibrated; empty when they are
};

CameraCalibration calibrateCameras(const Ros2Bag& bag, const Dataset& ds, const TfTree& tree,
                                   const std::string& imu_frame) {
  CameraCalibration out;
  out.cameras = ds.cameras;
  std::vector<CameraInfoMessage> infos;
  std::vector<std::string> frames;
  std::vector<Eigen::Isometry3d> raw_to_rect;
  for (std::size_t c = 0; c < ds.cameras.size(); ++c) {
    const std::string image_topic = roleTopic(ds, "cam" + std::to_string(c));
    const std::string info_topic = cameraInfoTopic(image_topic);
    const Ros2Topic* t = bag.topic(info_topic);
    if (t == nullptr || t->type != kRos2CameraInfoType || t->messages.empty()) {
      out.missing = fmt::format("no CameraInfo on {} beside {}", info_topic, image_topic);
      return out;
    }
    infos.push_back(decodeMessage(bag, *t, 0, decodeCameraInfo));
    const bool rectified = isRectifiedTopic(image_topic);
    CameraModel& cam = out.cameras[c];
    setIntrinsics(infos.back(), rectified, info_topic, cam);
    out.sources.push_back(
        {cam.name + " intrinsics",
         fmt::format(
             "{} ({}{})", info_topic, rectified ? "P, rectified" : infos.back().distortion_model,
             rectified                ? ""
             : cam.distortion.empty() ? ", no distortion"
                                      : fmt::format(", {} coefficients", cam.distortion.size()))});
    const std::string frame = tfFrame(infos.back().frame_id.empty() ? firstFrameId(bag, image_topic)
                                                                    : infos.back().frame_id);
    frames.push_back(frame);
    // An image_rect topic's camera frame is the rectified one: x_rect = R x_raw.
    Eigen::Isometry3d T_raw_rect = Eigen::Isometry3d::Identity();
    if (rectified) T_raw_rect.linear() = matrix3(infos.back().r).transpose();
    raw_to_rect.push_back(T_raw_rect);
    // The body frame is the IMU's; without an IMU it is the first camera's.
    const std::string body = imu_frame.empty() ? frames.front() : imu_frame;
    const auto path = frame.empty() ? std::nullopt : tree.lookup(body, frame);
    if (path) {
      cam.T_b_c = path->T_a_b * T_raw_rect;
      out.sources.push_back({"T_b_" + cam.name, chain(*path)});
    } else if (c == 0 && imu_frame.empty()) {
      cam.T_b_c = T_raw_rect;
      out.sources.push_back({"T_b_" + cam.name, "no IMU: the body frame is " + cam.name + "'s"});
    } else if (const auto T_c0_c1 =
                   c == 1 ? stereoFromProjections(infos[0], infos[1]) : std::nullopt) {
      cam.T_b_c = out.cameras[0].T_b_c * raw_to_rect[0].inverse() * *T_c0_c1 * T_raw_rect;
      out.sources.push_back(
          {"T_cam0_cam1", fmt::format("{} and {} (R, P: baseline {:.4f} m)",
                                      cameraInfoTopic(roleTopic(ds, "cam0")), info_topic,
                                      T_c0_c1->translation().norm())});
    } else {
      out.missing = fmt::format(
          "no tf path from the body frame '{}' to camera frame '{}' ({} "
          "static tf links{})",
          body, frame, tree.links().size(),
          c == 1 ? ", and no stereo baseline in the CameraInfos' P" : "");
      return out;
    }
  }
  return out;
}

}  // namespace

void applyBagCalibration(const Ros2Bag& bag, Dataset& ds) {
  const TfTree tree = staticTree(bag, ds.warnings);
  const std::string imu_topic = roleTopic(ds, "imu");
  const std::string imu_frame =
      imu_topic.empty() ? std::string() : tfFrame(firstFrameId(bag, imu_topic));
  if (!ds.cameras.empty()) {
    CameraCalibration calibration;
    try {
      calibration = calibrateCameras(bag, ds, tree, imu_frame);
    } catch (const Ros2Error& e) {
      // A CameraInfo that contradicts its images or names a model gvio cannot use leaves the
      // cameras uncalibrated, saying why: Kalibr files (--calib) can still calibrate them.
      calibration.missing = e.what();
    }
    if (!imu_topic.empty() && imu_frame.empty()) {
      // Without the IMU's frame the body frame is unknown: no camera may be placed in it.
      calibration.missing =
          "the IMU messages on " + imu_topic + " carry no frame_id to look transforms up by";
    }
    if (calibration.missing.empty()) {
      ds.cameras = std::move(calibration.cameras);
      ds.calibration_sources = std::move(calibration.sources);
    } else {
      ds.calibration_missing = calibration.missing;
    }
  }
  const std::string gnss_topic = roleTopic(ds, "gnss");
  if (gnss_topic.empty() || imu_frame.empty()) return;
  const std::string gnss_frame = tfFrame(firstFrameId(bag, gnss_topic));
  if (gnss_frame.empty()) return;
  if (const auto path = tree.lookup(imu_frame, gnss_frame)) {
    ds.gnss_lever_arm_b = path->T_a_b.translation();
    ds.calibration_sources.push_back({"GNSS lever arm", chain(*path)});
  }
}

}  // namespace gvio::io::ros2
