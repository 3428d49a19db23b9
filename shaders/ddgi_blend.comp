#version 460
// DDGI blending (issue 12; the GPU twin of ddgi::blend_irradiance and
// blend_distance, RTXGI's ProbeBlendingCS and ProbeBorderUpdate): one
// workgroup per probe, lanes over the interior texels, then the borders.
#extension GL_GOOGLE_include_directive : require
#include "transgi_shared.h"

layout(local_size_x = kDdgiBlendGroupSize) in;

layout(std430, set = 0, binding = 0) readonly buffer Rays { DdgiRayGpu rays[]; };         // probes x rays_per_probe
layout(std430, set = 0, binding = 1) coherent buffer Irradiance { float irradiance[]; };  // probes x size^2 x rgb
layout(std430, set = 0, binding = 2) coherent buffer Distance { float distance[]; };      // probes x size^2 x 2
layout(std430, set = 0, binding = 3) readonly buffer Flags { uint blend[]; };             // 0: leave the probe

layout(push_constant) uniform PushBlock { DdgiBlendPush p; };

shared uint backfaces;

vec2 sign_not_zero(vec2 v) { return vec2(v.x >= 0.0 ? 1.0 : -1.0, v.y >= 0.0 ? 1.0 : -1.0); }

// ddgi::texel_direction.
vec3 texel_direction(uint x, uint y, uint n) {
  const vec2 c = (vec2(float(x), float(y)) + 0.5) / float(n) * 2.0 - 1.0;
  vec3 d = vec3(c.x, c.y, 1.0 - abs(c.x) - abs(c.y));
  if (d.z < 0.0) d.xy = (vec2(1.0) - abs(d.yx)) * sign_not_zero(d.xy);
  return normalize(d);
}

float max_component(vec3 v) { return max(v.x, max(v.y, v.z)); }

// ddgi::to_change_encoding: a texel stored with the maps' gamma, re-encoded with RTXGI's 5.
const float kRtxgiGamma = 5.0;
vec3 to_change_encoding(vec3 stored) {
  return p.irradiance_gamma == kRtxgiGamma ? stored : pow(max(stored, vec3(0.0)), vec3(p.irradiance_gamma / kRtxgiGamma));
}

uint irr_at(uint probe, uint x, uint y) {
  const uint size = p.irradiance_interior + 2u;
  return (probe * size * size + y * size + x) * 3u;
}
uint dist_at(uint probe, uint x, uint y) {
  const uint size = p.distance_interior + 2u;
  return (probe * size * size + y * size + x) * 2u;
}
void copy_irr(uint probe, uvec2 to, uvec2 from) {
  const uint a = irr_at(probe, to.x, to.y), b = irr_at(probe, from.x, from.y);
  irradiance[a] = irradiance[b];
  irradiance[a + 1u] = irradiance[b + 1u];
  irradiance[a + 2u] = irradiance[b + 2u];
}
void copy_dist(uint probe, uvec2 to, uvec2 from) {
  const uint a = dist_at(probe, to.x, to.y), b = dist_at(probe, from.x, from.y);
  distance[a] = distance[b];
  distance[a + 1u] = distance[b + 1u];
}

void main() {
  const uint probe = gl_WorkGroupID.x, lane = gl_LocalInvocationID.x;
  if (probe >= p.probes || blend[probe] == 0u) return;  // uniform per workgroup
  const uint first = probe * p.rays_per_probe;
  if (lane == 0u) backfaces = 0u;
  barrier();
  uint mine = 0u;
  for (uint r = lane; r < p.rays_per_probe; r += kDdgiBlendGroupSize) mine += rays[first + r].distance < 0.0 ? 1u : 0u;
  atomicAdd(backfaces, mine);
  barrier();
  // A probe at or past the back-face limit (inside geometry) keeps its irradiance.
  const bool blend_irradiance = !(backfaces > 0u && int(backfaces) >= p.max_backfaces);

  const uint n = p.irradiance_interior;
  if (blend_irradiance) {
    for (uint t = lane; t < n * n; t += kDdgiBlendGroupSize) {
      const uint x = t % n, y = t / n;
      const vec3 texel_dir = texel_direction(x, y, n);
      vec3 sum = vec3(0.0);
      float weight_sum = 0.0;
      for (uint r = 0u; r < p.rays_per_probe; ++r) {
        const DdgiRayGpu ray = rays[first + r];
        if (ray.distance < 0.0) continue;
        const float w = max(0.0, dot(texel_dir, vec3(ray.dx, ray.dy, ray.dz)));
        sum += vec3(ray.rx, ray.ry, ray.rz) * w;
        weight_sum += w;
      }
      const float epsilon = float(p.rays_per_probe) * 1e-9;
      vec3 result = sum / (2.0 * max(weight_sum, epsilon));
      result = pow(result, vec3(1.0 / p.irradiance_gamma));
      const uint at = irr_at(probe, x + 1u, y + 1u);
      const vec3 previous = vec3(irradiance[at], irradiance[at + 1u], irradiance[at + 2u]);
      float h = p.hysteresis;
      vec3 delta = result - previous;
      // RTXGI's change tests, judged in its gamma-5 encoding whatever the maps' (ddgi_blend.cpp).
      const vec3 old_judged = to_change_encoding(previous), new_judged = to_change_encoding(result);
      if (max_component(old_judged - new_judged) > p.irradiance_threshold) h = max(0.0, h - 0.75);
      if (p.clamp_brightness != 0u && length(new_judged - old_judged) > p.brightness_threshold) {
        result = previous + delta * 0.25;
        delta = result - previous;
      }
      vec3 lerp_delta = (1.0 - h) * delta;
      if (p.irradiance_gamma == kRtxgiGamma && max_component(result) < max_component(previous)) {
        const float threshold = 1.0 / 1024.0;
        for (int c = 0; c < 3; ++c)
          lerp_delta[c] = min(max(threshold, abs(lerp_delta[c])), abs(delta[c])) * sign(lerp_delta[c]);
      }
      const vec3 texel = previous + lerp_delta;
      irradiance[at] = texel.r;
      irradiance[at + 1u] = texel.g;
      irradiance[at + 2u] = texel.b;
    }
  }
  const uint dn = p.distance_interior;
  for (uint t = lane; t < dn * dn; t += kDdgiBlendGroupSize) {
    const uint x = t % dn, y = t / dn;
    const vec3 texel_dir = texel_direction(x, y, dn);
    vec2 sum = vec2(0.0);
    float weight_sum = 0.0;
    for (uint r = 0u; r < p.rays_per_probe; ++r) {
      const DdgiRayGpu ray = rays[first + r];
      const float w = pow(max(0.0, dot(texel_dir, vec3(ray.dx, ray.dy, ray.dz))), p.distance_exponent);
      const float d = min(abs(ray.distance), p.max_distance);
      sum += w * vec2(d, d * d);
      weight_sum += w;
    }
    if (weight_sum <= 0.0) continue;
    const vec2 result = sum / weight_sum;
    const uint at = dist_at(probe, x + 1u, y + 1u);
    const vec2 texel = mix(result, vec2(distance[at], distance[at + 1u]), p.hysteresis);
    distance[at] = texel.x;
    distance[at + 1u] = texel.y;
  }
  memoryBarrierBuffer();
  barrier();
  // ddgi::update_border: each border texel from the mirrored interior one.
  for (uint i = lane + 1u; i <= max(n, dn); i += kDdgiBlendGroupSize) {
    if (blend_irradiance && i <= n) {
      const uint e = n + 1u;
      copy_irr(probe, uvec2(i, 0u), uvec2(e - i, 1u));
      copy_irr(probe, uvec2(i, e), uvec2(e - i, n));
      copy_irr(probe, uvec2(0u, i), uvec2(1u, e - i));
      copy_irr(probe, uvec2(e, i), uvec2(n, e - i));
    }
    if (i <= dn) {
      const uint e = dn + 1u;
      copy_dist(probe, uvec2(i, 0u), uvec2(e - i, 1u));
      copy_dist(probe, uvec2(i, e), uvec2(e - i, dn));
      copy_dist(probe, uvec2(0u, i), uvec2(1u, e - i));
      copy_dist(probe, uvec2(e, i), uvec2(dn, e - i));
    }
  }
  if (lane == 0u) {
    if (blend_irradiance) {
      const uint e = n + 1u;
      copy_irr(probe, uvec2(0u, 0u), uvec2(n, n));
      copy_irr(probe, uvec2(e, 0u), uvec2(1u, n));
      copy_irr(probe, uvec2(0u, e), uvec2(n, 1u));
      copy_irr(probe, uvec2(e, e), uvec2(1u, 1u));
    }
    const uint e = dn + 1u;
    copy_dist(probe, uvec2(0u, 0u), uvec2(dn, dn));
    copy_dist(probe, uvec2(e, 0u), uvec2(1u, dn));
    copy_dist(probe, uvec2(0u, e), uvec2(dn, 1u));
    copy_dist(probe, uvec2(e, e), uvec2(1u, 1u));
  }
}
