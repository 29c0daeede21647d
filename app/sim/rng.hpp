#pragma once
// The simulator's one random source. std::mt19937_64's output is fixed by the C++ standard, but
// the <random> distributions are not, so uniform and normal deviates are derived here (normals by
// the Box-Muller transform, Box & Muller 1958): a seed gives byte-identical datasets everywhere.
#include <Eigen/Core>
#include <cstdint>
#include <random>

namespace gvio::sim {

class Rng {
 public:
  explicit Rng(std::uint64_t seed) : engine_(seed) {}

  // An independent stream for a sub-task, so adding draws in one place does not shift another.
  [[nodiscard]] static Rng derive(std::uint64_t seed, std::uint64_t stream);

  double uniform() { return static_cast<double>(engine_() >> 11U) * 0x1.0p-53; }  // [0, 1)
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  int integer(int lo, int hi);  // [lo, hi]
  bool chance(double p) { return uniform() < p; }
  double normal();  // N(0, 1); the second variate of each pair serves the next call
  Eigen::Vector3d normal3() {
    const double x = normal(), y = normal(), z = normal();
    return {x, y, z};
  }

 private:
  std::mt19937_64 engine_;
  bool has_spare_ = false;
  double spare_ = 0.0;
};

// SplitMix64 finaliser (Steele, Lea & Flood 2014): spreads seeds that differ in few bits.
std::uint64_t splitmix64(std::uint64_t x);
// One seed from several (per stage, frame and camera streams).
std::uint64_t mixSeed(std::uint64_t a, std::uint64_t b, std::uint64_t c = 0);

}  // namespace gvio::sim
