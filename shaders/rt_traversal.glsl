// Closest-hit queries, rt_intersect(), in one of two ways, which give the
// same hits (tests/gpu/rt_traversal_test.cpp runs both against Embree):
// - with RT_RAY_QUERY defined (GpuRtScene::shader_defines, where the device
//   has VK_KHR_ray_query): the driver's acceleration structure, traversed by
//   rayQueryEXT, on RT cores where the GPU has them;
// - otherwise (lavapipe 22.3, GPUs without ray queries): a two-level BVH
//   (rt_shared.h) traversed here in a loop.
// The includer defines RT_SET and RT_BINDING (the first of eight consecutive
// bindings: the TLAS (nodes, or the acceleration structure), instances, BLAS
// nodes (unused with ray queries), triangles, then the alpha test's triangle
// UVs, materials, texel bytes and textures) before including this file.
//
// Arithmetic follows Embree's conventions, not its exact floating point:
// t in (tmin, tmax], hits from both sides, barycentrics (u, v) such that the
// point is (1 - u - v) p0 + u p1 + v p2; alpha-masked triangles are cut out
// where their texture says, as Embree's filter does.
#include "rt_shared.h"

#ifdef RT_RAY_QUERY
#extension GL_EXT_ray_query : require
layout(set = RT_SET, binding = RT_BINDING) uniform accelerationStructureEXT rt_tlas_structure;
#else
layout(std430, set = RT_SET, binding = RT_BINDING) readonly buffer RtTlas { BvhNodeGpu rt_tlas[]; };
layout(std430, set = RT_SET, binding = RT_BINDING + 2) readonly buffer RtBlas { BvhNodeGpu rt_blas[]; };
#endif
layout(std430, set = RT_SET, binding = RT_BINDING + 1) readonly buffer RtInstances { InstanceGpu rt_instances[]; };
layout(std430, set = RT_SET, binding = RT_BINDING + 3) readonly buffer RtTriangles { TriangleGpu rt_triangles[]; };
layout(std430, set = RT_SET, binding = RT_BINDING + 4) readonly buffer RtTriangleUvs { RtTriangleUvGpu rt_triangle_uvs[]; };
layout(std430, set = RT_SET, binding = RT_BINDING + 5) readonly buffer RtAlphaMaterials { RtAlphaMaterialGpu rt_alpha_materials[]; };
layout(std430, set = RT_SET, binding = RT_BINDING + 6) readonly buffer RtAlphaBytes { uint rt_alpha_bytes[]; };
layout(std430, set = RT_SET, binding = RT_BINDING + 7) readonly buffer RtAlphaTextures { RtAlphaTextureGpu rt_alpha_textures[]; };

#include "texture_wrap.glsl"

// RtScene's alpha_passes for triangle `index` (in leaf order) at (u, v).
bool rt_alpha_passes(TriangleGpu tri, uint index, float u, float v) {
  const RtAlphaMaterialGpu m = rt_alpha_materials[tri.alpha_material];
  float alpha = m.alpha;
  const RtTriangleUvGpu t = rt_triangle_uvs[index];
  if (m.texture >= 0 && t.has_uv != 0u) {
    const vec2 uv = (1.0 - u - v) * vec2(t.u0, t.v0) + u * vec2(t.u1, t.v1) + v * vec2(t.u2, t.v2);
    const RtAlphaTextureGpu tex = rt_alpha_textures[m.texture];
    if (!isnan(uv.x) && !isinf(uv.x) && !isnan(uv.y) && !isinf(uv.y)) {
      const vec2 r = uv - 4096.0 * trunc(uv / 4096.0);  // std::fmod
      const int x = texture_wrap(int(floor(r.x * float(tex.width))), tex.width, tex.wrap & 0xffu);
      const int y = texture_wrap(int(floor(r.y * float(tex.height))), tex.height, tex.wrap >> 8);
      const uint byte_index = tex.offset + uint(y * tex.width + x);
      alpha *= float((rt_alpha_bytes[byte_index >> 2] >> ((byte_index & 3u) * 8u)) & 0xffu) / 255.0;
    }
  }
  return alpha >= m.cutoff;
}

// What rt_intersect returns for a ray that hits nothing up to tmax.
HitGpu rt_no_hit(float tmax) {
  HitGpu hit;
  hit.t = tmax;
  hit.u = 0.0;
  hit.v = 0.0;
  hit.instance = kRtNoHit;
  hit.primitive = 0u;
  hit.mesh = 0u;
  hit.pad0 = 0u;
  hit.pad1 = 0u;
  return hit;
}

#ifndef RT_RAY_QUERY
// 1 / d without infinities that would make 0 * inf = NaN in the slab test.
vec3 rt_safe_inverse(vec3 d) {
  const float tiny = 1e-30;
  return vec3(1.0) / vec3(abs(d.x) > tiny ? d.x : (d.x < 0.0 ? -tiny : tiny),
                          abs(d.y) > tiny ? d.y : (d.y < 0.0 ? -tiny : tiny),
                          abs(d.z) > tiny ? d.z : (d.z < 0.0 ? -tiny : tiny));
}

// Entry distance into the node's box, or +inf when the ray misses it
// within [tmin, tmax].
float rt_enter(BvhNodeGpu n, vec3 o, vec3 inv_d, float tmin, float tmax) {
  const vec3 t0 = (vec3(n.min_x, n.min_y, n.min_z) - o) * inv_d;
  const vec3 t1 = (vec3(n.max_x, n.max_y, n.max_z) - o) * inv_d;
  const vec3 lo = min(t0, t1), hi = max(t0, t1);
  const float enter = max(max(lo.x, lo.y), max(lo.z, tmin));
  const float leave = min(min(hi.x, hi.y), min(hi.z, tmax));
  // The 1 + 2^-22 widening keeps rays grazing a box face from slipping past
  // it through rounding (Ize 2013, "Robust BVH ray traversal").
  return enter <= leave * 1.00000024 ? enter : uintBitsToFloat(0x7f800000u);
}

// Which children of an interior node the ray enters (their entry distances
// ta, tb; +inf = missed): 0, 1 (`next`) or 2 (the nearer as `next`, the
// other as `later`, to wait on the stack).
uint rt_children(float ta, float tb, uint a, uint b, inout uint next, out uint later) {
  const bool hit_a = !isinf(ta), hit_b = !isinf(tb);
  const uint visit = uint(hit_a) + uint(hit_b);
  if (visit > 0u) next = hit_a && (!hit_b || ta <= tb) ? a : b;
  later = next == a ? b : a;
  return visit;
}

// Moeller-Trumbore; updates t, u, v and returns true for a closer hit.
bool rt_triangle(TriangleGpu tri, uint index, vec3 o, vec3 d, float tmin, inout float t, inout float u, inout float v) {
  const vec3 p0 = vec3(tri.p0_x, tri.p0_y, tri.p0_z);
  const vec3 e1 = vec3(tri.p1_x, tri.p1_y, tri.p1_z) - p0;
  const vec3 e2 = vec3(tri.p2_x, tri.p2_y, tri.p2_z) - p0;
  const vec3 pv = cross(d, e2);
  const float det = dot(e1, pv);
  if (det == 0.0) return false;
  const float inv_det = 1.0 / det;
  const vec3 tv = o - p0;
  const float bu = dot(tv, pv) * inv_det;
  if (bu < 0.0 || bu > 1.0) return false;
  const vec3 qv = cross(tv, e1);
  const float bv = dot(d, qv) * inv_det;
  if (bv < 0.0 || bu + bv > 1.0) return false;
  const float th = dot(e2, qv) * inv_det;
  if (!(th > tmin && th <= t)) return false;
  if (tri.alpha_material != kRtOpaque && !rt_alpha_passes(tri, index, bu, bv)) return false;
  t = th;
  u = bu;
  v = bv;
  return true;
}

// The BLAS of one instance, in its object space (the similarity keeps t).
// any_hit: stop at the first hit (shadow rays), not the closest.
void rt_traverse_blas(uint inst, vec3 wo, vec3 wd, float tmin, bool any_hit, inout HitGpu hit) {
  const InstanceGpu I = rt_instances[inst];
  const vec4 r0 = vec4(I.r0_x, I.r0_y, I.r0_z, I.r0_w), r1 = vec4(I.r1_x, I.r1_y, I.r1_z, I.r1_w),
             r2 = vec4(I.r2_x, I.r2_y, I.r2_z, I.r2_w);
  const vec3 o = vec3(dot(r0, vec4(wo, 1.0)), dot(r1, vec4(wo, 1.0)), dot(r2, vec4(wo, 1.0)));
  const vec3 d = vec3(dot(r0.xyz, wd), dot(r1.xyz, wd), dot(r2.xyz, wd));
  const vec3 inv_d = rt_safe_inverse(d);
  uint stack[kRtStackSize];
  uint top = 0u;
  uint node = I.blas_root;
  while (true) {
    const BvhNodeGpu n = rt_blas[node];
    if (n.count > 0u) {
      for (uint k = 0u; k < n.count; ++k) {
        const uint index = I.triangle_offset + n.first + k;
        const TriangleGpu tri = rt_triangles[index];
        if (rt_triangle(tri, index, o, d, tmin, hit.t, hit.u, hit.v)) {
          hit.instance = I.id;
          hit.primitive = tri.primitive;
          hit.mesh = I.mesh;
          if (any_hit) return;
        }
      }
    } else {
      const uint a = I.blas_root + n.first, b = a + 1u;
      uint later;
      const uint visit = rt_children(rt_enter(rt_blas[a], o, inv_d, tmin, hit.t), rt_enter(rt_blas[b], o, inv_d, tmin, hit.t),
                                     a, b, node, later);
      if (visit == 2u && top < kRtStackSize) stack[top++] = later;
      if (visit > 0u) continue;
    }
    if (top == 0u) break;
    node = stack[--top];
  }
}

// Closest hit of the ray in world space (any hit with any_hit: the answer to
// "is anything there" at less traversal); hit.instance == kRtNoHit if none.
HitGpu rt_intersect(vec3 o, vec3 d, float tmin, float tmax, bool any_hit) {
  HitGpu hit = rt_no_hit(tmax);
  const vec3 inv_d = rt_safe_inverse(d);
  if (isinf(rt_enter(rt_tlas[0], o, inv_d, tmin, hit.t))) return hit;
  uint stack[kRtStackSize];
  uint top = 0u;
  uint node = 0u;
  while (true) {
    const BvhNodeGpu n = rt_tlas[node];
    if (n.count > 0u) {
      for (uint k = 0u; k < n.count; ++k) {
        rt_traverse_blas(n.first + k, o, d, tmin, any_hit, hit);
        if (any_hit && hit.instance != kRtNoHit) return hit;
      }
    } else {
      const uint a = n.first, b = a + 1u;
      uint later;
      const uint visit = rt_children(rt_enter(rt_tlas[a], o, inv_d, tmin, hit.t), rt_enter(rt_tlas[b], o, inv_d, tmin, hit.t),
                                     a, b, node, later);
      if (visit == 2u && top < kRtStackSize) stack[top++] = later;
      if (visit > 0u) continue;
    }
    if (top == 0u) break;
    node = stack[--top];
  }
  return hit;
}
#else  // RT_RAY_QUERY

// The same contract through the driver's traversal. The BLAS keep each
// mesh's triangles in its own order (GpuRtScene), so a primitive index
// names the TriangleGpu at the instance's triangle_offset plus it, and the
// instance's custom index names its InstanceGpu.
HitGpu rt_intersect(vec3 o, vec3 d, float tmin, float tmax, bool any_hit) {
  HitGpu hit = rt_no_hit(tmax);
  // A ray query's origin, direction and interval must be finite and ordered
  // (undefined otherwise); such a ray hits nothing in the loop above either.
  if (any(isnan(o)) || any(isinf(o)) || any(isnan(d)) || any(isinf(d)) || isnan(tmin) || isnan(tmax) || !(tmin >= 0.0) ||
      !(tmax >= tmin) || d == vec3(0.0))
    return hit;
  rayQueryEXT q;
  rayQueryInitializeEXT(q, rt_tlas_structure, any_hit ? gl_RayFlagsTerminateOnFirstHitEXT : gl_RayFlagsNoneEXT, 0xffu, o, tmin,
                        d, min(tmax, 3.0e38));
  while (rayQueryProceedEXT(q)) {
    // Only alpha-masked meshes are built non-opaque: their candidates pass
    // the same cut-out test as in the loop above.
    if (rayQueryGetIntersectionTypeEXT(q, false) != gl_RayQueryCandidateIntersectionTriangleEXT) continue;
    const uint inst = rayQueryGetIntersectionInstanceCustomIndexEXT(q, false);
    const uint index = rt_instances[inst].triangle_offset + uint(rayQueryGetIntersectionPrimitiveIndexEXT(q, false));
    const TriangleGpu tri = rt_triangles[index];
    const vec2 uv = rayQueryGetIntersectionBarycentricsEXT(q, false);
    if (tri.alpha_material == kRtOpaque || rt_alpha_passes(tri, index, uv.x, uv.y)) rayQueryConfirmIntersectionEXT(q);
  }
  if (rayQueryGetIntersectionTypeEXT(q, true) != gl_RayQueryCommittedIntersectionTriangleEXT) return hit;
  const InstanceGpu I = rt_instances[rayQueryGetIntersectionInstanceCustomIndexEXT(q, true)];
  const uint index = I.triangle_offset + uint(rayQueryGetIntersectionPrimitiveIndexEXT(q, true));
  const vec2 uv = rayQueryGetIntersectionBarycentricsEXT(q, true);
  hit.t = rayQueryGetIntersectionTEXT(q, true);
  hit.u = uv.x;
  hit.v = uv.y;
  hit.instance = I.id;
  hit.primitive = rt_triangles[index].primitive;
  hit.mesh = I.mesh;
  return hit;
}
#endif  // RT_RAY_QUERY
