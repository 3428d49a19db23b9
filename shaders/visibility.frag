#version 460
// The visibility pass's fragments: which instance and triangle cover the
// pixel (instance + 1; 0 is the clear value, nothing). A cut-out
// triangle's fragment is tested as RtScene tests a ray's hit
// (rt_alpha_passes at the pixel ray's barycentrics) and discarded where
// the ray would pass.
#extension GL_GOOGLE_include_directive : require
#define RT_SET 0
#define RT_BINDING 0
#include "rt_traversal.glsl"
#include "visibility_shared.h"

layout(push_constant) uniform PushBlock { VisibilityPushGpu p; };
#include "visibility.glsl"

layout(location = 0) flat in uint in_triangle;
layout(location = 1) flat in uint in_instance;
layout(location = 0) out uvec2 out_visibility;

void main() {
  const TriangleGpu t = rt_triangles[in_triangle];
  if (t.alpha_material != kRtOpaque) {
    vec3 o, d;
    visibility_to_object(rt_instances[in_instance], vec3(p.origin_x, p.origin_y, p.origin_z),
                         visibility_ray_direction(visibility_film(uvec2(gl_FragCoord.xy))), o, d);
    const vec3 b = visibility_barycentrics(t, o, d);
    if (!rt_alpha_passes(t, in_triangle, b.x, b.y)) discard;
  }
  out_visibility = uvec2(in_instance + 1u, in_triangle);
}
