#pragma once
// Merges a dataset's IMU, camera and GNSS records into one time-ordered stream. At equal stamps
// IMU comes first, so a frame at t always has every IMU sample up to t before it.
#include <cstddef>
#include <optional>
#include <variant>

#include "io/dataset.hpp"

namespace gvio::io {

using Measurement = std::variant<const ImuSample*, const FrameRecord*, const GnssFix*>;

std::int64_t stampOf(const Measurement& m);

class MeasurementStream {
 public:
  explicit MeasurementStream(const Dataset& dataset) : ds_(dataset) {}

  // The next record in time order, nullopt at the end. The pointers stay valid while the
  // dataset lives.
  std::optional<Measurement> next();
  [[nodiscard]] std::size_t total() const {
    return ds_.imu.size() + ds_.frames.size() + ds_.gnss.size();
  }

 private:
  const Dataset& ds_;
  std::size_t imu_ = 0, frame_ = 0, gnss_ = 0;
};

}  // namespace gvio::io
