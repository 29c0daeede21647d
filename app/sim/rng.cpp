#include "sim/rng.hpp"

#include <cmath>
#include <numbers>

namespace gvio::sim {

std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ULL;
  x = (x ^ (x >> 30U)) * 0xBF58476D1CE4E5B9ULL;
  x = (x ^ (x >> 27U)) * 0x94D049BB133111EBULL;
  return x ^ (x >> 31U);
}

std::uint64_t mixSeed(std::uint64_t a, std::uint64_t b, std::uint64_t c) {
  return splitmix64(splitmix64(splitmix64(a) ^ (b + 0x632BE59BD9B4E019ULL)) ^
                    (c + 0x8CB92BA72F3D8DD7ULL));
}

Rng Rng::derive(std::uint64_t seed, std::uint64_t stream) {
  return Rng(splitmix64(splitmix64(seed) ^ splitmix64(stream + 0x5851F42D4C957F2DULL)));
}

int Rng::integer(int lo, int hi) {
  const auto span = static_cast<std::uint64_t>(hi - lo) + 1U;
  return lo + static_cast<int>(engine_() % span);  // modulo bias is irrelevant for small spans
}

double Rng::normal() {
  if (has_spare_) {
    has_spare_ = false;
    return spare_;
  }
  const double u1 = 1.0 - uniform();  // (0, 1]: the logarithm stays finite
  const double u2 = uniform();
  const double r = std::sqrt(-2.0 * std::log(u1));
  spare_ = r * std::sin(2.0 * std::numbers::pi * u2);
  has_spare_ = true;
  return r * std::cos(2.0 * std::numbers::pi * u2);
}

}  // namespace gvio::sim
