#version 460
// The visibility buffer turned into the hits rt_query.comp gives for the
// same camera rays (t, barycentrics, instance id, primitive), as
// VisibilityHitGpu: each pixel's ray meets the triangle the raster found
// there.
#extension GL_GOOGLE_include_directive : require
#define RT_SET 0
#define RT_BINDING 2
#include "rt_traversal.glsl"
#include "visibility_shared.h"

layout(local_size_x = kVisibilityGroupSize) in;
layout(std430, set = 0, binding = 0) readonly buffer Visibility { uvec2 visibility[]; };
layout(std430, set = 0, binding = 1) writeonly buffer Hits { VisibilityHitGpu hits[]; };
layout(push_constant) uniform PushBlock { VisibilityPushGpu p; };
#include "visibility.glsl"

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= p.width * p.height) return;
  const uvec2 v = visibility[i];
  if (v.x == 0u) {
    hits[i] = VisibilityHitGpu(uintBitsToFloat(0x7f800000u), 0.0, 0.0, kRtNoHit, 0u);  // t = +inf, as a missed ray's
    return;
  }
  const InstanceGpu I = rt_instances[v.x - 1u];
  const TriangleGpu t = rt_triangles[v.y];
  vec3 o, d;
  visibility_to_object(I, vec3(p.origin_x, p.origin_y, p.origin_z), visibility_ray_direction(visibility_film(uvec2(i % p.width, i / p.width))), o, d);
  const vec3 b = visibility_barycentrics(t, o, d);
  hits[i] = VisibilityHitGpu(b.z, b.x, b.y, I.id, t.primitive);
}
