#include "io/measurement_stream.hpp"

#include <limits>

namespace gvio::io {

std::int64_t stampOf(const Measurement& m) {
  return std::visit([](const auto* record) { return record->t_ns; }, m);
}

std::optional<Measurement> MeasurementStream::next() {
  constexpr auto kEnd = std::numeric_limits<std::int64_t>::max();
  const std::int64_t t_imu = imu_ < ds_.imu.size() ? ds_.imu[imu_].t_ns : kEnd;
  const std::int64_t t_frame = frame_ < ds_.frames.size() ? ds_.frames[frame_].t_ns : kEnd;
  const std::int64_t t_gnss = gnss_ < ds_.gnss.size() ? ds_.gnss[gnss_].t_ns : kEnd;
  if (t_imu == kEnd && t_frame == kEnd && t_gnss == kEnd) return std::nullopt;
  if (t_imu <= t_frame && t_imu <= t_gnss) return Measurement{&ds_.imu[imu_++]};
  if (t_frame <= t_gnss) return Measurement{&ds_.frames[frame_++]};
  return Measurement{&ds_.gnss[gnss_++]};
}

}  // namespace gvio::io
