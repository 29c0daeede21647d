#include "odometry/corner_candidates.hpp"

#include <opencv2/core/hal/intrin.hpp>

#include <algorithm>
#include <cstdint>

namespace gvio::odometry {
namespace {

bool isLocalMaximum(const float* above, const float* r, const float* below, int x) {
  const float v = r[x];
  return !(v < r[x - 1] || v < r[x + 1] || v < above[x - 1] || v < above[x] || v < above[x + 1] ||
           v < below[x - 1] || v < below[x] || v < below[x + 1]);
}

}  // namespace

// Max is exact whatever the order, so 4 running maxima give the single one's result. The
// compiler does not vectorise the plain loop itself (std::max's NaN and signed-zero semantics).
float maskedMaximum(const cv::Mat& response, const cv::Mat& mask) {
  CV_Assert(response.type() == CV_32FC1 && mask.type() == CV_8UC1 &&
            response.size() == mask.size());
  float best = 0.0F;
  for (int y = 0; y < response.rows; ++y) {
    const auto* r = response.ptr<float>(y);
    const auto* m = mask.ptr<std::uint8_t>(y);
    int x = 0;
#if CV_SIMD128
    const cv::v_float32x4 zero = cv::v_setzero_f32();
    const cv::v_uint32x4 zero_u = cv::v_setzero_u32();
    cv::v_float32x4 best4 = zero;
    // 16 mask bytes by one unaligned load, widened to 4 x 4 lanes (cv::v_load_expand_q would read
    // 4 bytes as one int: a misaligned load where the row or x is not a multiple of 4, undefined
    // behaviour that UBSan stops at).
    for (; x + 16 <= response.cols; x += 16) {
      cv::v_uint16x8 m_lo, m_hi;
      cv::v_expand(cv::v_load(m + x), m_lo, m_hi);
      cv::v_uint32x4 m4[4];
      cv::v_expand(m_lo, m4[0], m4[1]);
      cv::v_expand(m_hi, m4[2], m4[3]);
      for (int k = 0; k < 4; ++k) {
        const cv::v_float32x4 inside = cv::v_reinterpret_as_f32(m4[k] != zero_u);
        best4 = cv::v_max(best4, cv::v_select(inside, cv::v_load(r + x + 4 * k), zero));
      }
    }
    best = std::max(best, cv::v_reduce_max(best4));
#endif
    for (; x < response.cols; ++x) best = std::max(best, m[x] != 0 ? r[x] : 0.0F);
  }
  return best;
}

std::vector<std::pair<float, int>> localMaximumCandidates(const cv::Mat& response,
                                                          const cv::Mat& mask, float threshold) {
  CV_Assert(response.type() == CV_32FC1 && mask.type() == CV_8UC1 &&
            response.size() == mask.size());
  std::vector<std::pair<float, int>> candidates;
  const int cols = response.cols;
  const auto test = [&](const float* above, const float* r, const float* below,
                        const std::uint8_t* allowed, int y, int x) {
    if (r[x] < threshold || allowed[x] == 0) return;
    if (isLocalMaximum(above, r, below, x)) candidates.emplace_back(r[x], y * cols + x);
  };
  for (int y = 1; y + 1 < response.rows; ++y) {
    const auto* above = response.ptr<float>(y - 1);
    const auto* r = response.ptr<float>(y);
    const auto* below = response.ptr<float>(y + 1);
    const auto* allowed = mask.ptr<std::uint8_t>(y);
    int x = 1;
#if CV_SIMD128
    // Most responses are below the threshold: skip 4 at a time where all of them are ("not
    // below" rather than "at least", so that the 4-wide test passes what the per-pixel one does).
    const cv::v_float32x4 threshold4 = cv::v_setall_f32(threshold);
    for (; x + 4 <= cols - 1; x += 4) {
      if (!cv::v_check_any(~(cv::v_load(r + x) < threshold4))) continue;
      for (int k = x; k < x + 4; ++k) test(above, r, below, allowed, y, k);
    }
#endif
    for (; x + 1 < cols; ++x) test(above, r, below, allowed, y, x);
  }
  std::sort(candidates.begin(), candidates.end(), [](const auto& a, const auto& b) {
    return a.first != b.first ? a.first > b.first : a.second < b.second;
  });
  return candidates;
}

}  // namespace gvio::odometry
