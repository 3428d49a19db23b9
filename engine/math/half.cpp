#include "engine/math/half.h"

#include <cpuid.h>
#include <immintrin.h>

namespace engine::math {

namespace {

bool has_f16c() {
  // CPUID rather than __builtin_cpu_supports("f16c"), which clang 14 (the fuzz
  // preset's compiler) does not know.
  static const bool yes = [] {
    unsigned a = 0, b = 0, c = 0, d = 0;
    return __get_cpuid(1, &a, &b, &c, &d) && (c & bit_F16C) != 0 && __builtin_cpu_supports("avx");
  }();
  return yes;
}

__attribute__((target("avx,f16c"))) void to_halves_f16c(const float* in, std::uint16_t* out, std::size_t n) {
  std::size_t i = 0;
  for (; i + 8 <= n; i += 8)
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out + i), _mm256_cvtps_ph(_mm256_loadu_ps(in + i), _MM_FROUND_TO_NEAREST_INT));
  for (; i < n; ++i) out[i] = to_half(in[i]);
}

__attribute__((target("avx,f16c"))) void from_halves_f16c(const std::uint16_t* in, float* out, std::size_t n) {
  std::size_t i = 0;
  for (; i + 8 <= n; i += 8)
    _mm256_storeu_ps(out + i, _mm256_cvtph_ps(_mm_loadu_si128(reinterpret_cast<const __m128i*>(in + i))));
  for (; i < n; ++i) out[i] = from_half(in[i]);
}

}  // namespace

void to_halves(const float* in, std::uint16_t* out, std::size_t n) {
  if (has_f16c()) return to_halves_f16c(in, out, n);
  for (std::size_t i = 0; i < n; ++i) out[i] = to_half(in[i]);
}

void from_halves(const std::uint16_t* in, float* out, std::size_t n) {
  if (has_f16c()) return from_halves_f16c(in, out, n);
  for (std::size_t i = 0; i < n; ++i) out[i] = from_half(in[i]);
}

}  // namespace engine::math
