#pragma once
// In-motion coarse alignment of the GNSS/INS filter's heading for platforms that start at rest,
// move slowly or carry their IMU turned in the vehicle (fusion/gnss_ins.hpp), where the course of
// single fixes is noise (1 m/s against metres of SPP error) and the body x axis need not point
// where the vehicle goes.
//
// The IMU is levelled at an anchor epoch from the mean specific force of the window before it
// (Groves section 5.6.2), its gyro bias taken from that window when the IMU was quiet (at rest or
// moving steadily). While it stays quiet (short means of the specific force and rate within
// quiet_acc_mps2 and quiet_gyro_std_radps of the long ones over 0.5 s), levelling and gyro bias
// are refined over the whole quiet run: a robot that waits a minute before driving off gets a
// minute's gyro bias, not a second's. From the anchor on the gyros carry the attitude R_w'_b in
// the levelled frame w', whose yaw psi in ENU is the unknown. Two things are then estimated:
// - the mount yaw m of the IMU in the vehicle, from turns: the vehicle's centripetal
//   acceleration v w is along its lateral axis, which in the body's yaw frame is Rz(-m) y; so
//   S = sum a_b w dt (a_b the gravity-free specific force in the body's yaw frame, w the levelled
//   yaw rate) points at 90 deg - m (longitudinal accelerations average out). Levelled at rest,
//   the horizontal accelerometer bias stays absorbed in the tilt as the body turns. Only chunks
//   at a steady speed (within 20 % of both neighbours', from the track) are summed: a robot
//   that speeds up while it turns would otherwise tilt S towards its forward axis (14 deg on
//   the unit test's drive).
// - the vehicle's heading offset phi = psi - m from the track: a land vehicle moves along its
//   forward axis (the non-holonomic constraint), so over a chunk of chunk_s seconds at a speed s
//   its position is p(t) = p_j + s Rz(phi) H(t), H(t) = int (cos, sin)(yaw_b) dt with yaw_b the
//   body's gyro-integrated yaw in w': linear in p_j and in c_j = s e^{i phi} (complex). Each
//   chunk's phi_j = arg c_j with its 1-sigma from the fit; the chunks are combined by weight,
//   those more than 3 sigma from the mean (reversing, a chunk with a speed change) left out.
// The heading psi = phi + m is known when both 1-sigmas, combined, are below max_heading_sigma.
// Forward driving is assumed (a vehicle that mostly reverses is aligned 180 deg off).
#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <vector>

#include "fusion/ins_error_model.hpp"
#include "odometry/measurements.hpp"

namespace gvio::fusion {

struct AlignmentConfig {
  double chunk_s = 5.0;                 // the track's chunks, each at its own constant speed
  double max_window_s = 120.0;          // beyond this without a heading, start again later
  double max_heading_sigma_deg = 5.0;   // the heading is known when its 1-sigma is below this
  double quiet_gyro_std_radps = 0.02;   // a window this still gives the gyro bias
  double quiet_gyro_mean_radps = 0.05;  // (and is not a steady turn)
  double quiet_acc_mps2 = 0.15;         // a quiet run ends at this change of the specific force
  double min_speed_mps = 0.3;           // slower chunks say nothing about the heading
  // The heading bank (fusion/ins_heading_bank.hpp), consulted while the sums above say nothing:
  // scouts over this many headings (0: none), chosen once the best leads every scout that
  // converged more than same_solution_deg away by min_nll_gap in -2 log-likelihood.
  int hypotheses = 12;
  double same_solution_deg = 15.0;
  double min_nll_gap = 30.0;
  double bank_max_heading_sigma_deg = 15.0;  // the winner's own 1-sigma (the filter refines it)
  // An attitude the IMU itself reports (sensor_msgs/Imu orientation, an AHRS) gives the heading
  // when its stated yaw 1-sigma is at most this (0: never used).
  double imu_orientation_max_sigma_deg = 10.0;
};

struct AlignmentSolution {
  ImuSample anchor;  // the IMU sample the solution's state is at
  Eigen::Matrix3d R_enu_b = Eigen::Matrix3d::Identity();  // at the anchor
  Eigen::Vector2d p_en = Eigen::Vector2d::Zero();         // body position at the anchor (E, N)
  Eigen::Vector2d v_en = Eigen::Vector2d::Zero();         // body velocity at the anchor
  Eigen::Vector3d ba_b_mps2 = Eigen::Vector3d::Zero();    // the window's vertical mismatch
  Eigen::Vector3d bg_b_radps = Eigen::Vector3d::Zero();   // from the quiet window, else 0
  double heading_sigma_rad = 0.0;
  double mount_yaw_rad = 0.0;  // m: R_v_b = Rz(m) about the vertical
  double mount_yaw_sigma_rad = 0.0;
  int fixes = 0, chunks = 0;
  bool quiet_start = false;  // the gyro bias came from a quiet anchor window
};

class TrackAlignment {
 public:
  // `window` the IMU samples before the anchor (its last one is the anchor sample); `lever_b`
  // the antenna in the body frame.
  TrackAlignment(const AlignmentConfig& config, const std::vector<ImuSample>& window,
                 const Eigen::Vector3d& lever_b);

  [[nodiscard]] std::int64_t anchorNs() const { return chunks_.front().start.t_ns; }
  [[nodiscard]] std::int64_t lastImuNs() const { return last_.t_ns; }
  // When the quiet run from the anchor ended (the anchor when it was not quiet); nullopt while
  // it lasts.
  [[nodiscard]] std::optional<std::int64_t> movingSinceNs() const { return moving_since_ns_; }
  void addImu(const ImuSample& sample);
  // A fix's antenna position (ENU, horizontal used) and horizontal 1-sigma; it is placed at the
  // last IMU sample (fixes arrive before the first IMU sample later than their stamp). The
  // antenna's track is taken for the vehicle's (a lever arm of decimetres turns with it).
  void addFix(std::int64_t t_ns, const Eigen::Vector3d& p_ant_enu, double sigma_h_m);
  // The heading solution once it is determined well enough, else nullopt.
  [[nodiscard]] std::optional<AlignmentSolution> solve() const;
  // The start state for a heading found elsewhere (fusion/ins_heading_bank.hpp): psi the yaw of
  // the levelled frame in ENU. Nullopt before the first fix.
  [[nodiscard]] std::optional<AlignmentSolution> solutionWithHeading(double psi_rad,
                                                                     double sigma_rad) const;
  [[nodiscard]] const ImuSample& anchorSample() const { return chunks_.front().start; }
  [[nodiscard]] const Eigen::Matrix3d& anchorAttitude() const { return chunks_.front().R0; }
  [[nodiscard]] const Eigen::Matrix3d& attitudeNow() const { return st_.R_enu_b; }  // R_w'_b
  [[nodiscard]] const Eigen::Vector3d& accBias() const { return st_.ba_b_mps2; }
  [[nodiscard]] const Eigen::Vector3d& gyrBias() const { return bg_; }
  [[nodiscard]] bool quietStart() const { return quiet_; }

 private:
  struct Chunk {
    Eigen::Matrix4d N = Eigen::Matrix4d::Zero();  // normal equations in [p_e p_n c_re c_im]
    Eigen::Vector4d g = Eigen::Vector4d::Zero();
    double bWb = 0.0;
    int fixes = 0;
    std::int64_t t_last_ns = 0;
    ImuSample start;                                   // the IMU sample the chunk starts at
    Eigen::Matrix3d R0 = Eigen::Matrix3d::Identity();  // R_w'_b there
    Eigen::Vector2d S = Eigen::Vector2d::Zero();       // sum a_b w dt (the mount's turn sum)
  };
  struct ChunkHeading {
    double phi = 0.0, sigma = 0.0;
    Eigen::Vector2d p = Eigen::Vector2d::Zero(), c = Eigen::Vector2d::Zero();
    int fixes = 0;
    double speed_sigma = 0.0;
  };

  void level();  // R at the anchor, ba and bg from the quiet sums
  [[nodiscard]] bool stillQuiet(const ImuSample& sample);
  void startChunk(const ImuSample& at);
  void integrate(const ImuSample& held, double dt);
  [[nodiscard]] std::optional<ChunkHeading> chunkHeading(const Chunk& chunk) const;

  AlignmentConfig config_;
  Eigen::Vector3d lever_b_;
  Eigen::Vector3d bg_ = Eigen::Vector3d::Zero();
  bool quiet_ = false;
  // Sums over the anchor window and the quiet run after it; the short window's last samples.
  Eigen::Vector3d f_sum_ = Eigen::Vector3d::Zero(), w_sum_ = Eigen::Vector3d::Zero();
  double n_sum_ = 0.0;
  std::vector<ImuSample> recent_;
  std::optional<std::int64_t> moving_since_ns_;
  ImuSample last_;
  // R_enu_b is R_w'_b (ins_error_model.hpp's mechanisation); ba holds the window's gravity
  // mismatch so that a quiet IMU integrates to no acceleration.
  InsState st_;
  Eigen::Vector2d H_ = Eigen::Vector2d::Zero();  // int (cos, sin)(yaw_b) dt in the chunk
  std::vector<Chunk> chunks_;
};

}  // namespace gvio::fusion
