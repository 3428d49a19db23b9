#version 460
// Closest-hit queries for a batch of rays through rt_traversal.glsl: what
// GpuRtScene::intersect runs, and what the tests compare with Embree.
#extension GL_GOOGLE_include_directive : require
#define RT_SET 0
#define RT_BINDING 2
#include "rt_traversal.glsl"

layout(local_size_x = kRtGroupSize) in;
layout(std430, set = 0, binding = 0) readonly buffer Rays { RayGpu rays[]; };
layout(std430, set = 0, binding = 1) writeonly buffer Hits { HitGpu hits[]; };
layout(push_constant) uniform PushBlock { uint count; uint any_hit; } push;

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= push.count) return;
  const RayGpu r = rays[i];
  hits[i] = rt_intersect(vec3(r.origin_x, r.origin_y, r.origin_z), vec3(r.dir_x, r.dir_y, r.dir_z), r.tmin, r.tmax, push.any_hit != 0u);
}
