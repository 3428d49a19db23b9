#include "probes/probe_rays.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "engine/math/sampling.h"
#include "probe_shading_shared.h"

namespace transgi::probes {

std::vector<glm::vec3> spherical_fibonacci(int n) {
  std::vector<glm::vec3> d(static_cast<std::size_t>(n));
  const float golden = 0.5f * (1.0f + std::sqrt(5.0f));
  for (int i = 0; i < n; ++i) {
    const float z = 1.0f - (2.0f * static_cast<float>(i) + 1.0f) / static_cast<float>(n);
    const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
    const float phi = engine::math::kTwoPi * std::fmod(static_cast<float>(i) / golden, 1.0f);
    d[static_cast<std::size_t>(i)] = {r * std::cos(phi), r * std::sin(phi), z};
  }
  return d;
}

namespace {
// Shoemake's uniform rotation from a point of the unit cube.
glm::quat rotation_from_cube(float u1, float v2, float v3) {
  const float u2 = engine::math::kTwoPi * v2, u3 = engine::math::kTwoPi * v3;
  const float a = std::sqrt(1 - u1), b = std::sqrt(u1);
  return glm::normalize(glm::quat(b * std::cos(u3), a * std::sin(u2), a * std::cos(u2), b * std::sin(u3)));
}

float radical_inverse(std::uint64_t i, std::uint64_t base) {
  double inv = 1.0 / static_cast<double>(base), f = inv, r = 0;
  for (; i > 0; i /= base, f *= inv) r += static_cast<double>(i % base) * f;
  return static_cast<float>(r);
}
}  // namespace

glm::quat random_rotation(engine::math::Pcg32& rng) {
  const float u1 = rng.next_float(), u2 = rng.next_float(), u3 = rng.next_float();
  return rotation_from_cube(u1, u2, u3);
}

glm::quat low_discrepancy_rotation(std::uint64_t index) {
  return rotation_from_cube(radical_inverse(index + 1, 2), radical_inverse(index + 1, 3), radical_inverse(index + 1, 5));
}

}  // namespace transgi::probes

namespace transgi::probes {

PendingProbeRay begin_probe_ray(const engine::rt::RtScene& scene, const engine::render::LightSet& lights,
                                const glm::vec3& dir, const engine::rt::Hit* traced, engine::math::Pcg32& rng, HitLobes lobes) {
  using namespace engine;
  PendingProbeRay p;
  ProbeRayHit& r = p.r;
  if (!traced) {
    if (const scene::Environment* env = lights.environment()) r.emitted = env->radiance(dir);
    if (!std::isfinite(r.emitted.r + r.emitted.g + r.emitted.b)) {
      r.emitted = glm::vec3(0.0f);
      r.replaced_non_finite = true;
    }
    r.saw_light = true;
    return p;
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
  if (emitter || wo.z <= 0) return p;
  p.takes_feedback = true;
  // The bounce: the previous frame's irradiance there, reflected as light
  // arriving evenly, by every lobe that reflects the next-event sample.
  const glm::vec3 albedo = lobes == HitLobes::Diffuse ? material::diffuse_albedo(s.brdf) : material::directional_albedo(s.brdf, wo.z);
  p.reflectance_over_pi = albedo * math::kInvPi;
  p.shading_normal = s.shading_normal;
  p.to_probe = -dir;
  // The light sample is reflected by a lobe at least kProbeHitMinRoughness
  // rough, scaled to the surface's own directional albedo: the blur keeps
  // the energy (a rougher GGX lobe alone reflects less: single scattering).
  material::BrdfParams blurred = s.brdf;
  glm::vec3 energy(1.0f);
  if (lobes == HitLobes::All && blurred.roughness < gpu::kProbeHitMinRoughness) {
    blurred.roughness = gpu::kProbeHitMinRoughness;
    const glm::vec3 rough = material::directional_albedo(blurred, wo.z);
    for (int k = 0; k < 3; ++k) energy[k] = rough[k] > 0 ? albedo[k] / rough[k] : 0.0f;
  }
  render::LightSample ls;
  const float u_sel = rng.next_float();
  const glm::vec2 u{rng.next_float(), rng.next_float()};
  if (lights.sample(s.position, u_sel, u, ls) && glm::dot(ls.direction, s.geometric_normal) > 0) {
    const glm::vec3 wi = s.frame.to_local(ls.direction);
    const glm::vec3 f = !(wi.z > 0)                ? glm::vec3(0.0f)
                        : lobes == HitLobes::Diffuse ? material::brdf_eval_diffuse(s.brdf, wo, wi)
                                                     : material::brdf_eval(blurred, wo, wi) * energy;
    if (f != glm::vec3(0.0f)) {
      const glm::vec3 o = rt::offset_ray_origin(s.position, s.geometric_normal, scene.offset_scale());
      const float tmax = std::isinf(ls.distance) ? std::numeric_limits<float>::infinity() : ls.distance * (1.0f - 1e-4f);
      p.needs_shadow = true;
      p.shadow = rt::Ray{o, ls.direction, 0.0f, tmax};
      p.unoccluded = f * wi.z * ls.radiance / (ls.delta ? 1.0f : ls.pdf);
    }
  }
  return p;
}

}  // namespace transgi::probes
