#version 460
// The view's shadow rays (engine/render/view_shadows.h, whose
// trace_view_shadows is the oracle): one invocation a pixel, after the
// visibility pass's resolve, one ray to each light from the surface the
// pixel sees, traced through rt_traversal.glsl (either traversal).
#extension GL_GOOGLE_include_directive : require
#define RT_SET 0
#define RT_BINDING 4
#include "rt_traversal.glsl"
#include "view_shadows_shared.h"
#include "ray_offset.glsl"

layout(local_size_x = kVisibilityGroupSize) in;
layout(std430, set = 0, binding = 0) readonly buffer Visibility { uvec2 visibility[]; };
layout(std430, set = 0, binding = 1) readonly buffer Hits { VisibilityHitGpu hits[]; };
layout(std430, set = 0, binding = 2) readonly buffer Lights { ViewShadowLightGpu lights[]; };
layout(std430, set = 0, binding = 3) writeonly buffer Answers { float answers[]; };
layout(push_constant) uniform PushBlock {
  VisibilityPushGpu p;
  ViewShadowPushGpu s;
};
#include "visibility.glsl"

const float kSlack = 1e-3;  // render::kViewShadowSlack

void main() {
  const uint i = gl_GlobalInvocationID.x;
  const uint pixels = p.width * p.height;
  if (i >= pixels) return;
  const float not_traced = uintBitsToFloat(0x7fc00000u), infinity = uintBitsToFloat(0x7f800000u);
  for (uint l = 0u; l < s.lights; ++l) answers[l * pixels + i] = not_traced;
  const uvec2 v = visibility[i];
  if (v.x == 0u) return;
  const InstanceGpu I = rt_instances[v.x - 1u];
  const TriangleGpu t = rt_triangles[v.y];
  const uvec2 pixel = uvec2(i % p.width, i / p.width);
  const vec3 dir = visibility_ray_direction(visibility_film(pixel));
  const vec3 position = vec3(p.origin_x, p.origin_y, p.origin_z) + hits[i].t * dir;
  const vec3 p0 = vec3(t.p0_x, t.p0_y, t.p0_z);
  const vec3 n_object = cross(vec3(t.p1_x, t.p1_y, t.p1_z) - p0, vec3(t.p2_x, t.p2_y, t.p2_z) - p0);
  // The instance's rows map world to object space (a rotation over the
  // scale): their transpose turns an object-space normal to world space.
  vec3 ng = vec3(I.r0_x, I.r0_y, I.r0_z) * n_object.x + vec3(I.r1_x, I.r1_y, I.r1_z) * n_object.y +
            vec3(I.r2_x, I.r2_y, I.r2_z) * n_object.z;
  const float length_ng = length(ng);
  if (!(length_ng > 0.0)) return;
  ng /= length_ng;
  if (dot(ng, dir) > 0.0) ng = -ng;
  const vec3 origin = offset_ray_origin(position, ng, s.offset_scale);
  const uint cell = uint(((int(pixel.x) + s.shift_x) & 7) | (((int(pixel.y) + s.shift_y) & 7) << 3));
  for (uint l = 0u; l < s.lights; ++l) {
    const uint flags = lights[l].flags;
    vec3 d;
    float tmax = infinity;
    if ((flags & kViewShadowDirectional) != 0u) {
      d = vec3(lights[l].directions[4u * cell], lights[l].directions[4u * cell + 1u], lights[l].directions[4u * cell + 2u]);
    } else {
      d = vec3(lights[l].position_x, lights[l].position_y, lights[l].position_z) - position;
      const float distance = length(d);
      if (!(distance > 0.0)) continue;
      d /= distance;
      tmax = distance * (1.0 - 1e-4);
    }
    if (!(dot(d, ng) > -kSlack)) continue;
    const bool nearest = (flags & kViewShadowNearest) != 0u;
    const HitGpu h = rt_intersect(origin, d, 0.0, tmax, !nearest);
    answers[l * pixels + i] = h.instance == kRtNoHit ? infinity : (nearest ? h.t : 0.0);
  }
}
