// Constants and structs shared by the C++ host code and the GLSL kernels
// (the Falcor pattern). Both languages include this file, so a field added on
// one side is added on the other. Rules that keep the layouts equal:
//  - only 32-bit scalars (uint, int, float), never vec3 (std430 pads it to 16);
//  - each struct padded by hand to a multiple of 16 bytes, and the C++ side
//    checks every size and offset with static_assert.
#ifndef TRANSGI_SHARED_H
#define TRANSGI_SHARED_H

#ifdef __cplusplus
#include <cstddef>
#include <cstdint>
namespace transgi::gpu {
using uint = std::uint32_t;
#define TRANSGI_CONST inline constexpr
#else
#define TRANSGI_CONST const
#endif

// Fused transfer inference (fused_inference.comp).
TRANSGI_CONST uint kFusedGroupSize = 64u;     // points per workgroup, one per invocation
TRANSGI_CONST uint kFusedMaxWidth = 128u;     // widest layer a kernel holds per invocation
TRANSGI_CONST uint kFusedRowsPerChunk = 32u;  // weight rows staged in shared memory at once: 32 x 128 fp32 = 16 KB
TRANSGI_CONST uint kShCoefficients = 25u;     // degree-4 SH
TRANSGI_CONST uint kTransferOutputs = 75u;    // 25 x RGB

struct FusedPush {
  uint count;          // shading points
  uint inputs;         // decoder inputs (16)
  uint width;          // hidden width (<= kFusedMaxWidth)
  uint hidden_layers;  // ReLU layers before the linear output
  uint outputs;        // kTransferOutputs
  uint pad0;
  uint pad1;
  uint pad2;
};

// SH projection of probe radiance maps (sh_projection.comp).
TRANSGI_CONST uint kProjectGroupSize = 32u;  // invocations per probe; 32 x 75 partial sums = 9.6 KB shared

struct ProjectPush {
  uint probes;
  uint texels;  // per map
  uint pad0;
  uint pad1;
};

#ifdef __cplusplus
static_assert(sizeof(ProjectPush) == 16 && offsetof(ProjectPush, texels) == 4, "ProjectPush layout");
static_assert(sizeof(FusedPush) == 32, "FusedPush must match its std430/push-constant layout");
static_assert(offsetof(FusedPush, count) == 0 && offsetof(FusedPush, inputs) == 4 && offsetof(FusedPush, width) == 8 &&
              offsetof(FusedPush, hidden_layers) == 12 && offsetof(FusedPush, outputs) == 16,
              "FusedPush field offsets");
static_assert(kFusedRowsPerChunk * kFusedMaxWidth * 4 <= 16384, "the weight chunk must fit the 16 KB we plan for");
}  // namespace transgi::gpu
#endif

#endif  // TRANSGI_SHARED_H
