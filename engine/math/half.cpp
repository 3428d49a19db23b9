#include "engine/math/half.h"

#include <immintrin.h>

#include "engine/core/cpu_isa.h"

namespace engine::math {

namespace {

// F16C is part of the AVX2 level (x86-64-v3), so the engine's ISA cap turns
// it off with the rest.
bool has_f16c() { return cpu::isa_enabled(cpu::Isa::Avx2); }

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
