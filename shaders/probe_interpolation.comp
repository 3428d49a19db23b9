#version 460
// Probe interpolation with pruning (issue 12; the GPU twin of
// probes::interpolate_probes, paper Section 5.3): per shading point the 8
// probes of its cage with trilinear weights, minus back-facing probes and
// probes whose Chebyshev visibility bound (on their own hit-distance moments
// toward the point) is below the threshold; a distance-and-cosine average
// when all are pruned. Writes the weights and the blended light SH.
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

#include "map_texel.glsl"
#include "probe_grid.glsl"

int texel_of(vec3 d) { return map_texel_of(d, p.map_width, p.map_height); }
float chebyshev_visibility(float mean, float variance_in, float distance) {
  if (isnan(mean) || isinf(mean) || distance <= mean) return 1.0;
  const float variance = max(variance_in, 1e-6 * mean * mean + 1e-8);
  const float d = distance - mean;
  return variance / (variance + d * d);
}

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= uint(p.points)) return;
  const vec3 x = vec3(points[i * 6], points[i * 6 + 1], points[i * 6 + 2]);
  const vec3 n = vec3(points[i * 6 + 3], points[i * 6 + 4], points[i * 6 + 5]);
  const ivec3 dims = grid_dims(p.grid);
  const vec3 lo = grid_min(p.grid), s = grid_spacing(p.grid);

  // ProbeGrid::cage: the cell, clamped to the grid.
  vec3 g = vec3(0.0);
  for (int a = 0; a < 3; ++a)
    if (dims[a] > 1 && s[a] > 0.0) g[a] = clamp((x[a] - lo[a]) / s[a], 0.0, float(dims[a] - 1));
  const ivec3 base = min(ivec3(floor(g)), max(dims - 2, ivec3(0)));
  const vec3 f = clamp(g - vec3(base), vec3(0.0), vec3(1.0));
  const vec3 biased = x + n * p.bias_length;

  InterpolationGpu r;
  float fallback[8];
  float sum = 0.0;
  uint pruned = 0u;
  for (int c = 0; c < 8; ++c) {
    const ivec3 o = ivec3(c & 1, (c >> 1) & 1, (c >> 2) & 1);
    const ivec3 q = min(base + o, dims - 1);
    const int at = grid_index(p.grid, q);
    const float w = (o.x != 0 ? f.x : 1.0 - f.x) * (o.y != 0 ? f.y : 1.0 - f.y) * (o.z != 0 ? f.z : 1.0 - f.z);
    const ProbeGpu probe = probes[at];
    vec3 pos = lo + vec3(q) * s;
    if ((p.flags & kInterpolateHasOffsets) != 0u) pos += vec3(probe.offset_x, probe.offset_y, probe.offset_z);

    const vec3 to_probe = pos - x;
    const float dist = length(to_probe);
    const float facing = dist > 1e-6 ? dot(to_probe / dist, n) : 1.0;
    const vec3 from_probe = biased - pos;
    const float from_dist = length(from_probe);
    const bool occlusion = (p.flags & kInterpolatePruneOccluded) != 0u;
    const int texel = occlusion && from_dist > 1e-6 ? texel_of(from_probe / from_dist) : -1;

    const bool holds_light = probe.usable != 0u;
    fallback[c] = holds_light ? max(0.05, 0.5 * (facing + 1.0)) / (dist * dist + 1e-4) : 0.0;
    bool keep = w > 0.0 && holds_light;
    if (keep && (p.flags & kInterpolatePruneBackFacing) != 0u && facing < 0.0) keep = false;
    if (keep && texel >= 0) {
      const vec2 m = unpackHalf2x16(depth[uint(at) * p.texels + uint(texel)]);
      if (chebyshev_visibility(m.x * probe.depth_unit, m.y * probe.depth_unit * probe.depth_unit, from_dist) <
          p.visibility_threshold)
        keep = false;
    }
    if (!keep && w > 0.0) ++pruned;
    r.probes[c] = at;
    r.weights[c] = keep ? w : 0.0;
    sum += r.weights[c];
  }
  r.pruned = pruned;
  r.fallback = 0u;
  if (sum > 1e-6) {
    for (int c = 0; c < 8; ++c) r.weights[c] /= sum;
  } else {
    r.fallback = 1u;
    float fsum = 0.0;
    for (int c = 0; c < 8; ++c) fsum += fallback[c];
    for (int c = 0; c < 8; ++c) r.weights[c] = fsum > 0.0 ? fallback[c] / fsum : 0.0;
  }
  r.pad0 = 0u;
  r.pad1 = 0u;
  results[i] = r;

  for (uint k = 0; k < kTransferOutputs; ++k) {
    float l = 0.0;
    for (int c = 0; c < 8; ++c)
      if (r.weights[c] > 0.0) l += r.weights[c] * probe_sh[uint(r.probes[c]) * kTransferOutputs + k];
    point_sh[i * kTransferOutputs + k] = l;
  }
}
