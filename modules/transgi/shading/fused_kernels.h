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
// Outputs per register block: 4 vectors of 16 (AVX-512) or of 8 (AVX2).
inline constexpr int kGroupAvx512 = 64;
inline constexpr int kGroupAvx2 = 32;

// light2 / rgb2 may be null (one light).
void shade_tile_avx512bf16(const std::vector<PackedLayer>& layers, int inputs, const float* x, const float* light, int n,
                           float* rgb, const float* light2, float* rgb2);
void shade_tile_avx2(const std::vector<PackedLayer>& layers, int inputs, const float* x, const float* light, int n,
                     float* rgb, const float* light2, float* rgb2);

}  // namespace transgi::shading::detail
