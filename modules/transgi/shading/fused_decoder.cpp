#include "shading/fused_decoder.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>

#include "engine/core/cpu_isa.h"
#include "shading/fused_kernels.h"

namespace transgi::shading {

std::uint16_t to_bf16(float x) {
  const std::uint32_t u = std::bit_cast<std::uint32_t>(x);
  if (std::isnan(x)) return static_cast<std::uint16_t>((u >> 16) | 0x40u);  // stay a (quiet) NaN
  const std::uint32_t rounding = 0x7fffu + ((u >> 16) & 1u);
  return static_cast<std::uint16_t>((u + rounding) >> 16);
}

float from_bf16(std::uint16_t x) { return std::bit_cast<float>(static_cast<std::uint32_t>(x) << 16); }

// The engine's effective ISA (capped by TRANSGI_MAX_ISA) decides; the BF16
// kernels also need AVX-512 BF16, which not every AVX-512 CPU has.
bool cpu_supports(FusedIsa isa) {
  using engine::cpu::Isa;
  switch (isa) {
    case FusedIsa::Scalar: return true;
    case FusedIsa::Avx2: return engine::cpu::isa_enabled(Isa::Avx2);
    case FusedIsa::Avx512Bf16: return engine::cpu::avx512_bf16();
    case FusedIsa::Amx: return engine::cpu::isa_enabled(Isa::Amx);
  }
  return false;
}

const char* fused_isa_name(FusedIsa isa) {
  switch (isa) {
    case FusedIsa::Scalar: return "scalar";
    case FusedIsa::Avx2: return "avx2";
    case FusedIsa::Avx512Bf16: return "avx512bf16";
    case FusedIsa::Amx: return "amx";
  }
  return "?";
}

FusedIsa best_fused_isa() {
  if (const char* v = std::getenv("TRANSGI_FUSED_ISA")) {
    for (FusedIsa isa : {FusedIsa::Scalar, FusedIsa::Avx2, FusedIsa::Avx512Bf16, FusedIsa::Amx})
      if (std::string(v) == fused_isa_name(isa)) {
        if (!cpu_supports(isa))
          throw std::runtime_error(std::string("TRANSGI_FUSED_ISA=") + v + ": not available on " + engine::cpu::isa_summary());
        return isa;
      }
    throw std::runtime_error(std::string("TRANSGI_FUSED_ISA: expected scalar, avx2, avx512bf16 or amx, got '") + v + "'");
  }
  if (cpu_supports(FusedIsa::Amx)) return FusedIsa::Amx;
  if (cpu_supports(FusedIsa::Avx512Bf16)) return FusedIsa::Avx512Bf16;
  if (cpu_supports(FusedIsa::Avx2)) return FusedIsa::Avx2;
  return FusedIsa::Scalar;
}

namespace {

// Whether the SIMD kernels' fixed scratch sizes and blockings hold this layout.
bool simd_layout_ok(const model::MlpLayout& l) {
  return l.hidden_layers >= 1 && l.inputs <= detail::kMaxInputs && l.width % 16 == 0 && l.width <= detail::kMaxWidth;
}

int round_up(int x, int m) { return (x + m - 1) / m * m; }

// The AMX kernel's tile products run over whole 32-wide steps of k and
// blocks of 32 outputs.
bool amx_layout_ok(const model::MlpLayout& l) { return simd_layout_ok(l) && l.width % 32 == 0; }

int same_output(int column) { return column; }

// The AMX output layer's columns blocked by colour channel: channel c's 25
// values at columns c * 32 .. c * 32 + 24, the rest padding (-1).
int channel_blocked_output(int column) { return column % 32 < 25 ? column / 32 * 25 + column % 32 : -1; }

// One layer packed for the kernels: out_padded columns, output_of(column) the
// decoder output a column holds (-1 or past the outputs: zero padding).
// Columns are split into groups of `group` (the register block); within a
// group the layout is [k][column] for fp32 and [k / 2][column][k % 2] for
// bf16. With one group of all columns, the bf16 layout is what an AMX weight
// tile reads: 16 k-pairs of 16 columns, rows out_padded * 4 bytes apart.
PackedLayer pack_layer(const model::Mlp& mlp, int layer, int out_padded, int group, bool bf16,
                       int (*output_of)(int) = same_output) {
  const model::MlpLayout& lay = mlp.layout();
  const float* w = mlp.params().data() + lay.weight_offset(layer);  // [out][in]
  const float* b = mlp.params().data() + lay.bias_offset(layer);
  PackedLayer p;
  p.in = lay.in_of(layer);
  p.out = lay.out_of(layer);
  p.out_padded = out_padded;
  p.relu = layer < lay.hidden_layers;
  p.bf16 = bf16;
  auto output = [&](int column) {
    const int o = output_of(column);
    return o >= 0 && o < p.out ? o : -1;
  };
  auto weight = [&](int column, int i) {
    const int o = output(column);
    return o >= 0 && i < p.in ? w[static_cast<std::size_t>(o) * p.in + i] : 0.0f;
  };
  p.bias.assign(static_cast<std::size_t>(p.out_padded), 0.0f);
  for (int col = 0; col < p.out_padded; ++col)
    if (output(col) >= 0) p.bias[static_cast<std::size_t>(col)] = b[output(col)];
  if (bf16) {
    const int in2 = round_up(p.in, 2);
    p.w_bf16.assign(static_cast<std::size_t>(in2) * p.out_padded, 0);
    for (int o0 = 0; o0 < p.out_padded; o0 += group) {
      const int gs = std::min(group, p.out_padded - o0);
      std::uint16_t* slab = p.w_bf16.data() + static_cast<std::size_t>(in2) * o0;
      for (int kp = 0; kp < in2 / 2; ++kp)
        for (int j = 0; j < gs; ++j)
          for (int r = 0; r < 2; ++r) slab[(kp * gs + j) * 2 + r] = to_bf16(weight(o0 + j, 2 * kp + r));
    }
  } else {
    p.w_f32.assign(static_cast<std::size_t>(p.in) * p.out_padded, 0.0f);
    for (int o0 = 0; o0 < p.out_padded; o0 += group) {
      const int gs = std::min(group, p.out_padded - o0);
      float* slab = p.w_f32.data() + static_cast<std::size_t>(p.in) * o0;
      for (int k = 0; k < p.in; ++k)
        for (int j = 0; j < gs; ++j) slab[k * gs + j] = weight(o0 + j, k);
    }
  }
  return p;
}

}  // namespace

FusedDecoder::FusedDecoder(const model::Mlp& mlp, FusedIsa isa) : layout_(mlp.layout()), isa_(isa), params_(mlp.params()) {
  if (layout_.outputs != 75)
    throw std::invalid_argument("FusedDecoder: the decoder must output 75 SH transfer values, has " +
                                std::to_string(layout_.outputs));
  if (!cpu_supports(isa_)) throw std::invalid_argument(std::string("FusedDecoder: CPU lacks ") + fused_isa_name(isa_));
  if (isa_ == FusedIsa::Amx && !amx_layout_ok(layout_)) isa_ = FusedIsa::Avx512Bf16;
  if (isa_ != FusedIsa::Scalar && !simd_layout_ok(layout_)) isa_ = FusedIsa::Scalar;
  if (isa_ == FusedIsa::Scalar) return;
  if (isa_ == FusedIsa::Amx) {
    layers_.push_back(pack_layer(mlp, 0, round_up(layout_.out_of(0), 16), detail::kGroupAvx512, false));
    for (int l = 1; l < layout_.hidden_layers; ++l) {
      const int columns = round_up(layout_.out_of(l), 32);
      layers_.push_back(pack_layer(mlp, l, columns, columns, true));
    }
    layers_.push_back(pack_layer(mlp, layout_.hidden_layers, detail::kAmxOutputs, detail::kAmxOutputs, true, channel_blocked_output));
    return;
  }
  const bool avx512 = isa_ == FusedIsa::Avx512Bf16;
  const int lane = avx512 ? 16 : 8;
  const int group = avx512 ? detail::kGroupAvx512 : detail::kGroupAvx2;
  for (int l = 0; l < layout_.layer_count(); ++l)
    layers_.push_back(pack_layer(mlp, l, round_up(layout_.out_of(l), lane), group, avx512 && l > 0));
}

void FusedDecoder::shade_tile(const float* inputs, const float* light, int n, float* rgb, const float* light2,
                              float* rgb2) const {
  if (!light2 || !rgb2) light2 = nullptr, rgb2 = nullptr;
  run_tile(inputs, light, n, rgb, light2, rgb2, nullptr);
}

void FusedDecoder::decode_tile(const float* inputs, int n, float* transfer) const {
  run_tile(inputs, nullptr, n, nullptr, nullptr, nullptr, transfer);
}

void FusedDecoder::run_tile(const float* inputs, const float* light, int n, float* rgb, const float* light2, float* rgb2,
                            float* transfer) const {
  if (n <= 0) return;
  if (n > kFusedTile) throw std::invalid_argument("FusedDecoder: more than kFusedTile points in a tile");
  switch (isa_) {
    case FusedIsa::Avx512Bf16:
      detail::shade_tile_avx512bf16(layers_, layout_.inputs, inputs, light, n, rgb, light2, rgb2, transfer);
      return;
    case FusedIsa::Amx: detail::shade_tile_amx(layers_, layout_.inputs, inputs, light, n, rgb, light2, rgb2, transfer); return;
    case FusedIsa::Avx2: detail::shade_tile_avx2(layers_, layout_.inputs, inputs, light, n, rgb, light2, rgb2, transfer); return;
    case FusedIsa::Scalar: break;
  }
  // Plain fp32 loops, one point at a time.
  std::vector<float> x, y;
  for (int i = 0; i < n; ++i) {
    x.assign(inputs + static_cast<std::size_t>(i) * layout_.inputs, inputs + static_cast<std::size_t>(i + 1) * layout_.inputs);
    for (int l = 0; l < layout_.layer_count(); ++l) {
      const int n_in = layout_.in_of(l), n_out = layout_.out_of(l);
      const float* w = params_.data() + layout_.weight_offset(l);
      const float* b = params_.data() + layout_.bias_offset(l);
      y.assign(static_cast<std::size_t>(n_out), 0.0f);
      for (int o = 0; o < n_out; ++o) {
        float s = b[o];
        for (int k = 0; k < n_in; ++k) s += w[static_cast<std::size_t>(o) * n_in + k] * x[static_cast<std::size_t>(k)];
        y[static_cast<std::size_t>(o)] = l < layout_.hidden_layers ? std::max(0.0f, s) : s;
      }
      x.swap(y);
    }
    if (transfer) {
      std::copy_n(x.data(), 75, transfer + static_cast<std::size_t>(i) * 75);
      continue;
    }
    for (int which = 0; which < (light2 ? 2 : 1); ++which) {
      const float* li = (which ? light2 : light) + static_cast<std::size_t>(i) * 75;
      for (int c = 0; c < 3; ++c) {
        float s = 0;
        for (int k = 0; k < 25; ++k) s += x[static_cast<std::size_t>(c * 25 + k)] * li[c * 25 + k];
        (which ? rgb2 : rgb)[i * 3 + c] = s;
      }
    }
  }
}

}  // namespace transgi::shading
