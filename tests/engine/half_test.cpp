// binary16 conversions: known answers, every half round-trips, and rounding
// agrees with the hardware's F16C conversion where the CPU has it.
#include <gtest/gtest.h>

#include <immintrin.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "engine/math/half.h"
#include "engine/math/rng.h"

using engine::math::from_half;
using engine::math::to_half;

TEST(Half, KnownAnswers) {
  EXPECT_EQ(to_half(0.0f), 0x0000);
  EXPECT_EQ(to_half(-0.0f), 0x8000);
  EXPECT_EQ(to_half(1.0f), 0x3c00);
  EXPECT_EQ(to_half(-2.0f), 0xc000);
  EXPECT_EQ(to_half(65504.0f), 0x7bff);
  EXPECT_EQ(to_half(65520.0f), 0x7c00) << "halfway past the largest half rounds to infinity";
  EXPECT_EQ(to_half(1e6f), 0x7c00);
  EXPECT_EQ(to_half(INFINITY), 0x7c00);
  EXPECT_EQ(to_half(std::ldexp(1.0f, -14)), 0x0400) << "smallest normal";
  EXPECT_EQ(to_half(std::ldexp(1.0f, -24)), 0x0001) << "smallest subnormal";
  EXPECT_EQ(to_half(std::ldexp(1.0f, -26)), 0x0000) << "a quarter of it rounds to zero";
  EXPECT_EQ(to_half(1.0f + std::ldexp(1.0f, -11)), 0x3c00) << "halfway: to even (down)";
  EXPECT_EQ(to_half(1.0f + 3 * std::ldexp(1.0f, -11)), 0x3c02) << "halfway: to even (up)";
  EXPECT_EQ(to_half(1.0f + std::ldexp(1.0f, -11) + std::ldexp(1.0f, -20)), 0x3c01) << "just above halfway";
  EXPECT_TRUE(std::isnan(from_half(to_half(NAN))));
  EXPECT_EQ(from_half(0x7bff), 65504.0f);
  EXPECT_EQ(from_half(0x0001), std::ldexp(1.0f, -24));
  EXPECT_EQ(from_half(0x3555), 0.333251953125f);
}

TEST(Half, EveryHalfRoundTrips) {
  for (std::uint32_t h = 0; h < 0x10000u; ++h) {
    const float f = from_half(static_cast<std::uint16_t>(h));
    if (std::isnan(f)) {
      EXPECT_EQ(h & 0x7c00u, 0x7c00u) << std::hex << h;
      continue;
    }
    ASSERT_EQ(to_half(f), h) << "half 0x" << std::hex << h << " -> " << f;
  }
}

namespace {
__attribute__((target("f16c"))) std::uint16_t hardware_half(float f) {
  return static_cast<std::uint16_t>(_cvtss_sh(f, _MM_FROUND_TO_NEAREST_INT));
}
__attribute__((target("f16c"))) float hardware_float(std::uint16_t h) { return _cvtsh_ss(h); }
}  // namespace

TEST(Half, MatchesF16cOnRandomFloats) {
  if (!__builtin_cpu_supports("f16c")) GTEST_SKIP() << "no F16C on this CPU";
  engine::math::Pcg32 rng(3, 5);
  for (int i = 0; i < 1 << 20; ++i) {
    // Exponents from far below the subnormals to past the half range.
    const float f = (2 * rng.next_float() - 1) * std::ldexp(1.0f, static_cast<int>(rng.next_float() * 52) - 30);
    ASSERT_EQ(to_half(f), hardware_half(f)) << "float " << f;
    const auto h = static_cast<std::uint16_t>(rng.next_float() * 65536.0f);
    const float a = from_half(h), b = hardware_float(h);
    if (std::isnan(a) || std::isnan(b)) {
      ASSERT_EQ(std::isnan(a), std::isnan(b)) << "half " << h;
    } else {
      ASSERT_EQ(a, b) << "half " << h;
    }
  }
}

// The bulk conversions (F16C where present) against the scalar ones, with
// tails that are not whole vectors.
TEST(Half, BulkConversionsEqualTheScalarOnes) {
  engine::math::Pcg32 rng(8, 1);
  for (std::size_t n : {0u, 1u, 7u, 8u, 29u, 1000u}) {
    std::vector<float> f(n), back(n);
    std::vector<std::uint16_t> h(n);
    for (float& v : f) v = (2 * rng.next_float() - 1) * std::ldexp(1.0f, static_cast<int>(rng.next_float() * 40) - 26);
    engine::math::to_halves(f.data(), h.data(), n);
    engine::math::from_halves(h.data(), back.data(), n);
    for (std::size_t i = 0; i < n; ++i) {
      ASSERT_EQ(h[i], to_half(f[i])) << "n " << n << " value " << i << " (" << f[i] << ")";
      ASSERT_EQ(back[i], from_half(h[i])) << "n " << n << " value " << i;
    }
  }
}
