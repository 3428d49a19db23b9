#version 460
// Fused transfer inference, tiled for GPUs (issue 12): the same contract as
// fused_inference.comp, which stays as its simple twin. That kernel gives
// each invocation one point and its 2 x 128 activations, which a GPU keeps in
// slow per-thread memory (2.5 ms for 57,600 points on an H100). Here a
// workgroup decodes 64 points at once: their activations sit in shared
// memory as [row][point], and invocation (g, q) sums output rows 4g..4g+3
// for points 16q..16q+15 in 64 registers. Per input row it loads its 4
// weights as one vec4 (a warp's lanes read neighbouring ones) and 4 vec4s of
// activations (the same for the whole warp: a broadcast) for 64 FMAs.
// Weights are fp32, transposed by the host (in x out per layer) and padded,
// so the 4 a lane needs are one vec4. The 75 outputs stay in shared memory,
// where they are dotted with the light SH (and a second light, if asked).
#extension GL_GOOGLE_include_directive : require
#include "transgi_shared.h"

layout(local_size_x = kFusedTiledGroupSize) in;

// Per layer: weights transposed (in x out, row-major) with each row of outputs
// padded with zeros to a multiple of 4, then the biases, padded likewise
// (fused_tiled_params on the host): a lane's 4 weights are one vec4.
layout(std430, set = 0, binding = 0) readonly buffer Params { vec4 params[]; };
layout(std430, set = 0, binding = 1) readonly buffer Inputs { float inputs[]; };  // count x inputs
layout(std430, set = 0, binding = 2) readonly buffer Light { float light[]; };    // count x 75, [c * 25 + k]
layout(std430, set = 0, binding = 3) writeonly buffer Rgb { float rgb[]; };       // count x 3
layout(std430, set = 0, binding = 4) readonly buffer Light2 { float light2[]; };  // with p.second: a second light
layout(std430, set = 0, binding = 5) writeonly buffer Rgb2 { float rgb2[]; };     // with p.second

layout(push_constant) uniform PushBlock { FusedPush p; };

// The host compiles the kernel for its network's layout, so loop bounds are
// constants; without the defines (the build's syntax check) the push
// constants give it.
#ifdef FUSED_WIDTH
#define N_INPUTS FUSED_INPUTS
#define N_WIDTH FUSED_WIDTH
#define N_HIDDEN FUSED_HIDDEN
#else
#define N_INPUTS p.inputs
#define N_WIDTH p.width
#define N_HIDDEN p.hidden_layers
#endif
#define RPL kFusedTiledRowsPerLane
#define PPL kFusedTiledPointsPerLane
#define TILE kFusedTiledPoints

// [row][point]; vec4 = 4 neighbouring points.
shared vec4 act[kFusedMaxWidth * TILE / 4];

void main() {
  const uint lane = gl_LocalInvocationID.x;
  const uint g = lane % 32u;  // row group: rows RPL*g ..
  const uint q = lane / 32u;  // point group: points PPL*q .. (one per warp of 32)
  const uint base = gl_WorkGroupID.x * TILE;

  // Consecutive lanes read consecutive floats (coalesced).
  for (uint t = lane; t < N_INPUTS * TILE; t += kFusedTiledGroupSize) {
    const uint pt = t / N_INPUTS, k = t % N_INPUTS;
    act[(k * TILE + pt) / 4][pt % 4] = base + pt < p.count ? inputs[base * N_INPUTS + t] : 0.0;
  }
  barrier();

  uint offset = 0;
  for (uint layer = 0; layer <= N_HIDDEN; ++layer) {
    const uint n_in = layer == 0 ? N_INPUTS : N_WIDTH;
    const bool last = layer == N_HIDDEN;
    const uint n_out = last ? kTransferOutputs : N_WIDTH;
    const uint out4 = (n_out + 3u) / 4u;  // padded row length in vec4s
    const uint bias_offset = offset + n_in * out4;
    vec4 acc[RPL][PPL / 4];
    for (uint j = 0; j < RPL; ++j)
      for (uint v = 0; v < PPL / 4; ++v) acc[j][v] = vec4(0.0);
    // Four input rows at a time: their four weight loads are in flight
    // together rather than each waited for before its 64 FMAs.
    const bool lane_has_rows = g < out4;
    uint k = 0;
    for (; k + 4u <= n_in; k += 4u) {
      vec4 w[4];
      for (uint u = 0; u < 4u; ++u) w[u] = lane_has_rows ? params[offset + (k + u) * out4 + g] : vec4(0.0);
      for (uint u = 0; u < 4u; ++u)
        for (uint v = 0; v < PPL / 4; ++v) {
          const vec4 a = act[((k + u) * TILE + PPL * q) / 4 + v];
          for (uint j = 0; j < RPL; ++j) acc[j][v] += w[u][j] * a;
        }
    }
    for (; k < n_in; ++k) {
      const vec4 w = lane_has_rows ? params[offset + k * out4 + g] : vec4(0.0);
      for (uint v = 0; v < PPL / 4; ++v) {
        const vec4 a = act[(k * TILE + PPL * q) / 4 + v];
        for (uint j = 0; j < RPL; ++j) acc[j][v] += w[j] * a;
      }
    }
    barrier();  // every lane has read this layer's inputs
    const vec4 bias4 = g < out4 ? params[bias_offset + g] : vec4(0.0);
    for (uint j = 0; j < RPL; ++j) {
      const uint r = RPL * g + j;
      if (r >= n_out) continue;
      const float bias = bias4[j];
      for (uint v = 0; v < PPL / 4; ++v) {
        const vec4 s = acc[j][v] + bias;
        act[(r * TILE + PPL * q) / 4 + v] = last ? s : max(s, vec4(0.0));
      }
    }
    barrier();
    offset = bias_offset + out4;
  }

  // Transfer coefficients are rows 0..74 of act; rows 75.. are free. Each
  // light (the second with p.second) is dotted with them half a tile at a
  // time: the lanes copy the half tile's light into the free rows, walking it
  // in memory order (coalesced; light is the kernel's largest input), then
  // one lane per point adds its 75 products.
  const uint half_tile = TILE / 2u;
  const uint scratch = kTransferOutputs * TILE;  // first free float of act
  const uint lights = p.second != 0u ? 2u : 1u;
  for (uint which = 0; which < lights; ++which)
    for (uint h = 0; h < 2u; ++h) {
      const uint first = base + h * half_tile;
      for (uint t = lane; t < half_tile * kTransferOutputs; t += kFusedTiledGroupSize) {
        const uint a = scratch + t, at = first * kTransferOutputs + t;
        const bool real = first + t / kTransferOutputs < p.count;
        act[a / 4][a % 4] = real ? (which == 0u ? light[at] : light2[at]) : 0.0;
      }
      barrier();
      if (lane < half_tile && first + lane < p.count) {
        const uint pt = h * half_tile + lane;
        vec3 gi = vec3(0.0);
        for (uint o = 0; o < kTransferOutputs; ++o) {
          const uint a = scratch + lane * kTransferOutputs + o;
          gi[o / kShCoefficients] += act[(o * TILE + pt) / 4][pt % 4] * act[a / 4][a % 4];
        }
        const uint i = first + lane;
        if (which == 0u) {
          rgb[i * 3 + 0] = gi.r;
          rgb[i * 3 + 1] = gi.g;
          rgb[i * 3 + 2] = gi.b;
        } else {
          rgb2[i * 3 + 0] = gi.r;
          rgb2[i * 3 + 1] = gi.g;
          rgb2[i * 3 + 2] = gi.b;
        }
      }
      barrier();  // the free rows are read before the next copy
    }
}
