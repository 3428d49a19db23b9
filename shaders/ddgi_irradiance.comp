#version 460
// DDGI irradiance at shading points (issue 12; the GPU twin of
// ddgi::DdgiVolume::irradiance, RTXGI's DDGIGetVolumeIrradiance): trilinear
// over the 8 probes around the biased point, wrap shading, Chebyshev
// visibility from the distance moments, weights crushed below 0.2, blended
// in gamma-2 space.
#extension GL_GOOGLE_include_directive : require
#include "transgi_shared.h"
#include "probe_grid.glsl"

layout(local_size_x = kDdgiGroupSize) in;

layout(std430, set = 0, binding = 0) readonly buffer Points { DdgiPointGpu points[]; };
layout(std430, set = 0, binding = 1) readonly buffer Irradiance { float irradiance[]; };  // probes x size^2 x rgb
layout(std430, set = 0, binding = 2) readonly buffer Distance { float distance[]; };      // probes x size^2 x 2
layout(std430, set = 0, binding = 3) readonly buffer Placed { vec4 placed[]; };           // xyz position, w: active
layout(std430, set = 0, binding = 4) writeonly buffer Result { vec4 result[]; };          // rgb irradiance, w: lit

layout(push_constant) uniform PushBlock { DdgiPush p; };

vec2 sign_not_zero(vec2 v) { return vec2(v.x >= 0.0 ? 1.0 : -1.0, v.y >= 0.0 ? 1.0 : -1.0); }

// ddgi::octahedral_coordinates.
vec2 octahedral_coordinates(vec3 d) {
  const float l1 = abs(d.x) + abs(d.y) + abs(d.z);
  vec2 uv = d.xy / l1;
  if (d.z < 0.0) uv = (vec2(1.0) - abs(uv.yx)) * sign_not_zero(uv);
  return uv;
}

// ddgi::sample_bilinear: the texel corner and the fractions.
void bilinear(vec3 d, uint size, uint interior, out ivec2 at, out vec2 f) {
  const vec2 oct = octahedral_coordinates(d);
  const float half_size = 0.5 * float(size);
  const vec2 q = vec2(half_size) + oct * (0.5 * float(interior)) - vec2(0.5);
  const vec2 c = clamp(q, vec2(0.0), vec2(float(size - 1u)));
  at = min(ivec2(c), ivec2(int(size) - 2));
  f = c - vec2(at);
}

vec3 irradiance_texel(int probe, int x, int y) {
  const uint i = (uint(probe) * p.irradiance_size * p.irradiance_size + uint(y) * p.irradiance_size + uint(x)) * 3u;
  return vec3(irradiance[i], irradiance[i + 1u], irradiance[i + 2u]);
}
vec2 distance_texel(int probe, int x, int y) {
  const uint i = (uint(probe) * p.distance_size * p.distance_size + uint(y) * p.distance_size + uint(x)) * 2u;
  return vec2(distance[i], distance[i + 1u]);
}

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= uint(p.points)) return;
  const DdgiPointGpu pt = points[i];
  const vec3 position = vec3(pt.px, pt.py, pt.pz), n = vec3(pt.nx, pt.ny, pt.nz), view_dir = vec3(pt.vx, pt.vy, pt.vz);
  const ivec3 dims = grid_dims(p.grid);
  const vec3 lo = grid_min(p.grid), spacing = grid_spacing(p.grid);
  const vec3 biased = position + (n * p.normal_bias - view_dir * p.view_bias);
  ivec3 base = ivec3(0);
  vec3 alpha = vec3(0.0);
  for (int a = 0; a < 3; ++a) {
    if (dims[a] < 2 || spacing[a] <= 0.0) continue;
    const float rel = (biased[a] - lo[a]) / spacing[a];
    base[a] = clamp(int(floor(rel)), 0, dims[a] - 1);
    alpha[a] = clamp(rel - float(base[a]), 0.0, 1.0);
  }
  vec3 sum = vec3(0.0);
  float weights = 0.0;
  for (int c = 0; c < 8; ++c) {
    const ivec3 offset = ivec3(c & 1, (c >> 1) & 1, (c >> 2) & 1);
    const int q = grid_index(p.grid, clamp(base + offset, ivec3(0), dims - 1));
    const vec4 probe = placed[q];
    if (probe.w == 0.0) continue;
    const vec3 to_probe = normalize(probe.xyz - position);
    const vec3 biased_to_probe = probe.xyz - biased;
    const float biased_dist = length(biased_to_probe);
    const vec3 trilinear3 = max(vec3(0.001), mix(vec3(1.0) - alpha, alpha, vec3(offset)));
    const float trilinear = trilinear3.x * trilinear3.y * trilinear3.z;
    const float wrap = 0.5 * (dot(to_probe, n) + 1.0);
    float w = wrap * wrap + 0.2;
    vec2 moments = vec2(0.0);
    if (biased_dist > 0.0) {
      ivec2 at;
      vec2 f;
      bilinear(-biased_to_probe / biased_dist, p.distance_size, p.distance_interior, at, f);
      moments = (distance_texel(q, at.x, at.y) * (1.0 - f.x) + distance_texel(q, at.x + 1, at.y) * f.x) * (1.0 - f.y) +
                (distance_texel(q, at.x, at.y + 1) * (1.0 - f.x) + distance_texel(q, at.x + 1, at.y + 1) * f.x) * f.y;
    }
    float chebyshev = 1.0;
    if (biased_dist > moments.x) {
      const float variance = abs(moments.x * moments.x - moments.y);
      const float v = biased_dist - moments.x;
      chebyshev = variance / (variance + v * v);
      chebyshev = max(chebyshev * chebyshev * chebyshev, 0.0);
    }
    w *= max(0.05, chebyshev);
    w = max(0.000001, w);
    const float crush = 0.2;
    if (w < crush) w *= w * w / (crush * crush);
    w *= trilinear;
    ivec2 at;
    vec2 f;
    bilinear(n, p.irradiance_size, p.irradiance_interior, at, f);
    const vec3 e = (irradiance_texel(q, at.x, at.y) * (1.0 - f.x) + irradiance_texel(q, at.x + 1, at.y) * f.x) * (1.0 - f.y) +
                   (irradiance_texel(q, at.x, at.y + 1) * (1.0 - f.x) + irradiance_texel(q, at.x + 1, at.y + 1) * f.x) * f.y;
    sum += w * pow(max(e, vec3(0.0)), vec3(0.5 * p.irradiance_gamma));
    weights += w;
  }
  if (weights <= 0.0) {
    result[i] = vec4(0.0);
    return;
  }
  const vec3 e = sum / weights;
  result[i] = vec4(e * e * 6.28318531, 1.0);
}
