#version 460
// The probe rays' hits as the raster's shaded points, on the device
// (ProbeField's consume does the same on the CPU): ray k of the shading
// batch (tracing probe j = k / M, direction i = k % M) becomes point
// first[j] + i, where first[j] is where probe j's points begin in the
// raster's list (kProbePointsSkip: the CPU dropped them, e.g. a probe that
// moved). So the points need not come back to the host and go up again.
#extension GL_GOOGLE_include_directive : require
#include "probe_shading_shared.h"

layout(local_size_x = kProbeShadingGroupSize) in;
layout(std430, set = 0, binding = 0) readonly buffer Hits { ProbeRayHitGpu hits[]; };       // the shading's results
layout(std430, set = 0, binding = 1) readonly buffer Directions { vec4 directions[]; };     // its M directions
layout(std430, set = 0, binding = 2) readonly buffer First { uint first[]; };               // per tracing probe
layout(std430, set = 0, binding = 3) writeonly buffer Points { ShadedPointGpu points[]; };
layout(push_constant) uniform PushBlock { uint count; uint rays_per_probe; } p;

void main() {
  const uint k = gl_GlobalInvocationID.x;
  if (k >= p.count) return;
  const uint j = k / p.rays_per_probe, i = k % p.rays_per_probe;
  if (first[j] == kProbePointsSkip) return;
  const ProbeRayHitGpu h = hits[k];
  const vec3 d = directions[i].xyz;
  // An escaped ray's distance is +inf, as the host reads it back.
  const float distance = (h.flags & kProbeRayHit) != 0u ? h.distance : uintBitsToFloat(0x7f800000u);
  points[first[j] + i] = ShadedPointGpu(h.px, h.py, h.pz, distance, h.rr, h.rg, h.rb, 0.0, d.x, d.y, d.z, 0.0, h.nx, h.ny, h.nz, 0.0);
}
