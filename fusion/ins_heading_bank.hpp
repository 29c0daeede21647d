#pragma once
// A bank of GNSS/INS filters over heading hypotheses (a Gaussian-sum start; Groves section 14.4.1
// "in-motion alignment" with multiple hypotheses), for when the track alignment's levelled-frame
// sums cannot separate heading from a consumer gyro's drift (fusion/ins_alignment.hpp). Each scout
// is a full GnssIns started at the alignment's anchor with the levelled attitude turned to one of
// n evenly spaced headings (1-sigma half the spacing), the constraint off (the mount is unknown);
// all see the same IMU samples and fixes. The filters estimate tilt and gyro bias with the fixes,
// and a wrong heading shows as position innovations that grow with every acceleration and turn:
// the scouts' -2 log-likelihoods (fusion/gnss_ins.hpp InsStats::position_nll) rank them. A heading
// is chosen once the best scout leads every scout that converged elsewhere (more than
// same_solution_deg away now) by min_nll_gap, and its own 1-sigma is small enough.
#include <Eigen/Core>
#include <optional>
#include <vector>

#include "fusion/gnss_ins.hpp"

namespace gvio::fusion {

struct HeadingChoice {
  Eigen::Matrix3d R_enu_b = Eigen::Matrix3d::Identity();  // the winner's attitude now
  double sigma_rad = 0.0;                                 // its heading 1-sigma now
  double nll_gap = 0.0;  // -2 log-likelihood lead over the best scout elsewhere
  int hypothesis = 0;
};

class HeadingBank {
 public:
  // `config` the main filter's (the scouts run without the constraint and without alignment);
  // `start` the state at `anchor` with the levelled attitude (its heading is replaced), `P` its
  // covariance (the heading's is replaced).
  HeadingBank(const InsConfig& config, const EnuFrame& enu, const ImuSample& anchor,
              const InsState& start, const InsMatrix& P);

  void addImu(const ImuSample& sample);
  void addFix(const GnssFix& fix);
  [[nodiscard]] std::optional<HeadingChoice> choose(double max_sigma_rad) const;
  [[nodiscard]] std::size_t size() const { return scouts_.size(); }

 private:
  InsConfig config_;
  std::vector<GnssIns> scouts_;
};

}  // namespace gvio::fusion
