#version 460
// Probe interpolation with pruning for a batch of shading points
// (probe_interpolation.glsl): the weights and the blended light SH per point.
#extension GL_GOOGLE_include_directive : require
#include "transgi_shared.h"

layout(local_size_x = kInterpolateGroupSize) in;

layout(std430, set = 0, binding = 0) readonly buffer Points { float points[]; };     // n x (position, normal)
layout(std430, set = 0, binding = 1) readonly buffer Depth { uint depth[]; };        // probes x texels, half2(mean, variance)
layout(std430, set = 0, binding = 2) readonly buffer Probes { ProbeGpu probes[]; };
layout(std430, set = 0, binding = 3) readonly buffer ProbeSh { float probe_sh[]; };  // probes x 75
layout(std430, set = 0, binding = 4) writeonly buffer Results { InterpolationGpu results[]; };
layout(std430, set = 0, binding = 5) writeonly buffer PointSh { float point_sh[]; };  // n x 75

layout(push_constant) uniform PushBlock { InterpolatePush p; };

#include "probe_interpolation.glsl"

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= uint(p.points)) return;
  const vec3 x = vec3(points[i * 6], points[i * 6 + 1], points[i * 6 + 2]);
  const vec3 n = vec3(points[i * 6 + 3], points[i * 6 + 4], points[i * 6 + 5]);
  const InterpolationGpu r = interpolate_probes_at(p, 0u, 0u, x, n);
  results[i] = r;
  for (uint k = 0; k < kTransferOutputs; ++k) {
    float l = 0.0;
    for (int c = 0; c < 8; ++c)
      if (r.weights[c] > 0.0) l += r.weights[c] * probe_sh[uint(r.probes[c]) * kTransferOutputs + k];
    point_sh[i * kTransferOutputs + k] = l;
  }
}
