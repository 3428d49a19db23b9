#pragma once
// Counter-based randomness: a sample's random numbers depend only on
// (seed, pixel or item index, sample index, dimension), never on which
// thread computed it or in what order, so renders are identical for any
// thread count.
#include <cstdint>

namespace engine::math {

// PCG-style 64 -> 32 bit hash (Jarzynski & Olano 2020, "pcg3d"-like mixing).
constexpr std::uint32_t hash32(std::uint64_t x) {
  x ^= x >> 33;
  x *= 0xff51afd7ed558ccdULL;
  x ^= x >> 33;
  x *= 0xc4ceb9fe1a85ec53ULL;
  x ^= x >> 33;
  return static_cast<std::uint32_t>(x);
}

constexpr std::uint64_t hash_combine(std::uint64_t a, std::uint64_t b) {
  return (a ^ (b + 0x9e3779b97f4a7c15ULL + (a << 6) + (a >> 2))) * 0x9e3779b97f4a7c15ULL;
}

// PCG32 (O'Neill 2014): small state, good statistics, reproducible streams.
class Pcg32 {
 public:
  constexpr Pcg32() = default;
  constexpr Pcg32(std::uint64_t seed, std::uint64_t stream) { reseed(seed, stream); }

  constexpr void reseed(std::uint64_t seed, std::uint64_t stream) {
    state_ = 0;
    inc_ = (stream << 1u) | 1u;
    next_u32();
    state_ += seed;
    next_u32();
  }

  constexpr std::uint32_t next_u32() {
    const std::uint64_t old = state_;
    state_ = old * 6364136223846793005ULL + inc_;
    const auto xorshifted = static_cast<std::uint32_t>(((old >> 18u) ^ old) >> 27u);
    const auto rot = static_cast<std::uint32_t>(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
  }

  // Uniform in [0, 1): 24 random mantissa bits, never returns 1.
  constexpr float next_float() { return static_cast<float>(next_u32() >> 8) * 0x1p-24f; }
  constexpr double next_double() {
    const std::uint64_t hi = next_u32(), lo = next_u32();
    return static_cast<double>(((hi << 32) | lo) >> 11) * 0x1p-53;
  }

 private:
  std::uint64_t state_ = 0x853c49e6748fea9bULL;
  std::uint64_t inc_ = 0xda3e39cb94b95bdbULL;
};

// The stream for one (item, sample) pair under a seed.
constexpr Pcg32 make_rng(std::uint64_t seed, std::uint64_t item, std::uint64_t sample) {
  return Pcg32(hash_combine(seed, sample), hash_combine(item, 0x5bd1e995ULL ^ seed));
}

}  // namespace engine::math
