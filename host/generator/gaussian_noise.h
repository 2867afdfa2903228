// GaussianNoise: a seeded, platform-independent stream of standard normal numbers.
// std::normal_distribution is implementation-defined (its output differs between standard
// libraries), so the generator's "same seed, same bytes" promise needs its own transform:
// Box-Muller on 53-bit uniforms from std::mt19937_64, whose output the standard fixes.
#pragma once

#include <cmath>
#include <cstdint>
#include <random>

namespace sigmafem {

class GaussianNoise {
 public:
  explicit GaussianNoise(std::uint64_t seed) : engine_(seed) {}

  double next() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    // u1 in (0, 1]: log(u1) is finite.
    const double u1 = (static_cast<double>(engine_() >> 11) + 1.0) * 0x1.0p-53;
    const double u2 = static_cast<double>(engine_() >> 11) * 0x1.0p-53;
    const double radius = std::sqrt(-2.0 * std::log(u1));
    const double angle = 2.0 * 3.14159265358979323846 * u2;
    spare_ = radius * std::sin(angle);
    has_spare_ = true;
    return radius * std::cos(angle);
  }

 private:
  std::mt19937_64 engine_;
  double spare_ = 0.0;
  bool has_spare_ = false;
};

}  // namespace sigmafem
