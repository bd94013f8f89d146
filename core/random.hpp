// Counter-based random numbers: every value is a pure function of (seed, stream, index), so results do
// not depend on thread count or on the order in which work is scheduled. There is no shared generator.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>

#include <glm/glm.hpp>

namespace growbench {

// SplitMix64 finaliser (Steele, Lea, Flood 2014): a bijective 64-bit mixer.
constexpr std::uint64_t mix64(std::uint64_t z) {
  z += 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

constexpr std::uint64_t random_bits(std::uint64_t seed, std::uint64_t stream, std::uint64_t index) {
  return mix64(mix64(mix64(seed) ^ stream) ^ index);
}

// A cheap handle that hands out successive values of one (seed, stream) sequence. Copying it copies
// the position; give each thread or each entity its own stream.
class Rng {
 public:
  constexpr Rng(std::uint64_t seed, std::uint64_t stream, std::uint64_t start = 0)
      : key_(mix64(mix64(seed) ^ stream)), index_(start) {}
  constexpr std::uint64_t next_u64() { return mix64(key_ ^ index_++); }
  // Uniform in [0, 1), 53 bits.
  double uniform() { return static_cast<double>(next_u64() >> 11) * 0x1.0p-53; }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  // Uniform on the unit sphere.
  glm::vec3 unit_vector() {
    const double z = uniform(-1.0, 1.0);
    const double phi = uniform(0.0, 2.0 * std::numbers::pi);
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    return {static_cast<float>(r * std::cos(phi)), static_cast<float>(r * std::sin(phi)), static_cast<float>(z)};
  }
  // Uniform in the unit ball.
  glm::vec3 in_unit_ball() {
    const glm::vec3 d = unit_vector();
    return d * static_cast<float>(std::cbrt(uniform()));
  }

 private:
  std::uint64_t key_;
  std::uint64_t index_;
};

}  // namespace growbench
