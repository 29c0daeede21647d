#include "mapping/loop_features.hpp"

#include <cmath>
#include <numeric>
#include <string>

#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "odometry/error.hpp"

namespace gvio::mapping {
namespace {

// ORB's descriptor patch, and the border an upright descriptor needs (the patch radius plus the
// smoothing kernel; OpenCV drops keypoints closer to the border than edgeThreshold).
constexpr int kOrbPatchPx = 31;
constexpr int kOrbBorderPx = 19;

std::vector<float> makeThumbnail(const cv::Mat& image) {
  cv::Mat small, f;
  cv::resize(image, small, cv::Size(kThumbnailWidth, kThumbnailHeight), 0, 0, cv::INTER_AREA);
  small.convertTo(f, CV_32F);
  std::vector<float> t(f.begin<float>(), f.end<float>());
  const float mean = std::accumulate(t.begin(), t.end(), 0.0F) / static_cast<float>(t.size());
  float norm = 0.0F;
  for (float& v : t) {
    v -= mean;
    norm += v * v;
  }
  norm = std::sqrt(norm);
  for (float& v : t) v = norm > 1e-3F ? v / norm : 0.0F;
  return t;
}

}  // namespace

void LoopFeatureConfig::validate() const {
  if (orb_features < 0) throw InvalidInput("config: loops.orb_features must be >= 0");
  if (orb_levels < 1 || orb_levels > 8) {
    throw InvalidInput("config: loops.orb_levels must be in 1..8");
  }
  if (orb_fast_threshold < 1 || orb_fast_threshold > 255) {
    throw InvalidInput("config: loops.orb_fast_threshold must be in 1..255");
  }
  if (!(std::isfinite(min_depth_m) && min_depth_m > 0.0)) {
    throw InvalidInput("config: loops.min_depth_m must be > 0");
  }
  if (!(std::isfinite(max_depth_m) && max_depth_m > min_depth_m)) {
    throw InvalidInput("config: loops.max_depth_m must be > loops.min_depth_m");
  }
}

std::size_t LoopKeyframe::memoryBytes() const {
  return px.capacity() * sizeof(Eigen::Vector2f) + descriptors.total() * descriptors.elemSize() +
         p_c.capacity() * sizeof(Eigen::Vector3f) + thumbnail.capacity() * sizeof(float) +
         sizeof(LoopKeyframe);
}

float thumbnailSimilarity(const LoopKeyframe& a, const LoopKeyframe& b) {
  if (a.thumbnail.size() != b.thumbnail.size() || a.thumbnail.empty()) return 0.0F;
  return std::inner_product(a.thumbnail.begin(), a.thumbnail.end(), b.thumbnail.begin(), 0.0F);
}

LoopKeyframe makeLoopKeyframe(std::int64_t t_ns, const cv::Mat& left,
                              const std::vector<LoopPointInput>& points,
                              const LoopFeatureConfig& config) {
  LoopKeyframe kf;
  kf.t_ns = t_ns;
  kf.thumbnail = makeThumbnail(left);
  const cv::Ptr<cv::ORB> orb =
      cv::ORB::create(std::max(config.orb_features, 1), 1.2F, config.orb_levels, kOrbBorderPx, 0, 2,
                      cv::ORB::HARRIS_SCORE, kOrbPatchPx, config.orb_fast_threshold);
  // The given keypoints at the finest level (class_id: their index), fresh corners after them
  // (class_id -1), all upright.
  std::vector<cv::KeyPoint> keypoints;
  if (config.orb_features > 0) orb->detect(left, keypoints);
  for (cv::KeyPoint& k : keypoints) k.class_id = -1;
  for (std::size_t i = 0; i < points.size(); ++i) {
    keypoints.emplace_back(
        cv::Point2f(static_cast<float>(points[i].px.x()), static_cast<float>(points[i].px.y())),
        static_cast<float>(kOrbPatchPx), 0.0F, 1.0F, 0, static_cast<int>(i));
  }
  for (cv::KeyPoint& k : keypoints) k.angle = 0.0F;
  cv::Mat descriptors;
  if (!keypoints.empty()) orb->compute(left, keypoints, descriptors);
  const auto has_point = [&](const cv::KeyPoint& k) {
    if (k.class_id < 0) return false;
    const LoopPointInput& p = points[static_cast<std::size_t>(k.class_id)];
    return p.has_point && p.p_c.z() >= config.min_depth_m && p.p_c.z() <= config.max_depth_m;
  };
  cv::Mat rows;
  for (int pass = 0; pass < 2; ++pass) {  // keypoints with a 3-D point first
    for (std::size_t i = 0; i < keypoints.size(); ++i) {
      const cv::KeyPoint& k = keypoints[i];
      if ((pass == 0) != has_point(k)) continue;
      if (pass == 0)
        kf.p_c.push_back(points[static_cast<std::size_t>(k.class_id)].p_c.cast<float>());
      kf.px.emplace_back(k.pt.x, k.pt.y);
      rows.push_back(descriptors.row(static_cast<int>(i)));
    }
  }
  kf.points = kf.p_c.size();
  kf.descriptors = rows;
  return kf;
}

}  // namespace gvio::mapping
