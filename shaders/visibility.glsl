// What the visibility pass's stages share: the camera ray of a film point
// (render::CameraRays::generate) and an instance's world-to-object rows.
// Include after rt_traversal.glsl (BVH variant) and a push block `p` of
// VisibilityPushGpu.

vec3 visibility_ray_direction(vec2 film) {
  const float sx = (2.0 * film.x / float(p.width) - 1.0) * p.tan_half_x;
  const float sy = (1.0 - 2.0 * film.y / float(p.height)) * p.tan_half_y;
  return normalize(vec3(p.c0_x, p.c0_y, p.c0_z) * sx + vec3(p.c1_x, p.c1_y, p.c1_z) * sy - vec3(p.c2_x, p.c2_y, p.c2_z));
}

// The film point a fragment or a resolved pixel stands for.
vec2 visibility_film(uvec2 pixel) { return vec2(pixel) + vec2(p.sample_x, p.sample_y); }

// World to object space (InstanceGpu's rows: a similarity, so t is kept).
void visibility_to_object(InstanceGpu I, vec3 wo, vec3 wd, out vec3 o, out vec3 d) {
  const vec4 r0 = vec4(I.r0_x, I.r0_y, I.r0_z, I.r0_w), r1 = vec4(I.r1_x, I.r1_y, I.r1_z, I.r1_w),
             r2 = vec4(I.r2_x, I.r2_y, I.r2_z, I.r2_w);
  o = vec3(dot(r0, vec4(wo, 1.0)), dot(r1, vec4(wo, 1.0)), dot(r2, vec4(wo, 1.0)));
  d = vec3(dot(r0.xyz, wd), dot(r1.xyz, wd), dot(r2.xyz, wd));
}

// The ray's intersection with the triangle's plane, as rt_triangle computes
// it (Moeller-Trumbore) but without its bounds: the rasteriser decided
// coverage. The barycentrics are clamped into the triangle, since a pixel
// the raster rules give to a triangle can lie a rounding error outside it.
vec3 visibility_barycentrics(TriangleGpu tri, vec3 o, vec3 d) {
  const vec3 p0 = vec3(tri.p0_x, tri.p0_y, tri.p0_z);
  const vec3 e1 = vec3(tri.p1_x, tri.p1_y, tri.p1_z) - p0;
  const vec3 e2 = vec3(tri.p2_x, tri.p2_y, tri.p2_z) - p0;
  const vec3 pv = cross(d, e2);
  const float det = dot(e1, pv);
  const float inv_det = det != 0.0 ? 1.0 / det : 0.0;
  const vec3 tv = o - p0;
  const float bu = clamp(dot(tv, pv) * inv_det, 0.0, 1.0);
  const vec3 qv = cross(tv, e1);
  const float bv = clamp(dot(d, qv) * inv_det, 0.0, 1.0 - bu);
  const float t = dot(e2, qv) * inv_det;
  return vec3(bu, bv, max(t, 0.0));
}
