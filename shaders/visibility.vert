#version 460
// The visibility pass's vertices: pulled from GpuRtScene's triangle buffer
// (three a triangle, in leaf order; no vertex buffers), placed by their
// instance's transform and projected by the camera of render::CameraRays,
// whose film point (x, y) + sample lands on pixel (x, y)'s centre. Depth is
// reversed with an infinite far plane (near / distance), so that a float
// depth buffer keeps its precision from the near plane to the horizon.
#extension GL_GOOGLE_include_directive : require
#define RT_SET 0
#define RT_BINDING 0
#include "rt_traversal.glsl"
#include "visibility_shared.h"

layout(push_constant) uniform PushBlock { VisibilityPushGpu p; };
layout(location = 0) flat out uint out_triangle;  // leaf index in the triangle buffer
layout(location = 1) flat out uint out_instance;  // InstanceGpu index

void main() {
  const uint triangle = uint(gl_VertexIndex) / 3u, corner = uint(gl_VertexIndex) % 3u;
  const TriangleGpu t = rt_triangles[triangle];
  const vec3 object = corner == 0u ? vec3(t.p0_x, t.p0_y, t.p0_z) : corner == 1u ? vec3(t.p1_x, t.p1_y, t.p1_z)
                                                                                 : vec3(t.p2_x, t.p2_y, t.p2_z);
  const InstanceGpu I = rt_instances[gl_InstanceIndex];
  // The rows map world to object: x_o = M x_w + m, so x_w = M^-1 (x_o - m).
  const mat3 to_object = transpose(mat3(I.r0_x, I.r0_y, I.r0_z, I.r1_x, I.r1_y, I.r1_z, I.r2_x, I.r2_y, I.r2_z));
  const vec3 world = inverse(to_object) * (object - vec3(I.r0_w, I.r1_w, I.r2_w));
  const vec3 rel = world - vec3(p.origin_x, p.origin_y, p.origin_z);
  // Camera space: the rotation's columns are the camera's axes.
  const vec3 cam = vec3(dot(vec3(p.c0_x, p.c0_y, p.c0_z), rel), dot(vec3(p.c1_x, p.c1_y, p.c1_z), rel),
                        dot(vec3(p.c2_x, p.c2_y, p.c2_z), rel));
  const float w = -cam.z;
  // NDC x = 2 film.x / width - 1 for the film point at the pixel's centre
  // (x + 0.5): a film offset `sample` moves the image by 0.5 - sample pixels.
  const vec2 shift = (vec2(p.sample_x, p.sample_y) - 0.5) * 2.0 / vec2(float(p.width), float(p.height));
  gl_Position = vec4(cam.x / p.tan_half_x - shift.x * w, -cam.y / p.tan_half_y - shift.y * w, p.near_plane, w);
  out_triangle = triangle;
  out_instance = uint(gl_InstanceIndex);
}
