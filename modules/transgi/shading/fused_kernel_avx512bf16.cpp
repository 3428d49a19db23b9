// AVX-512 BF16 fused decoder. Outputs lie across the 16 lanes; each of 4
// rows (shading points) broadcasts one bf16 pair of its activations, so a
// register block is 4 rows x 4 vectors = 16 independent accumulators, enough
// to cover vdpbf16ps latency at two per cycle. The hidden layers write their
// activations as bf16 rows ([point][output]), which is exactly the pair
// layout the next layer broadcasts: no shuffles between layers.
// GCC 12's own _mm512_undefined_ps (inside the mask-reduce intrinsics) trips
// -Wmaybe-uninitialized; the warning is about the header, not this code.
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <immintrin.h>

#include <algorithm>
#include <cstdint>
#include <cstring>

#include "shading/fused_kernels.h"

#define TRANSGI_AVX512BF16 __attribute__((target("avx512f,avx512bw,avx512vl,avx512bf16,fma")))

namespace transgi::shading::detail {

namespace {

constexpr int kLanes = 16;
// Rows per register block: 16 accumulators whatever the group's width, so a
// narrow last group (the output layer's 80 = 64 + 16) is not latency-bound.
template <int NB>
constexpr int kRowsFor = NB == 3 ? 4 : 16 / NB;
constexpr int kRowMultiple = 16;  // every kRowsFor divides it

struct Tile {
  alignas(64) float input[kFusedTile * kMaxInputs];
  alignas(64) float light[kFusedTile * kLightPadded];
  alignas(64) float light2[kFusedTile * kLightPadded];
  alignas(64) std::uint16_t act[2][kFusedTile * kMaxWidth];
  alignas(64) float transfer[kFusedTile * kLightPadded];  // the output layer's values, when kept
  float rgb[kFusedTile * 3], rgb2[kFusedTile * 3];
  bool two_lights = false;
  bool keep_transfer = false;  // store the output layer instead of dotting it with the light
};

TRANSGI_AVX512BF16 inline __m512bh broadcast_pair(const std::uint16_t* p) {
  std::int32_t v;
  std::memcpy(&v, p, sizeof v);
  return (__m512bh)_mm512_set1_epi32(v);
}

TRANSGI_AVX512BF16 inline void store_bf16(std::uint16_t* dst, __m512 v, bool relu) {
  if (relu) v = _mm512_max_ps(v, _mm512_setzero_ps());
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(dst), (__m256i)_mm512_cvtneps_pbh(v));
}

// Adds each lane's light-weighted value to the rgb sum of its colour channel
// (lane o of the 75 outputs belongs to channel o / 25).
TRANSGI_AVX512BF16 inline void dot_light(__m512 y, const float* light, int o, float* rgb) {
  const __m512 v = _mm512_mul_ps(y, _mm512_loadu_ps(light + o));
  for (int c = 0; c < 3; ++c) {
    const int lo = std::max(o, c * 25), hi = std::min(o + kLanes, c * 25 + 25);
    if (lo >= hi) continue;
    const auto mask = static_cast<__mmask16>(((1u << (hi - lo)) - 1u) << (lo - o));
    rgb[c] += _mm512_mask_reduce_add_ps(mask, v);
  }
}

// First layer, fp32: act[row][o0 .. o0 + NB*16) = relu(W x + b) as bf16.
template <int NB>
TRANSGI_AVX512BF16 void first_layer_group(const PackedLayer& L, int o0, const float* input, std::uint16_t* act,
                                          int act_stride, int rows) {
  constexpr int gs = NB * kLanes, kRows = kRowsFor<NB>;
  const float* w = L.w_f32.data() + static_cast<std::size_t>(L.in) * o0;
  for (int r0 = 0; r0 < rows; r0 += kRows) {
    __m512 acc[kRows][NB];
#pragma GCC unroll 16
    for (int j = 0; j < NB; ++j) {
      const __m512 b = _mm512_loadu_ps(L.bias.data() + o0 + j * kLanes);
#pragma GCC unroll 16
      for (int p = 0; p < kRows; ++p) acc[p][j] = b;
    }
    for (int k = 0; k < L.in; ++k) {
      __m512 wv[NB];
#pragma GCC unroll 16
      for (int j = 0; j < NB; ++j) wv[j] = _mm512_loadu_ps(w + k * gs + j * kLanes);
#pragma GCC unroll 16
      for (int p = 0; p < kRows; ++p) {
        const __m512 xv = _mm512_set1_ps(input[(r0 + p) * kMaxInputs + k]);
#pragma GCC unroll 16
        for (int j = 0; j < NB; ++j) acc[p][j] = _mm512_fmadd_ps(xv, wv[j], acc[p][j]);
      }
    }
#pragma GCC unroll 16
    for (int p = 0; p < kRows; ++p)
#pragma GCC unroll 16
      for (int j = 0; j < NB; ++j) store_bf16(act + (r0 + p) * act_stride + o0 + j * kLanes, acc[p][j], L.relu);
  }
}

// A bf16 layer: from act[src] to act[1 - src] (hidden) or dotted with the
// light into rgb (output layer).
template <int NB, bool kOutput>
TRANSGI_AVX512BF16 void bf16_layer_group(const PackedLayer& L, int o0, Tile& t, int src, int rows) {
  constexpr int gs = NB * kLanes, kRows = kRowsFor<NB>;
  const std::uint16_t* w = L.w_bf16.data() + static_cast<std::size_t>(L.in) * o0;
  const std::uint16_t* x = t.act[src];
  for (int r0 = 0; r0 < rows; r0 += kRows) {
    __m512 acc[kRows][NB];
#pragma GCC unroll 16
    for (int j = 0; j < NB; ++j) {
      const __m512 b = _mm512_loadu_ps(L.bias.data() + o0 + j * kLanes);
#pragma GCC unroll 16
      for (int p = 0; p < kRows; ++p) acc[p][j] = b;
    }
    for (int kp = 0; kp < L.in / 2; ++kp) {
      __m512bh wv[NB];
#pragma GCC unroll 16
      for (int j = 0; j < NB; ++j) wv[j] = (__m512bh)_mm512_loadu_si512(w + (kp * gs + j * kLanes) * 2);
#pragma GCC unroll 16
      for (int p = 0; p < kRows; ++p) {
        const __m512bh xv = broadcast_pair(x + (r0 + p) * kMaxWidth + 2 * kp);
#pragma GCC unroll 16
        for (int j = 0; j < NB; ++j) acc[p][j] = _mm512_dpbf16_ps(acc[p][j], xv, wv[j]);
      }
    }
#pragma GCC unroll 16
    for (int p = 0; p < kRows; ++p)
#pragma GCC unroll 16
      for (int j = 0; j < NB; ++j) {
        const int o = o0 + j * kLanes;
        if (kOutput && t.keep_transfer) {
          _mm512_store_ps(t.transfer + (r0 + p) * kLightPadded + o, acc[p][j]);
        } else if constexpr (kOutput) {
          dot_light(acc[p][j], t.light + (r0 + p) * kLightPadded, o, t.rgb + (r0 + p) * 3);
          if (t.two_lights) dot_light(acc[p][j], t.light2 + (r0 + p) * kLightPadded, o, t.rgb2 + (r0 + p) * 3);
        } else {
          store_bf16(t.act[1 - src] + (r0 + p) * kMaxWidth + o, acc[p][j], L.relu);
        }
      }
  }
}

// Runs fn<NB>(o0) over the layer's output groups (NB = 4 except a last,
// narrower group).
template <template <int> class Fn, class... Args>
TRANSGI_AVX512BF16 void for_each_group(const PackedLayer& L, Args&&... args) {
  for (int o0 = 0; o0 < L.out_padded; o0 += kGroupAvx512) {
    switch (std::min(kGroupAvx512, L.out_padded - o0) / kLanes) {
      case 4: Fn<4>::run(L, o0, args...); break;
      case 3: Fn<3>::run(L, o0, args...); break;
      case 2: Fn<2>::run(L, o0, args...); break;
      default: Fn<1>::run(L, o0, args...); break;
    }
  }
}

template <int NB>
struct FirstLayer {
  TRANSGI_AVX512BF16 static void run(const PackedLayer& L, int o0, const float* input, std::uint16_t* act, int act_stride,
                                     int rows) {
    first_layer_group<NB>(L, o0, input, act, act_stride, rows);
  }
};
template <int NB>
struct HiddenLayer {
  TRANSGI_AVX512BF16 static void run(const PackedLayer& L, int o0, Tile& t, int src, int rows) {
    bf16_layer_group<NB, false>(L, o0, t, src, rows);
  }
};
template <int NB>
struct OutputLayer {
  TRANSGI_AVX512BF16 static void run(const PackedLayer& L, int o0, Tile& t, int src, int rows) {
    bf16_layer_group<NB, true>(L, o0, t, src, rows);
  }
};

}  // namespace

TRANSGI_AVX512BF16 void first_layer_avx512(const PackedLayer& L, const float* input, std::uint16_t* act, int act_stride,
                                           int rows) {
  for_each_group<FirstLayer>(L, input, act, act_stride, rows);
}

TRANSGI_AVX512BF16 void shade_tile_avx512bf16(const std::vector<PackedLayer>& layers, int inputs, const float* x,
                                              const float* light, int n, float* rgb, const float* light2, float* rgb2,
                                              float* transfer) {
  thread_local Tile t;
  t.keep_transfer = transfer != nullptr;
  t.two_lights = !t.keep_transfer && light2 && rgb2;
  const int rows = (n + kRowMultiple - 1) / kRowMultiple * kRowMultiple;
  // Rows are independent: the padding rows past n are zeroed only so that
  // they compute finite values, which are dropped at the end.
  std::fill(t.input + n * kMaxInputs, t.input + rows * kMaxInputs, 0.0f);
  std::fill_n(t.rgb, rows * 3, 0.0f);
  std::fill_n(t.rgb2, rows * 3, 0.0f);
  for (int i = 0; i < rows; ++i) {
    float* l = t.light + i * kLightPadded;
    if (i < n && !t.keep_transfer) std::copy_n(light + static_cast<std::size_t>(i) * 75, 75, l);
    std::fill(l + (i < n ? 75 : 0), l + kLightPadded, 0.0f);
    if (t.two_lights) {
      float* l2 = t.light2 + i * kLightPadded;
      if (i < n) std::copy_n(light2 + static_cast<std::size_t>(i) * 75, 75, l2);
      std::fill(l2 + (i < n ? 75 : 0), l2 + kLightPadded, 0.0f);
    }
    if (i < n) std::copy_n(x + static_cast<std::size_t>(i) * inputs, inputs, t.input + i * kMaxInputs);
  }
  first_layer_avx512(layers.front(), t.input, t.act[0], kMaxWidth, rows);
  int src = 0;
  for (std::size_t l = 1; l + 1 < layers.size(); ++l, src = 1 - src) for_each_group<HiddenLayer>(layers[l], t, src, rows);
  for_each_group<OutputLayer>(layers.back(), t, src, rows);
  if (t.keep_transfer) {
    for (int i = 0; i < n; ++i) std::copy_n(t.transfer + i * kLightPadded, 75, transfer + static_cast<std::size_t>(i) * 75);
    return;
  }
  std::copy_n(t.rgb, n * 3, rgb);
  if (t.two_lights) std::copy_n(t.rgb2, n * 3, rgb2);
}

}  // namespace transgi::shading::detail
