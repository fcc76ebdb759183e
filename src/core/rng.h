#pragma once
/// @file core/rng.h
/// @brief Counter-based random numbers for deterministic parallel code.
///
/// Every parallel element (an emitted photon, a voxel) seeds its own generator
/// from (global seed, element index), so results do not depend on which thread
/// ran the element or in what order.

#include <cstdint>

namespace lo {

/// SplitMix64 finaliser: a bijective 64-bit mix.
constexpr uint64_t mix64(uint64_t z) {
  z += 0x9e3779b97f4a7c15ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

/// PCG32 (O'Neill 2014): small state, good statistics, cheap to seed.
class Rng {
 public:
  /// Generator for element `index` of a computation seeded with `seed`.
  Rng(uint64_t seed, uint64_t index) {
    state_ = 0;
    inc_ = (mix64(index ^ 0x2545f4914f6cdd1dull) << 1u) | 1u;
    next();
    state_ += mix64(seed + 0x632be59bd9b4e019ull * (index + 1));
    next();
  }

  uint32_t next() {
    uint64_t old = state_;
    state_ = old * 6364136223846793005ull + inc_;
    uint32_t xorshifted = uint32_t(((old >> 18u) ^ old) >> 27u);
    uint32_t rot = uint32_t(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
  }

  /// Uniform float in [0, 1).
  float uniform() { return float(next() >> 8) * (1.0f / 16777216.0f); }

  /// Uniform integer in [0, n).
  uint32_t uniformInt(uint32_t n) { return uint32_t((uint64_t(next()) * n) >> 32); }

 private:
  uint64_t state_ = 0;
  uint64_t inc_ = 1;
};

/// 53 random bits as a double in [0, 1) (two draws): for picking from tables
/// whose entries' shares can be below a float's 2^-24 (millions of emissive
/// triangles, a sky image's texels).
inline double uniform53(Rng& rng) {
  const uint64_t bits = (uint64_t(rng.next()) << 21) ^ uint64_t(rng.next());
  return double(bits & ((uint64_t(1) << 53) - 1)) * 0x1p-53;
}

}  // namespace lo
