#version 460
// Fused transfer inference (issue 12; the GPU twin of shading/fused_decoder):
// one invocation decodes one shading point through the MLP and dots the 75
// transfer coefficients with that point's light SH as they come out, so they
// never reach memory. Weights pass through shared memory a chunk of rows at a
// time (a whole 128-wide layer is 64 KB; devices guarantee 16-32 KB), read by
// all 64 points of the workgroup. With FUSED_F16_WEIGHTS (devices with
// shaderFloat16) the staged weights are fp16, half the shared memory and
// bandwidth; activations and sums stay fp32 either way.
#extension GL_GOOGLE_include_directive : require
#ifdef FUSED_F16_WEIGHTS
#extension GL_EXT_shader_explicit_arithmetic_types_float16 : require
#define WEIGHT float16_t
#else
#define WEIGHT float
#endif
#include "transgi_shared.h"

layout(local_size_x = kFusedGroupSize) in;

// The decoder's parameters exactly as model::Mlp stores them: per layer the
// weights (out x in, row-major), then the biases.
layout(std430, set = 0, binding = 0) readonly buffer Params { float params[]; };
layout(std430, set = 0, binding = 1) readonly buffer Inputs { float inputs[]; };  // count x inputs
layout(std430, set = 0, binding = 2) readonly buffer Light { float light[]; };    // count x 75, [c * 25 + k]
layout(std430, set = 0, binding = 3) writeonly buffer Rgb { float rgb[]; };       // count x 3
layout(std430, set = 0, binding = 4) readonly buffer Light2 { float light2[]; };  // with p.second: a second light
layout(std430, set = 0, binding = 5) writeonly buffer Rgb2 { float rgb2[]; };     // with p.second

layout(push_constant) uniform PushBlock { FusedPush p; };

// The host compiles the kernel for its network's layout (FUSED_INPUTS,
// FUSED_WIDTH, FUSED_HIDDEN as defines), so every loop bound is a constant
// the driver can unroll; without them the push constants give the layout.
#ifdef FUSED_WIDTH
#define N_INPUTS FUSED_INPUTS
#define N_WIDTH FUSED_WIDTH
#define N_HIDDEN FUSED_HIDDEN
#else
#define N_INPUTS p.inputs
#define N_WIDTH p.width
#define N_HIDDEN p.hidden_layers
#endif

shared WEIGHT chunk[kFusedRowsPerChunk * kFusedMaxWidth];

void main() {
  const uint i = gl_GlobalInvocationID.x;
  const bool in_range = i < p.count;  // idle lanes still join every barrier
  float a[kFusedMaxWidth];
  float b[kFusedMaxWidth];
  for (uint k = 0; k < N_INPUTS; ++k) a[k] = in_range ? inputs[i * N_INPUTS + k] : 0.0;
  vec3 gi = vec3(0.0), gi2 = vec3(0.0);

  uint offset = 0;
  const uint layers = N_HIDDEN + 1;
  for (uint layer = 0; layer < layers; ++layer) {
    const uint n_in = layer == 0 ? N_INPUTS : N_WIDTH;
    const bool last = layer == N_HIDDEN;
    const uint n_out = last ? kTransferOutputs : N_WIDTH;
    const uint bias_offset = offset + n_out * n_in;
    for (uint row0 = 0; row0 < n_out; row0 += kFusedRowsPerChunk) {
      const uint rows = min(kFusedRowsPerChunk, n_out - row0);
      barrier();  // the previous chunk is no longer read
      for (uint t = gl_LocalInvocationID.x; t < rows * n_in; t += kFusedGroupSize)
        chunk[t] = WEIGHT(params[offset + row0 * n_in + t]);
      barrier();
      for (uint r = 0; r < rows; ++r) {
        float s = params[bias_offset + row0 + r];
        for (uint k = 0; k < n_in; ++k) s += float(chunk[r * n_in + k]) * a[k];
        const uint o = row0 + r;
        if (!last) {
          b[o] = max(s, 0.0);
        } else if (in_range) {
          gi[o / kShCoefficients] += s * light[i * kTransferOutputs + o];
          if (p.second != 0u) gi2[o / kShCoefficients] += s * light2[i * kTransferOutputs + o];
        }
      }
    }
    if (!last)
      for (uint k = 0; k < n_out; ++k) a[k] = b[k];
    offset = bias_offset + n_out;
  }
  if (in_range) {
    rgb[i * 3 + 0] = gi.r;
    rgb[i * 3 + 1] = gi.g;
    rgb[i * 3 + 2] = gi.b;
    if (p.second != 0u) {
      rgb2[i * 3 + 0] = gi2.r;
      rgb2[i * 3 + 1] = gi2.g;
      rgb2[i * 3 + 2] = gi2.b;
    }
  }
}
