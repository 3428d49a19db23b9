#pragma once
// What every probe technique here shares (TransGI's SH probes and the DDGI
// baseline): the ray set, and the shading of a probe ray's hit, so that the
// two differ only in how they store, filter and interpolate light.
#include <limits>
#include <utility>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "engine/math/rng.h"
#include "engine/render/light_set.h"
#include "engine/render/surface.h"
#include "engine/rt/rt_scene.h"

namespace transgi::probes {

// n directions on a spherical Fibonacci lattice (the set RTXGI uses).
std::vector<glm::vec3> spherical_fibonacci(int n);
// A uniformly random rotation (Shoemake 1992), new every frame.
glm::quat random_rotation(engine::math::Pcg32& rng);
// The index-th rotation of a Halton (2, 3, 5) sequence through Shoemake's
// map: rotations that cover SO(3) evenly frame after frame, with no seed.
glm::quat low_discrepancy_rotation(std::uint64_t index);

struct ProbeRayHit {
  bool hit = false;
  bool back_face = false;  // hit a single-sided material from behind (Surface::back_face)
  // The ray escaped, met an emitter, or met a surface that its next-event
  // sample found directly lit: the probe is linked to light (open_space.h).
  bool saw_light = false;
  float distance = std::numeric_limits<float>::infinity();
  glm::vec3 position{0.0f};
  glm::vec3 normal{0.0f};    // geometric, facing the probe
  glm::vec3 radiance{0.0f};  // leaving the hit towards the probe
  // Light arriving straight from an emitter or the (residual) environment:
  // not part of `radiance`, which is indirect light only; the probes keep it
  // apart as the real-time path's direct sky and emitter light.
  glm::vec3 emitted{0.0f};
  // A non-finite radiance or emission (an overflowing light, a NaN material)
  // was replaced by zero here, at the probe rays' boundary; callers count it.
  bool replaced_non_finite = false;
};

// Traces one probe ray. At a hit that is not an emitter and faces the ray,
// the radiance is direct light by one next-event-estimation sample (MIS-free:
// delta and area lights alike are sampled, never hit) plus the diffuse
// albedo / pi times `feedback(position, normal)`, the previous frame's
// irradiance. Emitter hits and escaped rays carry zero: the probes hold
// indirect light, direct light is added at the pixel.
//
// shade_probe_ray does the same for a ray already traced (`hit` null: it
// escaped), so a backend can trace a frame's probe rays in one batch.
template <class Feedback>
ProbeRayHit shade_probe_ray(const engine::rt::RtScene& scene, const engine::render::LightSet& lights, const glm::vec3& dir,
                            const engine::rt::Hit* traced, engine::math::Pcg32& rng, Feedback&& feedback) {
  using namespace engine;
  ProbeRayHit r;
  if (!traced) {
    if (const scene::Environment* env = lights.environment()) r.emitted = env->radiance(dir);
    if (!std::isfinite(r.emitted.r + r.emitted.g + r.emitted.b)) {
      r.emitted = glm::vec3(0.0f);
      r.replaced_non_finite = true;
    }
    r.saw_light = true;
    return r;
  }
  const rt::Hit& hit = *traced;
  const render::Surface s = render::make_surface(scene, hit, dir);
  r.emitted = s.emission;
  if (!std::isfinite(r.emitted.r + r.emitted.g + r.emitted.b)) {
    r.emitted = glm::vec3(0.0f);
    r.replaced_non_finite = true;
  }
  r.hit = true;
  r.back_face = s.back_face;
  r.distance = hit.t;
  r.position = s.position;
  r.normal = s.geometric_normal;
  const bool emitter = s.emission.r > 0 || s.emission.g > 0 || s.emission.b > 0;
  r.saw_light = emitter;
  const glm::vec3 wo = s.frame.to_local(-dir);
  if (emitter || wo.z <= 0) return r;
  render::LightSample ls;
  const float u_sel = rng.next_float();
  const glm::vec2 u(rng.next_float(), rng.next_float());
  if (lights.sample(s.position, u_sel, u, ls) && glm::dot(ls.direction, s.geometric_normal) > 0) {
    const glm::vec3 wi = s.frame.to_local(ls.direction);
    const glm::vec3 f = wi.z > 0 ? material::brdf_eval(s.brdf, wo, wi) : glm::vec3(0.0f);
    if (f != glm::vec3(0.0f)) {
      const glm::vec3 o = rt::offset_ray_origin(s.position, s.geometric_normal, scene.offset_scale());
      const float tmax = std::isinf(ls.distance) ? std::numeric_limits<float>::infinity() : ls.distance * (1.0f - 1e-4f);
      if (!scene.occluded(rt::Ray{o, ls.direction, 0.0f, tmax})) {
        r.radiance += f * wi.z * ls.radiance / (ls.delta ? 1.0f : ls.pdf);
        r.saw_light = true;
      }
    }
  }
  r.radiance += material::diffuse_albedo(s.brdf) * math::kInvPi * feedback(s.position, s.shading_normal, -dir);
  if (!std::isfinite(r.radiance.r + r.radiance.g + r.radiance.b)) {
    r.radiance = glm::vec3(0.0f);
    r.replaced_non_finite = true;
  }
  return r;
}

template <class Feedback>
ProbeRayHit trace_probe_ray(const engine::rt::RtScene& scene, const engine::render::LightSet& lights, const glm::vec3& origin,
                            const glm::vec3& dir, engine::math::Pcg32& rng, Feedback&& feedback) {
  engine::rt::Hit hit;
  const bool found = scene.intersect(engine::rt::Ray{origin, dir}, hit);
  return shade_probe_ray(scene, lights, dir, found ? &hit : nullptr, rng, std::forward<Feedback>(feedback));
}

}  // namespace transgi::probes
