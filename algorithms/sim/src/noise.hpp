#pragma once
// Deterministic randomness for the simulator. Nothing here uses <random> distributions, whose
// outputs differ between standard libraries: the same seed must give the same bytes everywhere.
#include <cmath>
#include <cstdint>
#include <numbers>

namespace delineo::sim::detail {

inline std::uint64_t mix64(std::uint64_t z) {
  // splitmix64 finaliser: a bijective avalanche of the 64 bits.
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

inline std::uint64_t hash3(std::uint64_t seed, std::int64_t a, std::int64_t b, std::int64_t c = 0) {
  std::uint64_t h = mix64(seed);
  h = mix64(h ^ static_cast<std::uint64_t>(a));
  h = mix64(h ^ static_cast<std::uint64_t>(b));
  return mix64(h ^ static_cast<std::uint64_t>(c));
}

// Uniform in [0, 1) from the top 53 bits.
inline double toUnit(std::uint64_t h) { return static_cast<double>(h >> 11) * 0x1.0p-53; }

// Sequential generator for the scene layout (splitmix64 stream).
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : state_(mix64(seed ^ 0x5ce7e5eedULL)) {}
  std::uint64_t next() {
    state_ += 0x9e3779b97f4a7c15ULL;
    return mix64(state_);
  }
  double uniform() { return toUnit(next()); }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  // Integer in [lo, hi] inclusive.
  int uniformInt(int lo, int hi) {
    return lo + static_cast<int>(uniform() * static_cast<double>(hi - lo + 1));
  }
  bool chance(double p) { return uniform() < p; }

 private:
  std::uint64_t state_;
};

// Standard normal from two hashed uniforms (Box-Muller), for per-pixel noise.
inline double hashedNormal(std::uint64_t seed, std::int64_t a, std::int64_t b, std::int64_t c) {
  const std::uint64_t h = hash3(seed, a, b, c);
  const double u1 = (static_cast<double>(h >> 40) + 0.5) * 0x1.0p-24;  // (0, 1)
  const double u2 = static_cast<double>(h & 0xffffffULL) * 0x1.0p-24;
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

// Lattice value in [0, 1): one avalanche per lattice point keeps texturing cheap.
inline double latticeValue(std::uint64_t seed, std::int64_t ix, std::int64_t iy) {
  return toUnit(mix64(seed ^ (static_cast<std::uint64_t>(ix) * 0x9e3779b97f4a7c15ULL) ^
                      (static_cast<std::uint64_t>(iy) * 0xc2b2ae3d27d4eb4fULL)));
}

// Smooth value noise in [0, 1] on a unit lattice.
inline double valueNoise(std::uint64_t seed, double x, double y) {
  const double fx = std::floor(x), fy = std::floor(y);
  const auto ix = static_cast<std::int64_t>(fx), iy = static_cast<std::int64_t>(fy);
  const double tx = x - fx, ty = y - fy;
  const double sx = tx * tx * tx * (tx * (tx * 6 - 15) + 10);  // quintic fade: C2 smooth
  const double sy = ty * ty * ty * (ty * (ty * 6 - 15) + 10);
  const double v00 = latticeValue(seed, ix, iy);
  const double v10 = latticeValue(seed, ix + 1, iy);
  const double v01 = latticeValue(seed, ix, iy + 1);
  const double v11 = latticeValue(seed, ix + 1, iy + 1);
  const double a = v00 + (v10 - v00) * sx;
  const double b = v01 + (v11 - v01) * sx;
  return a + (b - a) * sy;
}

// Fractal sum of `octaves` value-noise layers, normalised to [0, 1]; `scale` is the period of
// the coarsest layer in the caller's units.
inline double fbm(std::uint64_t seed, double x, double y, double scale, int octaves) {
  // Each octave is rotated by about 31 degrees against the previous one so that the lattice
  // axes do not show as horizontal/vertical streaks.
  constexpr double kCos = 0.8571673007021123, kSin = 0.5150380749100542;
  double sum = 0.0, amp = 1.0, norm = 0.0, f = 1.0 / scale;
  for (int o = 0; o < octaves; ++o) {
    sum += amp * valueNoise(seed + static_cast<std::uint64_t>(o) * 0x632be5abULL, x * f, y * f);
    const double rx = kCos * x - kSin * y;
    y = kSin * x + kCos * y;
    x = rx;
    norm += amp;
    amp *= 0.5;
    f *= 2.0;
  }
  return sum / norm;
}

}  // namespace delineo::sim::detail
