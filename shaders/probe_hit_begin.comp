#version 460
// The first half of a probe ray's shading (probes::begin_probe_ray) for a
// batch of traced rays: the surface, its emission, and one next-event
// sample with its shadow ray. The light sample draws the CPU's random
// numbers (make_rng(seed, item, sample), then u_select, u.x, u.y).
#extension GL_GOOGLE_include_directive : require
#include "probe_shading_shared.h"
#include "rt_shared.h"
#include "pcg32.glsl"
#define SHADING_SET 0
#define SHADING_BINDING 5
#include "scene_shading.glsl"
#include "brdf.glsl"
#include "light_sampling.glsl"

layout(local_size_x = kProbeShadingGroupSize) in;
layout(std430, set = 0, binding = 0) readonly buffer Rays { RayGpu rays[]; };
layout(std430, set = 0, binding = 1) readonly buffer Hits { HitGpu hits[]; };
layout(std430, set = 0, binding = 2) readonly buffer Items { uint items[]; };  // per ray, its generator's item (lo, hi)
layout(std430, set = 0, binding = 3) writeonly buffer Pending { PendingProbeRayGpu pending[]; };
layout(std430, set = 0, binding = 4) writeonly buffer Shadows { RayGpu shadows[]; };
layout(push_constant) uniform PushBlock { ProbeHitPush p; };

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= p.count) return;
  const RayGpu ray = rays[i];
  const vec3 dir = vec3(ray.dir_x, ray.dir_y, ray.dir_z);
  const HitGpu hit = hits[i];
  PendingProbeRayGpu o;
  o.px = o.py = o.pz = 0.0;
  o.distance = shading_infinity();
  o.nx = o.ny = o.nz = 0.0;
  o.flags = 0u;
  o.er = o.eg = o.eb = o.pad0 = 0.0;
  o.ur = o.ug = o.ub = o.pad1 = 0.0;
  o.ar = o.ag = o.ab = o.pad2 = 0.0;
  o.sx = o.sy = o.sz = o.pad3 = 0.0;
  RayGpu shadow = RayGpu(0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0);  // tmin > tmax: no shadow ray

  if (hit.instance == kRtNoHit) {
    vec3 e = environment_radiance(dir);
    if (!finite3(e)) {
      e = vec3(0.0);
      o.flags |= kProbeRayReplacedNonFinite;
    }
    o.er = e.r;
    o.eg = e.g;
    o.eb = e.b;
    o.flags |= kProbeRaySawLight;
    pending[i] = o;
    shadows[i] = shadow;
    return;
  }
  const Surface s = make_surface(hit.instance, hit.mesh, hit.primitive, hit.u, hit.v, dir);
  vec3 e = s.emission;
  if (!finite3(e)) {
    e = vec3(0.0);
    o.flags |= kProbeRayReplacedNonFinite;
  }
  o.er = e.r;
  o.eg = e.g;
  o.eb = e.b;
  o.flags |= kProbeRayHit;
  if (s.back_face) o.flags |= kProbeRayBackFace;
  o.distance = hit.t;
  o.px = s.position.x;
  o.py = s.position.y;
  o.pz = s.position.z;
  o.nx = s.geometric_normal.x;
  o.ny = s.geometric_normal.y;
  o.nz = s.geometric_normal.z;
  const bool emitter = s.emission.r > 0.0 || s.emission.g > 0.0 || s.emission.b > 0.0;
  if (emitter) o.flags |= kProbeRaySawLight;
  const vec3 wo = to_local(s.frame, -dir);
  if (!emitter && wo.z > 0.0) {
    o.flags |= kProbeRayTakesFeedback;
    // probe_rays.cpp's begin_probe_ray: the feedback is reflected by every lobe.
    const vec3 own = directional_albedo(s.brdf, wo.z);
    const vec3 albedo = own * kShadingInvPi;
    // begin_probe_ray's blurred lobe, scaled to the surface's own albedo.
    Brdf blurred = s.brdf;
    vec3 energy = vec3(1.0);
    if (blurred.roughness < kProbeHitMinRoughness) {
      blurred.roughness = kProbeHitMinRoughness;
      const vec3 rough = directional_albedo(blurred, wo.z);
      for (int k = 0; k < 3; ++k) energy[k] = rough[k] > 0.0 ? own[k] / rough[k] : 0.0;
    }
    o.ar = albedo.r;
    o.ag = albedo.g;
    o.ab = albedo.b;
    o.sx = s.shading_normal.x;
    o.sy = s.shading_normal.y;
    o.sz = s.shading_normal.z;
    Pcg32 rng = make_rng(u64_of(p.seed_lo, p.seed_hi), u64_of(items[2u * i], items[2u * i + 1u]), u64_of(p.sample_lo, p.sample_hi));
    const float u_sel = pcg32_next_float(rng);
    const float ux = pcg32_next_float(rng);
    const float uy = pcg32_next_float(rng);
    LightSample ls;
    if (sample_light(s.position, u_sel, vec2(ux, uy), ls) && dot(ls.direction, s.geometric_normal) > 0.0) {
      const vec3 wi = to_local(s.frame, ls.direction);
      const vec3 f = wi.z > 0.0 ? brdf_eval(blurred, wo, wi) * energy : vec3(0.0);
      if (f != vec3(0.0)) {
        const vec3 origin = offset_ray_origin(s.position, s.geometric_normal, p.offset_scale);
        const float tmax = isinf(ls.distance) ? shading_infinity() : ls.distance * (1.0 - 1e-4);
        shadow = RayGpu(origin.x, origin.y, origin.z, 0.0, ls.direction.x, ls.direction.y, ls.direction.z, tmax);
        o.flags |= kProbeRayNeedsShadow;
        const vec3 unoccluded = f * wi.z * ls.radiance / (ls.delta ? 1.0 : ls.pdf);
        o.ur = unoccluded.r;
        o.ug = unoccluded.g;
        o.ub = unoccluded.b;
      }
    }
  }
  pending[i] = o;
  shadows[i] = shadow;
}
