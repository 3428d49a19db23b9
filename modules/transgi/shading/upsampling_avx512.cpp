// plan_row_scalar for 16 pixels at once. Every operation is the scalar
// one, in the same order, with no contraction (this file is built with
// -ffp-contract=off), so the plans are bit-identical; a pixel's cells are
// gathered from the cell guides.
#include <immintrin.h>

// GCC 12's AVX-512 intrinsics start from _mm512_undefined_*(), which trips
// -Wmaybe-uninitialized; the warning is about the header, not this code.
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"

#include "shading/upsampling.h"

namespace transgi::shading::detail {

__attribute__((target("avx512f"))) int plan_row_avx512(const PlanRow& r, UpsamplingPlan& u) {
  const int width = u.width;
  const std::size_t row = static_cast<std::size_t>(r.y) * static_cast<std::size_t>(width);
  const float* guide = &r.guide[0].x;
  const float* cells = &u.cell_guide[0].x;
  const float ty = u.row_t[static_cast<std::size_t>(r.y)];
  const __m512 zero = _mm512_setzero_ps(), one = _mm512_set1_ps(1.0f);
  const __m512 row_weight[2] = {_mm512_set1_ps(1 - ty), _mm512_set1_ps(ty)};
  const __m512i row_base[2] = {_mm512_set1_epi32(u.row0[static_cast<std::size_t>(r.y)] * u.grid_w),
                               _mm512_set1_epi32(u.row1[static_cast<std::size_t>(r.y)] * u.grid_w)};
  const __m512i lane4 = _mm512_mullo_epi32(_mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15), _mm512_set1_epi32(4));
  const __m512 tolerance = _mm512_set1_ps(r.depth_tolerance), min_depth = _mm512_set1_ps(1e-6f), min_weight = _mm512_set1_ps(r.min_weight);
  int x = 0;
  for (; x + 16 <= width; x += 16) {
    const __m512i at = _mm512_add_epi32(lane4, _mm512_set1_epi32(4 * x));
    const __m512 px = _mm512_i32gather_ps(at, guide, 4), py = _mm512_i32gather_ps(at, guide + 1, 4);
    const __m512 pz = _mm512_i32gather_ps(at, guide + 2, 4), pw = _mm512_i32gather_ps(at, guide + 3, 4);
    const __mmask16 hit = _mm512_cmp_ps_mask(pw, zero, _CMP_GT_OQ);
    // std::max(p.w, 1e-6f) keeps p.w unless it is below; hits have p.w > 0, not NaN.
    const __m512 denominator = _mm512_mul_ps(tolerance, _mm512_max_ps(pw, min_depth));
    const __m512 tx = _mm512_loadu_ps(&u.col_t[static_cast<std::size_t>(x)]);
    const __m512 col_weight[2] = {_mm512_sub_ps(one, tx), tx};
    const __m512i col[2] = {_mm512_loadu_si512(&u.col0[static_cast<std::size_t>(x)]), _mm512_loadu_si512(&u.col1[static_cast<std::size_t>(x)])};
    __m512 w[4];
    __m512 total = zero;
    for (int k = 0; k < 4; ++k) {
      const __m512i cell4 = _mm512_slli_epi32(_mm512_add_epi32(col[k & 1], row_base[k >> 1]), 2);
      const __m512 qx = _mm512_i32gather_ps(cell4, cells, 4), qy = _mm512_i32gather_ps(cell4, cells + 1, 4);
      const __m512 qz = _mm512_i32gather_ps(cell4, cells + 2, 4), qw = _mm512_i32gather_ps(cell4, cells + 3, 4);
      const __m512 dz = _mm512_div_ps(_mm512_sub_ps(qw, pw), denominator);
      // std::max(0.0f, v) is 0 for NaN and for -0, as is max_ps(v, 0).
      const __m512 depth = _mm512_max_ps(_mm512_sub_ps(one, _mm512_mul_ps(dz, dz)), zero);
      __m512 n = _mm512_add_ps(_mm512_add_ps(_mm512_mul_ps(px, qx), _mm512_mul_ps(py, qy)), _mm512_mul_ps(pz, qz));
      n = _mm512_max_ps(n, zero);
      __m512 normal = one;
      for (int e = r.normal_power; e > 0; e >>= 1, n = _mm512_mul_ps(n, n))
        if (e & 1) normal = _mm512_mul_ps(normal, n);
      const __mmask16 cell_hit = _mm512_cmp_ps_mask(qw, zero, _CMP_GT_OQ);
      const __m512 similarity = _mm512_maskz_mov_ps(cell_hit, _mm512_mul_ps(depth, normal));
      w[k] = _mm512_mul_ps(_mm512_mul_ps(col_weight[k & 1], row_weight[k >> 1]), similarity);
      total = _mm512_add_ps(total, w[k]);
    }
    const __mmask16 own = _mm512_cmp_ps_mask(total, min_weight, _CMP_LT_OQ);
    __m512i kind = _mm512_maskz_mov_epi32(own, _mm512_set1_epi32(UpsamplingPlan::kOwn));
    kind = _mm512_mask_mov_epi32(_mm512_set1_epi32(UpsamplingPlan::kMiss), hit, kind);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(&u.kind[row + static_cast<std::size_t>(x)]), _mm512_cvtepi32_epi8(kind));
    for (std::size_t k = 0; k < 4; ++k) _mm512_storeu_ps(&u.weight[k][row + static_cast<std::size_t>(x)], _mm512_div_ps(w[k], total));
  }
  return x;
}

}  // namespace transgi::shading::detail
