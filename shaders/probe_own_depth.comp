#version 460
// probes::update_own_depth on the device, bit for bit: each batch probe's
// depth map (binary16 mean and variance of its rays' hit distances, an
// exponential blend per texel) from its own rays, in their order, in the
// store's copy that the radiance raster's guard and the next frame's probe
// rays read. One invocation a probe: its rays may meet one texel several
// times, and the blend is sequential. `precise` keeps the compiler from
// fusing what the CPU rounds twice.
#extension GL_GOOGLE_include_directive : require
#include "probe_shading_shared.h"
#include "half_bits.glsl"
#include "map_texel.glsl"

layout(local_size_x = 64) in;
layout(std430, set = 0, binding = 0) readonly buffer Hits { ProbeRayHitGpu hits[]; };    // the shading's results
layout(std430, set = 0, binding = 1) readonly buffer Directions { vec4 directions[]; };  // its rays' directions
layout(std430, set = 0, binding = 2) readonly buffer Probes { OwnDepthProbeGpu probes[]; };
layout(std430, set = 0, binding = 3) buffer Depth { uint depth[]; };                     // mean | variance << 16
layout(push_constant) uniform PushBlock { OwnDepthPush p; };

const float kHalfMax = 65504.0;

// DepthMap::set: clamped into the half range, NaN kept for the mean.
uint depth_texel(float m, float v, float unit) {
  precise const float mu = m / unit;
  precise const float unit2 = unit * unit;
  precise const float var = v / unit2;
  const float mean_kept = isnan(mu) ? mu : min(mu, kHalfMax);
  const float var_kept = clamp((isinf(var) || isnan(var)) ? kHalfMax : var, 0.0, kHalfMax);
  return to_half_bits(mean_kept) | (to_half_bits(var_kept) << 16);
}

void main() {
  const uint k = gl_GlobalInvocationID.x;
  if (k >= p.count) return;
  const OwnDepthProbeGpu probe = probes[k];
  const uint texels = p.width * p.height;
  const float h = probe.blend, unit = probe.unit;
  precise const float keep = 1.0 - h;
  precise const float spread = h * keep;
  for (uint i = 0; i < p.rays_per_probe; ++i) {
    const ProbeRayHitGpu hit = hits[probe.first_ray + i];
    if ((hit.flags & kProbeRayHit) == 0u || isinf(hit.distance) || isnan(hit.distance)) continue;
    const uint at = probe.slot * texels + uint(map_texel_of(directions[i].xyz, p.width, p.height));
    const uint bits = depth[at];
    precise const float mean = from_half_bits(bits) * unit;
    if (isnan(mean)) {
      depth[at] = depth_texel(hit.distance, 0.0, unit);
      continue;
    }
    precise const float variance = from_half_bits(bits >> 16) * unit * unit;
    precise const float d = hit.distance - mean;
    precise const float new_mean = mean + keep * d;
    precise const float new_variance = h * variance + spread * d * d;
    depth[at] = depth_texel(new_mean, new_variance, unit);
  }
}
