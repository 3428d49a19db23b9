#version 460
// Across-probe radiance sharing (issue 12; the GPU twin of
// probes::rasterize_shared, paper Section 5.2): each target probe's frame
// samples from its own and its 26 neighbours' shaded points, each in the
// texel of the direction from the target, with the same-side and depth
// guards.
//
// A gather, not an atomic scatter: one workgroup per target probe classifies
// a chunk of candidate points into shared memory, then lane j adds the
// points that fall in the texels it owns (texel mod 64 == j) in point order.
// No two lanes write one texel, so the sums come out in the CPU's order and
// the same on every run; float atomics would make each frame's bits depend
// on scheduling. Only the accepted/rejected counters use (integer) atomics.
#extension GL_GOOGLE_include_directive : require
#include "transgi_shared.h"

layout(local_size_x = kRasterGroupSize) in;

layout(std430, set = 0, binding = 0) readonly buffer Points { ShadedPointGpu points[]; };
layout(std430, set = 0, binding = 1) readonly buffer PointRanges { uint point_begin[]; };  // probes + 1
layout(std430, set = 0, binding = 2) readonly buffer Depth { uint depth[]; };  // probes x texels, half2(mean, variance)
layout(std430, set = 0, binding = 3) readonly buffer Probes { ProbeGpu probes[]; };    // offsets, depth units
layout(std430, set = 0, binding = 4) readonly buffer Targets { uint targets[]; };      // 0 = leave the probe alone
layout(std430, set = 0, binding = 5) buffer Samples { vec4 samples[]; };               // probes x texels: sum rgb, count
layout(std430, set = 0, binding = 6) buffer Stats { uint accepted; uint rejected; };

layout(push_constant) uniform PushBlock { RasterPush p; };

#include "map_texel.glsl"
#include "probe_grid.glsl"

int texel_of(vec3 d) { return map_texel_of(d, p.map_width, p.map_height); }

const int kRejected = -1;
const int kSkipped = -2;
const int kZeroSample = 0x40000000;  // or'ed into the texel: an escaped own ray, a sample of 0

shared int chunk_texel[kRasterChunk];
shared uint chunk_point[kRasterChunk];
shared uint chunk_accepted, chunk_rejected;

void main() {
  const int target = int(gl_WorkGroupID.x);
  const uint lane = gl_LocalInvocationID.x;
  if (target >= p.grid.probes || targets[target] == 0u) return;  // uniform per workgroup
  const ivec3 dims = grid_dims(p.grid);
  const ivec3 tc = grid_coords(p.grid, target);
  vec3 origin = grid_min(p.grid) + vec3(tc) * grid_spacing(p.grid);
  if ((p.flags & kRasterHasOffsets) != 0u) origin += vec3(probes[target].offset_x, probes[target].offset_y, probes[target].offset_z);
  const uint base = uint(target) * p.texels;
  for (uint t = lane; t < p.texels; t += kRasterGroupSize) samples[base + t] = vec4(0.0);
  if (lane == 0u) {
    chunk_accepted = 0u;
    chunk_rejected = 0u;
  }
  const bool guard = (p.flags & kRasterDepthGuard) != 0u;

  // The neighbours in ProbeGrid::for_each_neighbour's order.
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const ivec3 nc = tc + ivec3(dx, dy, dz);
        if (any(lessThan(nc, ivec3(0))) || any(greaterThanEqual(nc, dims))) continue;  // uniform
        const int q = grid_index(p.grid, nc);
        const uint first = point_begin[q], last = point_begin[q + 1];
        for (uint c0 = first; c0 < last; c0 += kRasterChunk) {
          const uint n = min(kRasterChunk, last - c0);
          barrier();  // the previous chunk has been consumed
          for (uint k = lane; k < n; k += kRasterGroupSize) {
            const ShadedPointGpu pt = points[c0 + k];
            int texel = kSkipped;
            if (isinf(pt.distance) || isnan(pt.distance)) {
              if (q == target) texel = texel_of(vec3(pt.dx, pt.dy, pt.dz)) | kZeroSample;
            } else {
              const vec3 d = vec3(pt.px, pt.py, pt.pz) - origin;
              const float dist = length(d);
              if (dist > 1e-6) {
                const vec3 u = d / dist;
                texel = texel_of(u);
                if (q != target && guard && (p.flags & kRasterSameSide) != 0u && dot(vec3(pt.nx, pt.ny, pt.nz), u) > 0.0) {
                  texel = kRejected;
                } else if (q != target && guard && (p.flags & kRasterHasDepth) != 0u) {
                  const vec2 moments = unpackHalf2x16(depth[base + uint(texel)]);
                  const float unit = probes[target].depth_unit;
                  const float own = moments.x * unit, spread = sqrt(moments.y * unit * unit);
                  // No own hit in the texel (NaN): nothing says the point is
                  // visible from the target (radiance_sharing.cpp).
                  if (isnan(own) || isinf(own) ||
                      dist > own * (1.0 + p.relative_tolerance) + p.absolute_tolerance * unit + p.spread_tolerance * spread)
                    texel = kRejected;
                }
              }
            }
            chunk_texel[k] = texel;
            chunk_point[k] = c0 + k;
            if (texel == kRejected) atomicAdd(chunk_rejected, 1u);
            else if (texel != kSkipped) atomicAdd(chunk_accepted, 1u);
          }
          barrier();
          for (uint k = 0; k < n; ++k) {
            const int texel = chunk_texel[k];
            if (texel < 0) continue;
            const uint t = uint(texel & (kZeroSample - 1));
            if (t % kRasterGroupSize != lane) continue;
            vec4 s = samples[base + t];
            if ((texel & kZeroSample) == 0) {
              const ShadedPointGpu pt = points[chunk_point[k]];
              s.rgb += vec3(pt.rx, pt.ry, pt.rz);
            }
            s.w += 1.0;
            samples[base + t] = s;
          }
        }
      }
  barrier();
  if (lane == 0u) {
    atomicAdd(accepted, chunk_accepted);
    atomicAdd(rejected, chunk_rejected);
  }
}
