#version 460
// SH projection of probe radiance maps (issue 12; the GPU twin of
// probes::MapProjector::project): out[probe][c * 25 + k] =
// sum_texels radiance[texel][c] * integral_texel Y_k. One workgroup per probe;
// each invocation sums a strided share of the texels, then invocation j < 75
// adds the 32 partial sums of coefficient j in a fixed order, so the result
// does not depend on scheduling.
#extension GL_GOOGLE_include_directive : require
#include "transgi_shared.h"

layout(local_size_x = kProjectGroupSize) in;

layout(std430, set = 0, binding = 0) readonly buffer Basis { float basis[]; };        // texels x 25
layout(std430, set = 0, binding = 1) readonly buffer Radiance { float radiance[]; };  // probes x texels x 3
layout(std430, set = 0, binding = 2) writeonly buffer Coefficients { float coefficients[]; };  // probes x 75

layout(push_constant) uniform PushBlock { ProjectPush p; };

shared float partial[kProjectGroupSize * kTransferOutputs];

void main() {
  const uint probe = gl_WorkGroupID.x;
  const uint lane = gl_LocalInvocationID.x;
  float acc[kTransferOutputs];
  for (uint j = 0; j < kTransferOutputs; ++j) acc[j] = 0.0;
  if (probe < p.probes) {
    const uint base = probe * p.texels * 3;
    for (uint t = lane; t < p.texels; t += kProjectGroupSize) {
      const vec3 l = vec3(radiance[base + t * 3], radiance[base + t * 3 + 1], radiance[base + t * 3 + 2]);
      for (uint k = 0; k < kShCoefficients; ++k) {
        const float y = basis[t * kShCoefficients + k];
        acc[k] += l.r * y;
        acc[kShCoefficients + k] += l.g * y;
        acc[2 * kShCoefficients + k] += l.b * y;
      }
    }
  }
  for (uint j = 0; j < kTransferOutputs; ++j) partial[lane * kTransferOutputs + j] = acc[j];
  barrier();
  if (probe >= p.probes) return;
  for (uint j = lane; j < kTransferOutputs; j += kProjectGroupSize) {
    float s = 0.0;
    for (uint i = 0; i < kProjectGroupSize; ++i) s += partial[i * kTransferOutputs + j];
    coefficients[probe * kTransferOutputs + j] = s;
  }
}
