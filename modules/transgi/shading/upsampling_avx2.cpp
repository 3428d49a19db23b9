// plan_row_scalar for 8 pixels at once, for CPUs without AVX-512 (issue 33:
// the AVX2 frame had only the scalar plan). Every operation is the scalar
// one, in the same order, with no contraction (this file is built with
// -ffp-contract=off), so the plans are bit-identical; a pixel's cells are
// gathered from the cell guides. upsampling_avx512.cpp is the same kernel
// at 16 lanes.
#include <immintrin.h>

#include <cstdint>

#include "shading/upsampling.h"

namespace transgi::shading::detail {

__attribute__((target("avx2"))) int plan_row_avx2(const PlanRow& r, UpsamplingPlan& u) {
  const int width = u.width;
  const std::size_t row = static_cast<std::size_t>(r.y) * static_cast<std::size_t>(width);
  const float* guide = &r.guide[0].x;
  const float* cells = &u.cell_guide[0].x;
  const float ty = u.row_t[static_cast<std::size_t>(r.y)];
  const __m256 zero = _mm256_setzero_ps(), one = _mm256_set1_ps(1.0f);
  const __m256 row_weight[2] = {_mm256_set1_ps(1 - ty), _mm256_set1_ps(ty)};
  const __m256i row_base[2] = {_mm256_set1_epi32(u.row0[static_cast<std::size_t>(r.y)] * u.grid_w),
                               _mm256_set1_epi32(u.row1[static_cast<std::size_t>(r.y)] * u.grid_w)};
  const __m256i lane4 = _mm256_setr_epi32(0, 4, 8, 12, 16, 20, 24, 28);
  const __m256 tolerance = _mm256_set1_ps(r.depth_tolerance), min_depth = _mm256_set1_ps(1e-6f), min_weight = _mm256_set1_ps(r.min_weight);
  const __m256i own_kind = _mm256_set1_epi32(UpsamplingPlan::kOwn), miss_kind = _mm256_set1_epi32(UpsamplingPlan::kMiss);
  int x = 0;
  for (; x + 8 <= width; x += 8) {
    const __m256i at = _mm256_add_epi32(lane4, _mm256_set1_epi32(4 * x));
    const __m256 px = _mm256_i32gather_ps(guide, at, 4), py = _mm256_i32gather_ps(guide + 1, at, 4);
    const __m256 pz = _mm256_i32gather_ps(guide + 2, at, 4), pw = _mm256_i32gather_ps(guide + 3, at, 4);
    const __m256 hit = _mm256_cmp_ps(pw, zero, _CMP_GT_OQ);
    // std::max(p.w, 1e-6f) keeps p.w unless it is below; hits have p.w > 0, not NaN.
    const __m256 denominator = _mm256_mul_ps(tolerance, _mm256_max_ps(pw, min_depth));
    const __m256 tx = _mm256_loadu_ps(&u.col_t[static_cast<std::size_t>(x)]);
    const __m256 col_weight[2] = {_mm256_sub_ps(one, tx), tx};
    const __m256i col[2] = {_mm256_loadu_si256(reinterpret_cast<const __m256i*>(&u.col0[static_cast<std::size_t>(x)])),
                            _mm256_loadu_si256(reinterpret_cast<const __m256i*>(&u.col1[static_cast<std::size_t>(x)]))};
    __m256 w[4];
    __m256 total = zero;
    for (int k = 0; k < 4; ++k) {
      const __m256i cell4 = _mm256_slli_epi32(_mm256_add_epi32(col[k & 1], row_base[k >> 1]), 2);
      const __m256 qx = _mm256_i32gather_ps(cells, cell4, 4), qy = _mm256_i32gather_ps(cells + 1, cell4, 4);
      const __m256 qz = _mm256_i32gather_ps(cells + 2, cell4, 4), qw = _mm256_i32gather_ps(cells + 3, cell4, 4);
      const __m256 dz = _mm256_div_ps(_mm256_sub_ps(qw, pw), denominator);
      // std::max(0.0f, v) is 0 for NaN and for -0, as is max_ps(v, 0).
      const __m256 depth = _mm256_max_ps(_mm256_sub_ps(one, _mm256_mul_ps(dz, dz)), zero);
      __m256 n = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(px, qx), _mm256_mul_ps(py, qy)), _mm256_mul_ps(pz, qz));
      n = _mm256_max_ps(n, zero);
      __m256 normal = one;
      for (int e = r.normal_power; e > 0; e >>= 1, n = _mm256_mul_ps(n, n))
        if (e & 1) normal = _mm256_mul_ps(normal, n);
      const __m256 cell_hit = _mm256_cmp_ps(qw, zero, _CMP_GT_OQ);
      const __m256 similarity = _mm256_and_ps(cell_hit, _mm256_mul_ps(depth, normal));
      w[k] = _mm256_mul_ps(_mm256_mul_ps(col_weight[k & 1], row_weight[k >> 1]), similarity);
      total = _mm256_add_ps(total, w[k]);
    }
    const __m256i own = _mm256_castps_si256(_mm256_cmp_ps(total, min_weight, _CMP_LT_OQ));
    __m256i kind = _mm256_and_si256(own, own_kind);
    kind = _mm256_blendv_epi8(miss_kind, kind, _mm256_castps_si256(hit));
    alignas(32) std::int32_t kinds[8];
    _mm256_store_si256(reinterpret_cast<__m256i*>(kinds), kind);
    for (int i = 0; i < 8; ++i) u.kind[row + static_cast<std::size_t>(x + i)] = static_cast<std::uint8_t>(kinds[i]);
    for (std::size_t k = 0; k < 4; ++k) _mm256_storeu_ps(&u.weight[k][row + static_cast<std::size_t>(x)], _mm256_div_ps(w[k], total));
  }
  return x;
}

}  // namespace transgi::shading::detail
