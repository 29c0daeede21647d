#pragma once
// Visual front end (VINS-Fusion / OpenVINS style): Shi-Tomasi corners on the left image, tracked
// frame to frame with pyramidal KLT, cleaned by a forward-backward check and a fundamental-matrix
// RANSAC, topped up over a grid, and matched into the right image of a rectified stereo pair.
// Pure image processing: no camera model, no file I/O, no state beyond the previous frame.
#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

#include <cstdint>
#include <vector>

namespace gvio::odometry {

struct TrackerConfig {
  int max_features = 200;       // per left image
  double quality_level = 0.01;  // Shi-Tomasi: corners weaker than this x the strongest are dropped
  int min_distance_px = 20;     // minimum distance between features (old and new)
  // New detections are spread over a grid, at most ceil(max_features / cells) per cell, so that
  // one highly textured facade does not take every feature (poorly conditioned geometry).
  int grid_cols = 8, grid_rows = 4;
  // Pyramid level the Shi-Tomasi response is computed on (0: full resolution; L: 1/2^L of it),
  // each corner then moved to the strongest full-resolution response within 2^L px. The response
  // over the whole image is the front end's largest single cost (5.6 of 16.3 ms per KITTI frame
  // on one core); level 1 takes a quarter of it. Not the default: stereo+IMU gained (style matrix
  // geometric mean 0.0403 -> 0.0335 %, KITTI-00 1.105 -> 0.921 m) and mono+IMU a little, stereo
  // alone lost, and on the slanted-plane test one of its corners gets a stereo match 8 px off
  // that the checks pass (docs/benchmarks/vio-matrix.md, "Corners from the half-resolution level").
  int detect_level = 0;
  // A new corner is dropped when the smaller eigenvalue of its gradient covariance over a 7 x 7
  // window (the full-resolution KLT pass's) is below this fraction of the larger one (0: no
  // check). Shi-Tomasi asks only for a large smaller eigenvalue, relative to the frame's best
  // corner; where the frame has few corners (sparse texture: lane markings and wall edges) a
  // point on a strong edge passes on its noise, and KLT slides along the edge (the aperture
  // problem). Under forward motion a lane marking points at the focus of expansion, along the
  // epipolar lines, so the fundamental-matrix RANSAC cannot catch the slide either. 0.1 took
  // stereo+IMU from 27 to 29 of the style matrix's 30 cells within 0.10 % (six seeds), but the
  // whole KITTI-00 drive over four simulations from 0.904 to 1.161 m (geometric mean): off by
  // default (docs/benchmarks/vio-matrix.md, "Held-out seeds" and "Four simulations of KITTI-00").
  double min_eigen_ratio = 0.0;
  int klt_window_px = 21;  // odd side of the KLT window
  int klt_levels = 3;      // pyramid levels above the full-resolution image
  int klt_iterations = 30;
  // Odd side of a second KLT pass at full resolution, started where the pyramidal pass ended; 0
  // skips it. KLT fits one translation to the whole window (Lucas and Kanade 1981), so where the
  // image deforms across the window (the road at grazing angles: disparity changes by b/h = 0.33 px
  // per row on KITTI; its texture expands under forward motion) the fit is the gradient-weighted
  // mean of the displacements over the window, and any uneven spread of gradient energy biases
  // it. Near ground points came out 0.1 px too wide in disparity and 2 % short in flow over a 21 px
  // window, which made the VIO's trajectories 0.04-0.8 % short; the small window reduces the
  // deformation it averages over, while the pyramid (large window) still finds large motions.
  int klt_refine_window_px = 7;
  // KLT starts every track shifted by the frame's common image motion (the tracks' median image
  // velocity times the interval) when that shift is at least this (px), else at its old position;
  // 0 always shifts, a huge value never (FeatureTracker::predictedPositions).
  double klt_predict_min_px = 10.0;
  double fb_threshold_px = 1.0;      // forward-backward check: max round-trip miss
  double ransac_threshold_px = 1.0;  // fundamental-matrix RANSAC between consecutive left frames
  // Rectified stereo: a match further than this from the frame's median row offset (right y -
  // left y over its candidate matches) is rejected. KLT on an oblique edge (a lane marking, a
  // wall's edge) slides along it, off the row and to a wrong disparity; the median is the offset
  // a rig's rectification error gives every match alike (docs/benchmarks/vio-matrix.md, "The stereo
  // row check").
  double stereo_max_vertical_px = 0.5;
  // A stereo match is dropped when the zero-mean normalised cross-correlation of the 11 x 11
  // patches around the left pixel and its match is below this (-1: no check). KLT can stop in a
  // wrong minimum along the row whose patch resembles the left one well enough that the
  // forward-backward check (its reverse pass starts at the left pixel itself) and the row check
  // pass it: 8 px and 67 px wrong matches on the slanted-plane test scored 0.66 and 0.61, every
  // correct match there 0.77 or more, and 99.8 % of KITTI-00's matches 0.7 or more
  // (docs/benchmarks/vio-matrix.md, "Corners from the half-resolution level").
  double stereo_min_zncc = -1.0;
  // Exposure changes (odometry/photometric_gain.hpp): when the median brightness ratio of the
  // matched patches between the previous and this left image (or between the left and the right
  // image) is further from 1 than this, the image is divided by it and the points are tracked
  // (matched) again; 0: never. Below it the images are used as they are, so a drive without
  // exposure changes gives the same tracks as with none.
  double gain_threshold = 0.02;
  bool stereo = true;

  void validate() const;  // throws InvalidInput naming the field
};

struct Feature {
  std::uint64_t id = 0;  // unique over the tracker's life, kept while the feature is tracked
  Eigen::Vector2d px_left = Eigen::Vector2d::Zero();
  bool has_right = false;
  Eigen::Vector2d px_right = Eigen::Vector2d::Zero();  // valid when has_right
  int track_length = 1;  // frames this id has been seen in, this one included
  // Image-plane velocity of the left pixel at this frame (px/s; zero for a new feature): the
  // backward difference since the previous frame, carried to this frame to second order with the
  // one before it (a backward difference is the velocity half an interval earlier: at 10 Hz in a
  // turn that lag put the time-offset correction pixels off). The time-offset factors shift
  // observations along it.
  Eigen::Vector2d velocity_pxps = Eigen::Vector2d::Zero();
  // The right pixel's: the left one's less the rate of change of disparity (rectified rows, the
  // same second-order estimate), when the feature had a stereo match in the previous frame too;
  // else the left one's.
  Eigen::Vector2d velocity_right_pxps = Eigen::Vector2d::Zero();
};

struct TrackerStats {
  // Features carried over from the previous frame (after dropping those that drifted next to a
  // longer-lived feature).
  int tracked = 0;
  int new_features = 0;  // fresh detections in this frame
  int rejected_fb = 0;   // lost by KLT, the border or the forward-backward check
  int rejected_ransac = 0;
  int stereo_matches = 0;
  int rejected_stereo = 0;  // stereo KLT failures, forward-backward, epipolar or disparity sign
  double stereo_row_offset_px = 0.0;  // the frame's median right y - left y (0: no candidates)
  // Gains removed (TrackerConfig::gain_threshold): this left image against the previous one, the
  // right image against the left one; 1 where none was.
  double exposure_gain = 1.0, stereo_gain = 1.0;
  // Informational wall-clock timings of the three stages (not asserted anywhere).
  double ms_detect = 0, ms_track = 0, ms_stereo = 0;
};

struct TrackedFrame {
  std::int64_t t_ns = 0;
  std::vector<Feature> features;
  TrackerStats stats;
};

class FeatureTracker {
 public:
  explicit FeatureTracker(const TrackerConfig& config);
  // Not copyable: the image buffers below would be shared between the copies.
  FeatureTracker(const FeatureTracker&) = delete;
  FeatureTracker& operator=(const FeatureTracker&) = delete;
  FeatureTracker(FeatureTracker&&) = default;
  FeatureTracker& operator=(FeatureTracker&&) = default;

  // `left` (and `right` when config.stereo) are 8-bit grey images of equal size, the same size
  // on every call until reset(); throws InvalidInput otherwise. Black or textureless images give
  // zero features.
  TrackedFrame track(std::int64_t t_ns, const cv::Mat& left, const cv::Mat& right = cv::Mat());

  // Forgets every track (e.g. after a black frame or a camera dropout); ids keep increasing so
  // that a consumer never confuses a new feature with an old one.
  void reset();
  // reset(), and the next new feature gets id `next_id`: undoes a frame tracked ahead and then
  // abandoned (VioEstimator::takeAhead), so the ids are those of a run that never tracked it.
  void rewind(std::uint64_t next_id);
  [[nodiscard]] std::uint64_t nextId() const { return next_id_; }

 private:
  // Per-feature state carried from one frame to the next (parallel to the output features).
  struct Track {
    std::uint64_t id = 0;
    cv::Point2f px;
    cv::Point2f velocity_pxps{0.0F, 0.0F};  // at this frame's stamp (see Feature)
    int length = 1;
    bool has_disparity = false;
    float disparity = 0.0F;  // left x - right x in the frame it was measured, a stereo KLT guess
    // The last backward differences and their intervals (0: none), for the second-order
    // estimate at the stamp.
    cv::Point2f step_velocity_pxps{0.0F, 0.0F};
    double step_dt_s = 0.0;
    double disparity_rate_pxps = 0.0;
    double disparity_rate_dt_s = 0.0;
  };

  void checkImages(const cv::Mat& left, const cv::Mat& right) const;
  void buildPyramid(const cv::Mat& image, std::vector<cv::Mat>& pyr) const;
  void trackPrevious(double dt_s, TrackerStats& stats);
  [[nodiscard]] std::vector<cv::Point2f> predictedPositions(double dt_s) const;
  void rejectOutliersRansac(const std::vector<cv::Point2f>& prev_px, TrackerStats& stats);
  void thinOutAndMask(const cv::Size& size);
  // The detection image: the left image at config_.detect_level (the KLT pyramid's level where
  // it has one, else halved here).
  [[nodiscard]] const cv::Mat& detectionImage(const cv::Mat& left);
  std::vector<cv::Point2f> shiTomasiCorners(const cv::Mat& image);
  cv::Point2f refinedCorner(const cv::Mat& left, const cv::Point& pixel);
  // The min_eigen_ratio check of a new corner.
  bool notOnAnEdge(const cv::Mat& left, const cv::Point2f& corner);
  void detectNew(const cv::Mat& left, TrackerStats& stats);
  std::vector<Feature> matchStereo(TrackerStats& stats);
  // With the points tracked from `from` into `to` (`to_px`, `ok`, started at `start_px`): when
  // their patches say `to` is brighter or darker by more than config_.gain_threshold, tracks them
  // again into `to` with that gain removed and returns it; else 1 (nothing changed).
  double removeExposureGain(const std::vector<cv::Mat>& from, const std::vector<cv::Mat>& to,
                            const std::vector<cv::Point2f>& from_px,
                            const std::vector<cv::Point2f>& start_px,
                            std::vector<cv::Point2f>& to_px, std::vector<bool>& ok);
  // The ZNCC check of a stereo match (config_.stereo_min_zncc).
  bool similarPatches(const cv::Point2f& left_px, const cv::Point2f& right_px);

  TrackerConfig config_;
  std::uint64_t next_id_ = 0;
  std::vector<Track> tracks_;   // features of the previous (then current) left image
  bool has_prev_ = false;       // prev_pyr_ holds the previous left image (false after reset())
  std::int64_t prev_t_ns_ = 0;  // its stamp
  double dt_s_ = 0.0;           // this frame's stamp minus the previous one's (0: none)
  cv::Size image_size_;
  // Image buffers kept from frame to frame only so that OpenCV reuses their memory: fresh
  // megabyte-sized allocations each frame cost more in page faults than the arithmetic on them.
  std::vector<cv::Mat> prev_pyr_, left_pyr_, right_pyr_;  // KLT pyramids with derivatives
  cv::Mat gain_image_;                                    // an image with its exposure gain removed
  std::vector<cv::Mat> gain_pyr_;                         // and its pyramid
  cv::Mat mask_;                                          // where new corners may go
  cv::Mat response_;                                      // Shi-Tomasi response
  cv::Mat detect_image_, detect_mask_;                    // left image and mask_ at detect_level
  cv::Mat refine_response_;                               // full-resolution response near a corner
  cv::Mat zncc_left_, zncc_right_;                        // patches of the stereo ZNCC check
  cv::Mat edge_gx_, edge_gy_;                             // gradients of the edge check
};

}  // namespace gvio::odometry
