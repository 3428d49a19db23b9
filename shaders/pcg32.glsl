// engine::math::Pcg32 and make_rng (engine/math/rng.h), bit for bit, so a
// kernel draws the same random numbers as the CPU stage it replaces. Needs
// 64-bit integers (VkPhysicalDeviceFeatures::shaderInt64).
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

struct Pcg32 {
  uint64_t state;
  uint64_t inc;
};

uint pcg32_next_u32(inout Pcg32 r) {
  const uint64_t old = r.state;
  r.state = old * 6364136223846793005UL + r.inc;
  const uint xorshifted = uint(((old >> 18u) ^ old) >> 27u);
  const uint rot = uint(old >> 59u);
  return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
}

// Uniform in [0, 1): 24 random mantissa bits.
float pcg32_next_float(inout Pcg32 r) { return float(pcg32_next_u32(r) >> 8u) * (1.0 / 16777216.0); }

Pcg32 pcg32_seeded(uint64_t seed, uint64_t stream) {
  Pcg32 r;
  r.state = 0UL;
  r.inc = (stream << 1u) | 1UL;
  pcg32_next_u32(r);
  r.state += seed;
  pcg32_next_u32(r);
  return r;
}

uint64_t rng_hash_combine(uint64_t a, uint64_t b) {
  return (a ^ (b + 0x9e3779b97f4a7c15UL + (a << 6u) + (a >> 2u))) * 0x9e3779b97f4a7c15UL;
}

// make_rng(seed, item, sample) ("sample" is reserved in GLSL).
Pcg32 make_rng(uint64_t seed, uint64_t item, uint64_t sample_index) {
  return pcg32_seeded(rng_hash_combine(seed, sample_index), rng_hash_combine(item, 0x5bd1e995UL ^ seed));
}

uint64_t u64_of(uint lo, uint hi) { return uint64_t(lo) | (uint64_t(hi) << 32u); }
