// AMX fused decoder (Intel Sapphire Rapids and later). On these cores
// vdpbf16ps issues on one port, so the AVX-512 BF16 kernel is no faster than
// fp32 FMA; the tile unit does a 16x32 by 32x16 bf16 product per instruction.
//
// Each hidden or output layer is one tile matrix product over the tile's
// rows: blocks of 32 rows x 32 outputs held in four accumulator tiles, two
// activation tiles (rows) and two weight tiles (outputs) per 32-wide step of
// k, so every loaded tile feeds two products. The accumulators go to an fp32
// scratch in L1; an AVX-512 epilogue adds the bias and applies ReLU while
// converting to the next layer's bf16 rows, or, after the output layer, dots
// each colour channel's 25 values with the light. The output layer's columns
// are blocked by channel (c * 32 + k), so each channel is two whole vectors.
// The first layer (16 inputs) stays fp32 FMA, as in the AVX-512 BF16 kernel.
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <immintrin.h>

#include <algorithm>
#include <cstdint>

#include "shading/fused_kernels.h"

#define TRANSGI_AMX __attribute__((target("avx512f,avx512bw,avx512vl,avx512bf16,amx-tile,amx-bf16,fma")))

namespace transgi::shading::detail {

namespace {

constexpr int kRowBlock = 32;  // rows per accumulator block (two tiles of 16)

struct TileConfig {
  std::uint8_t palette = 1;
  std::uint8_t start_row = 0;
  std::uint8_t reserved[14] = {};
  std::uint16_t colsb[16] = {};
  std::uint8_t rows[16] = {};
};

struct Scratch {
  alignas(64) float input[kFusedTile * kMaxInputs];
  alignas(64) float light[kFusedTile * kAmxOutputs];
  alignas(64) float light2[kFusedTile * kAmxOutputs];
  alignas(64) std::uint16_t act[2][kFusedTile * kMaxWidth];
  alignas(64) float acc[kFusedTile * kMaxWidth];
};

// Every tile 16 rows x 64 bytes: 16 x 16 fp32 (accumulators), 16 rows x 32
// bf16 (activations), 16 k-pairs x 16 outputs x 2 bf16 (weights).
TRANSGI_AMX void configure_tiles() {
  TileConfig cfg;
  for (int i = 0; i < 8; ++i) {
    cfg.colsb[i] = 64;
    cfg.rows[i] = 16;
  }
  _tile_loadconfig(&cfg);
}

// acc[rows x L.out_padded] = act[rows x L.in] * W (no bias). act rows are
// `act_stride` bf16 apart; W is [k / 2][out][k % 2] over all outputs.
TRANSGI_AMX void tile_product(const PackedLayer& L, const std::uint16_t* act, int act_stride, float* acc, int rows) {
  const int n_out = L.out_padded;
  const std::uint16_t* w = L.w_bf16.data();
  const long a_stride = static_cast<long>(act_stride) * 2, w_stride = static_cast<long>(n_out) * 4, c_stride = w_stride;
  for (int r0 = 0; r0 < rows; r0 += kRowBlock) {
    for (int o0 = 0; o0 < n_out; o0 += 32) {
      _tile_zero(0);
      _tile_zero(1);
      _tile_zero(2);
      _tile_zero(3);
      for (int k0 = 0; k0 < L.in; k0 += 32) {
        _tile_loadd(4, act + r0 * act_stride + k0, a_stride);
        _tile_loadd(5, act + (r0 + 16) * act_stride + k0, a_stride);
        const std::uint16_t* wk = w + static_cast<std::size_t>(k0 / 2) * n_out * 2;
        _tile_loadd(6, wk + o0 * 2, w_stride);
        _tile_loadd(7, wk + (o0 + 16) * 2, w_stride);
        _tile_dpbf16ps(0, 4, 6);
        _tile_dpbf16ps(1, 4, 7);
        _tile_dpbf16ps(2, 5, 6);
        _tile_dpbf16ps(3, 5, 7);
      }
      _tile_stored(0, acc + r0 * n_out + o0, c_stride);
      _tile_stored(1, acc + r0 * n_out + o0 + 16, c_stride);
      _tile_stored(2, acc + (r0 + 16) * n_out + o0, c_stride);
      _tile_stored(3, acc + (r0 + 16) * n_out + o0 + 16, c_stride);
    }
  }
}

// act[r][o] = bf16(relu(acc[r][o] + bias[o])), rows n_out bf16 apart.
TRANSGI_AMX void bias_relu_to_bf16(const PackedLayer& L, const float* acc, std::uint16_t* act, int rows) {
  const int n_out = L.out_padded;
  for (int r = 0; r < rows; ++r)
    for (int o = 0; o < n_out; o += 32) {
      const float* a = acc + r * n_out + o;
      __m512 lo = _mm512_add_ps(_mm512_load_ps(a), _mm512_loadu_ps(L.bias.data() + o));
      __m512 hi = _mm512_add_ps(_mm512_load_ps(a + 16), _mm512_loadu_ps(L.bias.data() + o + 16));
      if (L.relu) {
        lo = _mm512_max_ps(lo, _mm512_setzero_ps());
        hi = _mm512_max_ps(hi, _mm512_setzero_ps());
      }
      _mm512_storeu_si512(act + r * n_out + o, (__m512i)_mm512_cvtne2ps_pbh(hi, lo));
    }
}

// rgb[r][c] = sum_k (acc[r][c*32 + k] + bias) * light[r][c*32 + k]; the
// padding columns have zero weights, bias and light.
TRANSGI_AMX void dot_with_light(const PackedLayer& L, const float* acc, const float* light, int n, float* rgb) {
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < 3; ++c) {
      const int o = c * 32;
      const float* a = acc + r * kAmxOutputs + o;
      const float* l = light + r * kAmxOutputs + o;
      const __m512 lo = _mm512_mul_ps(_mm512_add_ps(_mm512_load_ps(a), _mm512_loadu_ps(L.bias.data() + o)), _mm512_load_ps(l));
      const __m512 hi = _mm512_mul_ps(_mm512_add_ps(_mm512_load_ps(a + 16), _mm512_loadu_ps(L.bias.data() + o + 16)),
                                      _mm512_load_ps(l + 16));
      rgb[r * 3 + c] = _mm512_reduce_add_ps(_mm512_add_ps(lo, hi));
    }
}

// transfer[r][c * 25 + k] = acc[r][c * 32 + k] + bias: the output layer's
// values out of the channel-blocked layout.
TRANSGI_AMX void unblock_transfer(const PackedLayer& L, const float* acc, int n, float* transfer) {
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < 3; ++c)
      for (int k = 0; k < 25; ++k)
        transfer[static_cast<std::size_t>(r) * 75 + c * 25 + k] = acc[r * kAmxOutputs + c * 32 + k] + L.bias[static_cast<std::size_t>(c * 32 + k)];
}

// 75 light values into the channel-blocked, zero-padded layout.
void block_light(const float* src, float* dst) {
  for (int c = 0; c < 3; ++c) {
    std::copy_n(src + c * 25, 25, dst + c * 32);
    std::fill_n(dst + c * 32 + 25, 7, 0.0f);
  }
}

}  // namespace

TRANSGI_AMX void shade_tile_amx(const std::vector<PackedLayer>& layers, int inputs, const float* x, const float* light,
                                int n, float* rgb, const float* light2, float* rgb2, float* transfer) {
  thread_local Scratch s;
  const bool keep_transfer = transfer != nullptr;
  const bool two_lights = !keep_transfer && light2 && rgb2;
  const int rows = (n + kRowBlock - 1) / kRowBlock * kRowBlock;
  // Padding rows past n get zero inputs, so they compute finite values that
  // are never read back.
  for (int i = 0; i < rows; ++i) {
    float* in = s.input + i * kMaxInputs;
    if (i < n) {
      std::copy_n(x + static_cast<std::size_t>(i) * inputs, inputs, in);
      if (!keep_transfer) block_light(light + static_cast<std::size_t>(i) * 75, s.light + i * kAmxOutputs);
      if (two_lights) block_light(light2 + static_cast<std::size_t>(i) * 75, s.light2 + i * kAmxOutputs);
    } else {
      std::fill_n(in, inputs, 0.0f);
    }
  }
  const int width = layers.front().out_padded;
  first_layer_avx512(layers.front(), s.input, s.act[0], width, rows);
  configure_tiles();
  int src = 0;
  for (std::size_t l = 1; l + 1 < layers.size(); ++l, src = 1 - src) {
    tile_product(layers[l], s.act[src], layers[l].in, s.acc, rows);
    bias_relu_to_bf16(layers[l], s.acc, s.act[1 - src], rows);
  }
  const PackedLayer& out = layers.back();
  tile_product(out, s.act[src], out.in, s.acc, rows);
  _tile_release();
  if (keep_transfer) {
    unblock_transfer(out, s.acc, n, transfer);
    return;
  }
  dot_with_light(out, s.acc, s.light, n, rgb);
  if (two_lights) dot_with_light(out, s.acc, s.light2, n, rgb2);
}

TRANSGI_AMX double amx_peak_loop(long long reps) {
  alignas(64) static const std::uint16_t ones[16 * 32] = {};
  alignas(64) float out[16 * 16];
  configure_tiles();
  _tile_zero(0);
  _tile_zero(1);
  _tile_zero(2);
  _tile_zero(3);
  _tile_loadd(4, ones, 64);
  _tile_loadd(5, ones, 64);
  _tile_loadd(6, ones, 64);
  _tile_loadd(7, ones, 64);
  for (long long r = 0; r < reps; ++r) {
    _tile_dpbf16ps(0, 4, 6);
    _tile_dpbf16ps(1, 4, 7);
    _tile_dpbf16ps(2, 5, 6);
    _tile_dpbf16ps(3, 5, 7);
  }
  _tile_stored(0, out, 64);
  _tile_release();
  return static_cast<double>(out[0]);
}

}  // namespace transgi::shading::detail
