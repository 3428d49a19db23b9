// AVX2 + FMA fused decoder, every layer fp32: the path for CPUs without
// AVX-512 BF16. Outputs across the 8 lanes, 6 rows x 2 vectors = 12
// accumulators per register block, 2 weight vectors and a broadcast (15 of
// the 16 ymm registers). Each weight vector loaded serves 6 FMAs: a hidden
// layer's 64 KB of fp32 weights does not fit L1, and with 2 rows x 4
// vectors (4 FMAs a weight load) the kernel waited on L2.
#include <immintrin.h>

#include <algorithm>

#include "shading/fused_kernels.h"

#define TRANSGI_AVX2 __attribute__((target("avx2,fma")))

namespace transgi::shading::detail {

namespace {

constexpr int kLanes = 8;
constexpr int kRows = 6;
static_assert(kGroupAvx2 == 2 * kLanes, "the register block is 2 vectors of outputs wide");
// A tile's rows rounded up to whole blocks of kRows.
constexpr int kTileRows = (kFusedTile + kRows - 1) / kRows * kRows;

struct Tile {
  alignas(32) float act[2][kTileRows * kMaxWidth];  // act[0] also holds the inputs
  alignas(32) float light[kTileRows * kLightPadded];
  alignas(32) float light2[kTileRows * kLightPadded];
  alignas(32) float transfer[kTileRows * kLightPadded];  // the output layer's values, when kept
  float rgb[kTileRows * 3], rgb2[kTileRows * 3];
  bool two_lights = false;
  bool keep_transfer = false;  // store the output layer instead of dotting it with the light
};

TRANSGI_AVX2 inline void dot_light(__m256 y, const float* light, int o, float* rgb) {
  alignas(32) float v[kLanes];
  _mm256_store_ps(v, _mm256_mul_ps(y, _mm256_loadu_ps(light + o)));
  for (int l = 0; l < kLanes && o + l < 75; ++l) rgb[(o + l) / 25] += v[l];
}

template <int NB>
TRANSGI_AVX2 void layer_group(const PackedLayer& L, int o0, Tile& t, int src, int rows, bool output) {
  constexpr int gs = NB * kLanes;
  const float* w = L.w_f32.data() + static_cast<std::size_t>(L.in) * o0;
  const float* x = t.act[src];
  for (int r0 = 0; r0 < rows; r0 += kRows) {
    __m256 acc[kRows][NB];
#pragma GCC unroll 8
    for (int j = 0; j < NB; ++j) {
      const __m256 b = _mm256_loadu_ps(L.bias.data() + o0 + j * kLanes);
#pragma GCC unroll 8
      for (int p = 0; p < kRows; ++p) acc[p][j] = b;
    }
    for (int k = 0; k < L.in; ++k) {
      __m256 wv[NB];
#pragma GCC unroll 8
      for (int j = 0; j < NB; ++j) wv[j] = _mm256_loadu_ps(w + k * gs + j * kLanes);
#pragma GCC unroll 8
      for (int p = 0; p < kRows; ++p) {
        const __m256 xv = _mm256_broadcast_ss(x + (r0 + p) * kMaxWidth + k);
#pragma GCC unroll 8
        for (int j = 0; j < NB; ++j) acc[p][j] = _mm256_fmadd_ps(xv, wv[j], acc[p][j]);
      }
    }
#pragma GCC unroll 8
    for (int p = 0; p < kRows; ++p)
#pragma GCC unroll 8
      for (int j = 0; j < NB; ++j) {
        const int o = o0 + j * kLanes;
        if (output && t.keep_transfer) {
          _mm256_store_ps(t.transfer + (r0 + p) * kLightPadded + o, acc[p][j]);
        } else if (output) {
          dot_light(acc[p][j], t.light + (r0 + p) * kLightPadded, o, t.rgb + (r0 + p) * 3);
          if (t.two_lights) dot_light(acc[p][j], t.light2 + (r0 + p) * kLightPadded, o, t.rgb2 + (r0 + p) * 3);
        } else {
          const __m256 v = L.relu ? _mm256_max_ps(acc[p][j], _mm256_setzero_ps()) : acc[p][j];
          _mm256_storeu_ps(t.act[1 - src] + (r0 + p) * kMaxWidth + o, v);
        }
      }
  }
}

TRANSGI_AVX2 void run_layer(const PackedLayer& L, Tile& t, int src, int rows, bool output) {
  for (int o0 = 0; o0 < L.out_padded; o0 += kGroupAvx2) {
    if (std::min(kGroupAvx2, L.out_padded - o0) / kLanes == 2)
      layer_group<2>(L, o0, t, src, rows, output);
    else
      layer_group<1>(L, o0, t, src, rows, output);
  }
}

}  // namespace

TRANSGI_AVX2 void shade_tile_avx2(const std::vector<PackedLayer>& layers, int inputs, const float* x, const float* light,
                                  int n, float* rgb, const float* light2, float* rgb2, float* transfer) {
  thread_local Tile t;
  t.keep_transfer = transfer != nullptr;
  t.two_lights = !t.keep_transfer && light2 && rgb2;
  const int rows = (n + kRows - 1) / kRows * kRows;
  // Rows are independent: the padding rows past n are zeroed only so that
  // they compute finite values, which are dropped at the end.
  std::fill_n(t.rgb, rows * 3, 0.0f);
  std::fill_n(t.rgb2, rows * 3, 0.0f);
  for (int i = 0; i < rows; ++i) {
    float* in = t.act[0] + i * kMaxWidth;
    float* l = t.light + i * kLightPadded;
    float* l2 = t.light2 + i * kLightPadded;
    if (i < n) {
      std::copy_n(x + static_cast<std::size_t>(i) * inputs, inputs, in);
      if (!t.keep_transfer) std::copy_n(light + static_cast<std::size_t>(i) * 75, 75, l);
      if (t.two_lights) std::copy_n(light2 + static_cast<std::size_t>(i) * 75, 75, l2);
    } else {
      std::fill_n(in, inputs, 0.0f);
    }
    std::fill(l + (i < n ? 75 : 0), l + kLightPadded, 0.0f);
    if (t.two_lights) std::fill(l2 + (i < n ? 75 : 0), l2 + kLightPadded, 0.0f);
  }
  int src = 0;
  for (std::size_t l = 0; l < layers.size(); ++l, src = 1 - src) run_layer(layers[l], t, src, rows, l + 1 == layers.size());
  if (t.keep_transfer) {
    for (int i = 0; i < n; ++i) std::copy_n(t.transfer + i * kLightPadded, 75, transfer + static_cast<std::size_t>(i) * 75);
    return;
  }
  std::copy_n(t.rgb, n * 3, rgb);
  if (t.two_lights) std::copy_n(t.rgb2, n * 3, rgb2);
}

}  // namespace transgi::shading::detail
