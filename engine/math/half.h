#pragma once
// IEEE 754 binary16 ("half") conversions for compact storage (probe maps,
// images). Bit manipulation after Fabian Giesen's public-domain
// float_to_half_fast3_rtne and half_to_float: round to nearest even, NaN stays
// NaN, values past the half range become infinity (callers that must stay
// finite clamp to kHalfMax first). No F16C needed, so it runs on any x86-64
// and gives the same bits everywhere.
#include <bit>
#include <cstddef>
#include <cstdint>

namespace engine::math {

inline constexpr float kHalfMax = 65504.0f;
inline constexpr float kHalfMinNormal = 6.103515625e-05f;  // 2^-14

inline std::uint16_t to_half(float f) {
  std::uint32_t x = std::bit_cast<std::uint32_t>(f);
  const std::uint32_t sign = x & 0x80000000u;
  x ^= sign;
  std::uint32_t o;
  if (x >= 0x47800000u) {  // 2^16 or more, Inf or NaN
    o = x > 0x7f800000u ? 0x7e00u : 0x7c00u;
  } else if (x < 0x38800000u) {  // below 2^-14: a subnormal half, rounded by the float adder
    const float t = std::bit_cast<float>(x) + 0.5f;
    o = std::bit_cast<std::uint32_t>(t) - 0x3f000000u;
  } else {
    const std::uint32_t mantissa_odd = (x >> 13) & 1u;
    x += 0xc8000fffu;  // rebias the exponent ((15 - 127) << 23) and add half an ulp minus one
    x += mantissa_odd;
    o = x >> 13;
  }
  return static_cast<std::uint16_t>(o | (sign >> 16));
}

inline float from_half(std::uint16_t h) {
  constexpr std::uint32_t kShiftedExp = 0x7c00u << 13;
  std::uint32_t o = (h & 0x7fffu) << 13;
  const std::uint32_t exp = kShiftedExp & o;
  o += (127 - 15) << 23;
  if (exp == kShiftedExp) {
    o += (128 - 16) << 23;  // Inf or NaN
  } else if (exp == 0) {    // zero or subnormal: renormalise through the float unit
    o += 1u << 23;
    o = std::bit_cast<std::uint32_t>(std::bit_cast<float>(o) - std::bit_cast<float>(113u << 23));
  }
  o |= static_cast<std::uint32_t>(h & 0x8000u) << 16;
  return std::bit_cast<float>(o);
}

}  // namespace engine::math

namespace engine::math {

// Bulk conversions, F16C where the CPU has it (8 values an instruction),
// else the functions above; the results are the same bits either way, NaN
// payloads aside
// (tests/engine/half_test.cpp).
void to_halves(const float* in, std::uint16_t* out, std::size_t n);
void from_halves(const std::uint16_t* in, float* out, std::size_t n);

}  // namespace engine::math
