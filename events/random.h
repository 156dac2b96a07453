// Seeded random draws for the simulator and the scene synthesizer.
//
// The standard library's distributions (std::normal_distribution, ...) are implementation
// defined, so the same seed gives other numbers under libstdc++ and libc++. Benchmarks depend on
// simulated data being the same everywhere, so the draws here are built from std::mt19937_64,
// whose output sequence the standard fixes exactly.
#ifndef EVFS_EVENTS_RANDOM_H_
#define EVFS_EVENTS_RANDOM_H_

#include <cmath>
#include <cstdint>
#include <random>

namespace evfs {

/// A platform-independent random source: same seed, same numbers, on every compiler.
class Random {
 public:
  explicit Random(uint64_t seed) : engine_(seed) {}

  /// Uniform in [0, 1), 53 random bits.
  double Uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }

  /// Uniform in [low, high).
  double Uniform(double low, double high) { return low + (high - low) * Uniform(); }

  /// Uniform integer in [0, n); n > 0. The modulo bias is below 2^-40 for any n < 2^24.
  uint64_t UniformIndex(uint64_t n) { return engine_() % n; }

  /// +1 or -1 with equal probability.
  int8_t Sign() { return (engine_() >> 63) != 0 ? int8_t{1} : int8_t{-1}; }

  /// Normal with the given mean and standard deviation (Box–Muller, one value per call).
  double Normal(double mean, double stddev) {
    const double u1 = 1.0 - Uniform();  // in (0, 1], so the log is finite
    const double u2 = Uniform();
    constexpr double kTwoPi = 6.283185307179586476925;
    return mean + stddev * std::sqrt(-2.0 * std::log(u1)) * std::cos(kTwoPi * u2);
  }

  /// Exponential with the given rate (> 0): the gap between events of a Poisson process.
  double Exponential(double rate) { return -std::log(1.0 - Uniform()) / rate; }

 private:
  std::mt19937_64 engine_;
};

}  // namespace evfs

#endif  // EVFS_EVENTS_RANDOM_H_
