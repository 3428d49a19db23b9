#pragma once
// What every probe technique here shares (TransGI's SH probes and the DDGI
// baseline): the ray set, and the shading of a probe ray's hit, so that the
// two differ only in how they store, filter and interpolate light.
#include <cstdint>
#include <limits>
#include <span>
#include <utility>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "engine/jobs/parallel_for.h"
#include "engine/math/rng.h"
#include "engine/render/light_set.h"
#include "engine/render/surface.h"
#include "engine/rt/ray_batch_tracer.h"
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

// The shading of one probe ray's hit, in two halves around its shadow ray,
// so that a backend can trace a frame's shadow rays in one batch
// (probe_field.cpp). shade_probe_ray below is the two halves with Embree's
// query between them.
struct PendingProbeRay {
  ProbeRayHit r;
  bool needs_shadow = false;
  engine::rt::Ray shadow;           // the next-event sample's shadow ray
  glm::vec3 unoccluded{0.0f};       // what that sample adds if the shadow ray is clear
  bool takes_feedback = false;      // a lit-side hit of a non-emitter: gets the bounce
  glm::vec3 reflectance_over_pi{0.0f};  // what the feedback's irradiance is reflected by, over pi
  glm::vec3 shading_normal{0.0f};
  glm::vec3 to_probe{0.0f};         // -dir
};

// Which lobes of the hit's BRDF reflect its next-event sample: all of them
// (the probes), or the diffuse lobe only (the near field, whose few rays a
// frame, spread by its filter, made a sun glint on a metal a bright box).
enum class HitLobes { All, Diffuse };

// Everything up to the shadow ray: the surface, its emission, and one
// next-event-estimation sample (MIS-free: delta and area lights alike are
// sampled, never hit), reflected by all lobes as if the surface were at
// least gpu::kProbeHitMinRoughness rough, with its own directional albedo
// (probe_shading_shared.h says why).
// `traced` null: the ray escaped.
PendingProbeRay begin_probe_ray(const engine::rt::RtScene& scene, const engine::render::LightSet& lights,
                                const glm::vec3& dir, const engine::rt::Hit* traced, engine::math::Pcg32& rng,
                                HitLobes lobes = HitLobes::All);

// The rest, given whether the shadow ray was blocked: the sample's light if
// not, plus the directional albedo / pi (material::directional_albedo: the
// specular layer and metals reflect the room's light too; the diffuse
// albedo for HitLobes::Diffuse) times `feedback(position, normal,
// to_probe)`, the previous frame's irradiance.
template <class Feedback>
ProbeRayHit finish_probe_ray(const PendingProbeRay& p, bool blocked, Feedback&& feedback) {
  ProbeRayHit r = p.r;
  if (!p.takes_feedback) return r;
  if (p.needs_shadow && !blocked) {
    r.radiance += p.unoccluded;
    r.saw_light = true;
  }
  r.radiance += p.reflectance_over_pi * feedback(r.position, p.shading_normal, p.to_probe);
  if (!std::isfinite(r.radiance.r + r.radiance.g + r.radiance.b)) {
    r.radiance = glm::vec3(0.0f);
    r.replaced_non_finite = true;
  }
  return r;
}

// Shades one traced probe ray (`traced` null: it escaped). Emitter hits and
// escaped rays carry zero radiance: the probes hold indirect light, direct
// light is added at the pixel; what they saw is in `emitted`.
template <class Feedback>
ProbeRayHit shade_probe_ray(const engine::rt::RtScene& scene, const engine::render::LightSet& lights, const glm::vec3& dir,
                            const engine::rt::Hit* traced, engine::math::Pcg32& rng, Feedback&& feedback,
                            HitLobes lobes = HitLobes::All) {
  const PendingProbeRay p = begin_probe_ray(scene, lights, dir, traced, rng, lobes);
  const bool blocked = p.needs_shadow && scene.occluded(p.shadow);
  return finish_probe_ray(p, blocked, std::forward<Feedback>(feedback));
}

// Traces and shades one probe ray.
template <class Feedback>
ProbeRayHit trace_probe_ray(const engine::rt::RtScene& scene, const engine::render::LightSet& lights, const glm::vec3& origin,
                            const glm::vec3& dir, engine::math::Pcg32& rng, Feedback&& feedback) {
  engine::rt::Hit hit;
  const bool found = scene.intersect(engine::rt::Ray{origin, dir}, hit);
  return shade_probe_ray(scene, lights, dir, found ? &hit : nullptr, rng, std::forward<Feedback>(feedback));
}

// A batch of probe rays traced by `tracer`: their closest hits in one call,
// each hit's first half of the shading, the shadow rays in a second call,
// then the rest. rng_of(k) is ray k's generator.
template <class RngOf, class Feedback>
void shade_probe_rays_batched(const engine::rt::RtScene& scene, const engine::render::LightSet& lights,
                              engine::rt::RayBatchTracer& tracer, std::span<const engine::rt::Ray> rays, RngOf&& rng_of,
                              Feedback&& feedback, std::vector<ProbeRayHit>& out) {
  using namespace engine;
  std::vector<rt::Hit> hits(rays.size());
  std::vector<std::uint8_t> found(rays.size());
  tracer.intersect(scene, rays, hits, found);
  std::vector<PendingProbeRay> pending(rays.size());
  jobs::parallel_for<std::size_t>(0, rays.size(), 64, [&](std::size_t b, std::size_t e) {
    for (std::size_t k = b; k < e; ++k) {
      math::Pcg32 rng = rng_of(k);
      pending[k] = begin_probe_ray(scene, lights, rays[k].direction, found[k] ? &hits[k] : nullptr, rng);
    }
  });
  std::vector<rt::Ray> shadows;
  std::vector<std::size_t> shadow_of;
  for (std::size_t k = 0; k < pending.size(); ++k)
    if (pending[k].needs_shadow) {
      shadows.push_back(pending[k].shadow);
      shadow_of.push_back(k);
    }
  std::vector<std::uint8_t> blocked(shadows.size());
  tracer.occluded(scene, shadows, blocked);
  std::vector<std::uint8_t> blocked_at(pending.size(), 0);
  for (std::size_t j = 0; j < shadows.size(); ++j) blocked_at[shadow_of[j]] = blocked[j];
  out.resize(pending.size());
  jobs::parallel_for<std::size_t>(0, pending.size(), 256, [&](std::size_t b, std::size_t e) {
    for (std::size_t k = b; k < e; ++k) out[k] = finish_probe_ray(pending[k], blocked_at[k] != 0, feedback);
  });
}


// Every listed probe's rays, traced and shaded, handed to consume(q, i, hit)
// for ray i of probe q, which leaves origin_of(q) along directions[i] with
// generator rng_of(q, i). One probe's rays are consumed in order, on one
// thread, so consume may write that probe's data without locks. With
// `tracer` (a backend's, e.g. the GPU's) the rays and then their shadow
// rays go to it in two batches; without one Embree traces them ray by ray
// and each is consumed as it is shaded.
// A ray's result is trace_probe_ray's for the same hit either way. TransGI's
// probe field and the DDGI baseline both trace through here.
template <class OriginOf, class RngOf, class Feedback, class Consume>
void trace_probe_rays(const engine::rt::RtScene& scene, const engine::render::LightSet& lights,
                      engine::rt::RayBatchTracer* tracer, std::span<const int> probes, std::span<const glm::vec3> directions,
                      OriginOf&& origin_of, RngOf&& rng_of, Feedback&& feedback, Consume&& consume) {
  const std::size_t m = directions.size();
  const int n = static_cast<int>(probes.size());
  if (tracer) {
    std::vector<engine::rt::Ray> rays;
    rays.reserve(probes.size() * m);
    for (const int q : probes)
      for (const glm::vec3& d : directions) rays.push_back(engine::rt::Ray{origin_of(q), d});
    const auto rng_of_ray = [&](std::size_t k) { return rng_of(probes[k / m], static_cast<int>(k % m)); };
    std::vector<ProbeRayHit> shaded;
    shade_probe_rays_batched(scene, lights, *tracer, rays, rng_of_ray, feedback, shaded);
    engine::jobs::parallel_for(0, n, 1, [&](int b, int e) {
      for (int j = b; j < e; ++j)
        for (std::size_t i = 0; i < m; ++i)
          consume(probes[static_cast<std::size_t>(j)], static_cast<int>(i), shaded[static_cast<std::size_t>(j) * m + i]);
    });
    return;
  }
  engine::jobs::parallel_for(0, n, 1, [&](int b, int e) {
    for (int j = b; j < e; ++j) {
      const int q = probes[static_cast<std::size_t>(j)];
      const glm::vec3 origin = origin_of(q);
      for (std::size_t i = 0; i < m; ++i) {
        engine::math::Pcg32 rng = rng_of(q, static_cast<int>(i));
        consume(q, static_cast<int>(i), trace_probe_ray(scene, lights, origin, directions[i], rng, feedback));
      }
    }
  });
}

// The backends' form of trace_probe_rays, on Embree: the rays of probes
// origins[j] (index probe_ids[j]) along each of `directions`, ray i of probe q
// drawing from make_rng(seed, q * 4096 + i, sample), handed to
// consume(j, i, hit) by the list's position j (one probe's rays in order,
// on one thread).
template <class Feedback, class Consume>
void trace_listed_probe_rays(const engine::rt::RtScene& scene, const engine::render::LightSet& lights,
                             std::span<const glm::vec3> origins, std::span<const int> probe_ids,
                             std::span<const glm::vec3> directions, std::uint64_t seed, std::uint64_t sample,
                             Feedback&& feedback, Consume&& consume) {
  std::vector<int> slots(origins.size());
  for (std::size_t j = 0; j < slots.size(); ++j) slots[j] = static_cast<int>(j);
  trace_probe_rays(
      scene, lights, nullptr, slots, directions, [&](int j) { return origins[static_cast<std::size_t>(j)]; },
      [&](int j, int i) {
        return engine::math::make_rng(
            seed, static_cast<std::uint64_t>(probe_ids[static_cast<std::size_t>(j)]) * 4096 + static_cast<std::uint64_t>(i), sample);
      },
      std::forward<Feedback>(feedback), std::forward<Consume>(consume));
}

}  // namespace transgi::probes
