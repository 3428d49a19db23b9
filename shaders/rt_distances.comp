#version 460
// rt_query.comp's queries with only the distance coming back: each ray's
// closest (or, with any_hit, first) hit distance, +infinity where it hits
// nothing up to tmax. What GpuRtScene's queued batches run (shadow rays,
// the open-space search's segments): 4 bytes a ray back instead of 32.
#extension GL_GOOGLE_include_directive : require
#define RT_SET 0
#define RT_BINDING 2
#include "rt_traversal.glsl"

layout(local_size_x = kRtGroupSize) in;
layout(std430, set = 0, binding = 0) readonly buffer Rays { RayGpu rays[]; };
layout(std430, set = 0, binding = 1) writeonly buffer Distances { float distances[]; };
layout(push_constant) uniform PushBlock { uint count; uint any_hit; } push;

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= push.count) return;
  const RayGpu r = rays[i];
  const HitGpu hit = rt_intersect(vec3(r.origin_x, r.origin_y, r.origin_z), vec3(r.dir_x, r.dir_y, r.dir_z), r.tmin, r.tmax,
                                  push.any_hit != 0u);
  distances[i] = hit.instance != kRtNoHit ? hit.t : uintBitsToFloat(0x7f800000u);
}
