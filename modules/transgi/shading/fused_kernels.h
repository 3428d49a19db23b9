#pragma once
// The SIMD backends of FusedDecoder (one file each, compiled with their own
// target attributes and entered only after the run-time CPU check).
#include <vector>

#include "shading/fused_decoder.h"

namespace transgi::shading::detail {

// Scratch sizes the kernels keep on the stack.
inline constexpr int kMaxInputs = 64;
inline constexpr int kMaxWidth = 256;
inline constexpr int kLightPadded = 80;  // 75 SH values, padded to whole vectors
// The AMX output layer: 3 channels x 25 values, each channel padded to 32.
inline constexpr int kAmxOutputs = 96;
// Outputs per register block: 4 vectors of 16 (AVX-512) or 2 of 8 (AVX2,
// whose 16 registers hold 6 rows of them).
inline constexpr int kGroupAvx512 = 64;
inline constexpr int kGroupAvx2 = 16;

// The fp32 first layer on AVX-512 FMA, shared by the bf16 and AMX backends:
// act[r * act_stride + o] = bf16(relu(W input_r + b)) for rows r < rows (a
// multiple of 16), inputs at input + r * kMaxInputs; L packed in groups of
// kGroupAvx512 fp32 outputs.
void first_layer_avx512(const PackedLayer& L, const float* input, std::uint16_t* act, int act_stride, int rows);

// light2 / rgb2 may be null (one light). With transfer, the output layer's
// values go there (n x 75) instead, and the lights and rgb are not read.
void shade_tile_avx512bf16(const std::vector<PackedLayer>& layers, int inputs, const float* x, const float* light, int n,
                           float* rgb, const float* light2, float* rgb2, float* transfer);
// AMX: hidden and output layers as bf16 tile products; layers packed by
// pack_layer_amx (outputs padded to 32, the output layer blocked by colour
// channel: channel c's 25 values at columns c * 32 ..).
void shade_tile_amx(const std::vector<PackedLayer>& layers, int inputs, const float* x, const float* light, int n,
                    float* rgb, const float* light2, float* rgb2, float* transfer);
// The tile unit's peak: `reps` x 4 independent tile products of 16,384 FLOP
// each, no memory traffic. Only where cpu_supports(FusedIsa::Amx).
double amx_peak_loop(long long reps);
void shade_tile_avx2(const std::vector<PackedLayer>& layers, int inputs, const float* x, const float* light, int n,
                     float* rgb, const float* light2, float* rgb2, float* transfer);

}  // namespace transgi::shading::detail
