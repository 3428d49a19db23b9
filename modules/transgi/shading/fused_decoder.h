#pragma once
// Fused transfer shading (issue 10, item 2): for a tile of shading points,
// the decoder's layers and the dot product with each point's object-space SH
// light run in one pass over a tile held in L1, so the 75 transfer
// coefficients never reach memory and the weights stay in cache across tiles.
//
// Backends, chosen at run time: the best the engine's effective ISA allows
// (engine/core/cpu_isa.h; TRANSGI_MAX_ISA caps it), or the one
// TRANSGI_FUSED_ISA=scalar|avx2|avx512bf16|amx names, within that cap:
//  - Amx: hidden and output layers as AMX bf16 tile products with fp32
//    accumulation (Intel cores where vdpbf16ps runs at half the FMA rate);
//    the first layer fp32 as below. Needs widths that are multiples of 32;
//  - Avx512Bf16: hidden and output layers as bf16 dot products (vdpbf16ps)
//    with fp32 accumulation; the first layer (16 inputs, 2 % of the FLOPs)
//    stays fp32 so normals and view directions keep full precision;
//  - Avx2: every layer fp32 FMA;
//  - Scalar: plain loops, the fallback and the readable statement of what the
//    others compute.
// The oracle they are tested against is infer_transfer_reference + shade().
#include <cstdint>
#include <vector>

#include "model/mlp.h"

namespace transgi::shading {

enum class FusedIsa { Scalar, Avx2, Avx512Bf16, Amx };

// Whether a backend rounds weights and activations to bf16.
constexpr bool is_bf16(FusedIsa isa) { return isa == FusedIsa::Avx512Bf16 || isa == FusedIsa::Amx; }

// The fastest backend this CPU runs (or the TRANSGI_FUSED_ISA override).
FusedIsa best_fused_isa();
// For Amx this also asks Linux for the tile state (arch_prctl), once.
bool cpu_supports(FusedIsa isa);
const char* fused_isa_name(FusedIsa isa);

// Shading points per kernel call: activations of a tile (64 x 128 bf16 =
// 16 KB) and one layer's weight slab fit in L1 together.
inline constexpr int kFusedTile = 64;

// One layer's weights repacked for the kernels. Outputs are split into groups
// of `group` outputs (the register block); within a group the layout is
// [k][output] for fp32 and [k / 2][output][k % 2] for bf16, so one vector load
// fetches one k (or k pair) for a whole block of outputs.
struct PackedLayer {
  int in = 0, out = 0, out_padded = 0;
  bool relu = true;
  bool bf16 = false;
  std::vector<float> w_f32;
  std::vector<std::uint16_t> w_bf16;
  std::vector<float> bias;  // out_padded, zero-padded
};

class FusedDecoder {
 public:
  // Throws std::invalid_argument if the layout has no 75 outputs.
  explicit FusedDecoder(const model::Mlp& mlp, FusedIsa isa = best_fused_isa());

  // rgb[i] = sum_c sum_k decoder(inputs[i])[c * 25 + k] * light[i][c * 25 + k]
  // for n <= kFusedTile points. inputs: n x layout().inputs; light: n x 75.
  // With light2 and rgb2 (both or neither), the same decoded transfer is
  // also dotted with a second light (the probes' direct sky and emitters)
  // into rgb2: 0.2 % more FLOPs, but a second set of lane reductions
  // (measured 7.1 -> 8.7 ms on the level's 55k points). Single-threaded: callers run tiles
  // in parallel.
  void shade_tile(const float* inputs, const float* light, int n, float* rgb, const float* light2 = nullptr,
                  float* rgb2 = nullptr) const;

  // The decoded transfer itself, for callers that keep it across frames and
  // dot it with later lights (gi_history.h): transfer: n x 75, [c * 25 + k]
  // per point, what shade_tile dots with its light. Single-threaded.
  void decode_tile(const float* inputs, int n, float* transfer) const;

  [[nodiscard]] FusedIsa isa() const { return isa_; }
  [[nodiscard]] const model::MlpLayout& layout() const { return layout_; }
  [[nodiscard]] const std::vector<PackedLayer>& layers() const { return layers_; }

 private:
  void run_tile(const float* inputs, const float* light, int n, float* rgb, const float* light2, float* rgb2,
                float* transfer) const;

  model::MlpLayout layout_;
  FusedIsa isa_;
  std::vector<PackedLayer> layers_;
  std::vector<float> params_;  // the plain parameters, read by the Scalar backend
};

// Round to nearest even, as vcvtneps2bf16 does (NaN stays NaN).
std::uint16_t to_bf16(float x);
float from_bf16(std::uint16_t x);

}  // namespace transgi::shading
