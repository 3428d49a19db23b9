#pragma once
// The glTF 2.0 reference BRDF (spec Appendix B), in a local shading frame
// whose +z is the shading normal. Both wo and wi point away from the surface.
//
//   fr         = Schlick(F0 = min(0.04 specular_color, 1), wo.h)        (per channel)
//   dielectric = Lambert(base) * C(wo, wi) + s * fr * GGX
//   metal      = Schlick(F0 = base, wo.h) * GGX
//   f          = mix(dielectric, metal, metallic)
//
// GGX = D * V with height-correlated Smith V; alpha = roughness^2.
// s = specularFactor and specular_color = specularColorFactor come from
// KHR_materials_specular (s = 0 gives a pure Lambertian surface).
//
// The layer coupling C differs from the spec's fresnel_mix on purpose. The
// spec weights the diffuse by (1 - s max(fr(wo.h))), which gains energy at
// grazing view angles (white furnace albedo 1.84 at cos = 0.02, measured by
// tests/engine/brdf_test.cpp before this change). Weighting by F(n.wo), as
// shared/tools/cycles_render.py does, conserves energy but is not reciprocal.
// We use the reciprocal, energy-conserving albedo scaling of Kelemen and
// Szirmay-Kalos (2001):
//   C = (1 - s E(wo)) (1 - s E(wi)) / (1 - s E_avg)
// with E the specular lobe's directional albedo (specular_albedo.h), so the
// dielectric's albedo is exactly s E(wo) + base (1 - s E(wo)) <= 1.
#include <glm/glm.hpp>

namespace engine::material {

struct BrdfParams {
  glm::vec3 base_color{0.8f};
  float metallic = 0.0f;
  float roughness = 0.5f;
  float specular = 1.0f;                  // s above
  glm::vec3 specular_color{1.0f};
};

// Roughness below this is clamped: a perfect mirror is represented by a very
// sharp GGX lobe (alpha = 1e-6 would overflow D in float).
inline constexpr float kMinAlpha = 1e-3f;
// A dielectric's Fresnel reflectance at normal incidence (index 1.5), times
// specular_color.
inline constexpr float kDielectricF0 = 0.04f;

struct BrdfSample {
  glm::vec3 wi{0.0f};
  glm::vec3 f{0.0f};  // BRDF value (not multiplied by cos)
  float pdf = 0.0f;   // combined (one-sample MIS) pdf of wi
  bool specular_lobe = false;
};

// Reflectance of the diffuse lobe alone (base colour of the non-metal part).
// What irradiance-only lighting can reflect: probe feedback bounces, DDGI, and
// TransGI's fallback for objects without latents.
inline glm::vec3 diffuse_albedo(const BrdfParams& p) { return p.base_color * (1.0f - p.metallic); }
// The whole BRDF's directional albedo towards wo (cos_o = wo.z): the
// fraction of light arriving evenly from the hemisphere that it reflects
// towards wo, integral f(wo, wi) cos_i dwi, diffuse and specular lobes both.
// What a surface reflects of light known only as an average (irradiance /
// pi): a varnished floor's specular layer and a metal reflect the room's
// light too, where diffuse_albedo leaves them black.
glm::vec3 directional_albedo(const BrdfParams& p, float cos_o);
// Its parts, for shading that splits light known as averages by lobe (the
// diffuse lobe's about the normal, the glossy lobes' about the mirror
// direction): the non-metal part's specular layer albedo towards wo (per
// channel, at most 1; its diffuse lobe reflects base_color x (1 - this)), and
// the metal part's. directional_albedo = (1 - metallic) (base (1 - layer) +
// layer) + metallic metal (where the layer is below 1).
glm::vec3 dielectric_layer_albedo(const BrdfParams& p, float cos_o);
glm::vec3 metal_albedo(const BrdfParams& p, float cos_o);

// f(wo, wi). Zero when either direction is below the surface.
glm::vec3 brdf_eval(const BrdfParams& p, const glm::vec3& wo, const glm::vec3& wi);
// The diffuse lobe of f alone (the non-metal part, its layer coupling
// included): brdf_eval less the glossy lobes. For estimators that must not
// see glints (a sparse ray that meets the sun's highlight on a metal).
glm::vec3 brdf_eval_diffuse(const BrdfParams& p, const glm::vec3& wo, const glm::vec3& wi);
// Density with which brdf_sample() produces wi.
float brdf_pdf(const BrdfParams& p, const glm::vec3& wo, const glm::vec3& wi);
// Picks the GGX lobe (visible-normal sampling, Heitz 2018) or the cosine lobe
// with probability spec_probability(), and reports the combined pdf. Returns
// false when no valid direction was produced.
bool brdf_sample(const BrdfParams& p, const glm::vec3& wo, glm::vec2 u, float u_lobe, BrdfSample& out);

// Probability of choosing the GGX lobe: the lobes' estimated albedos.
float spec_probability(const BrdfParams& p, float cos_o);

// Pieces, exposed for tests.
float ggx_d(float alpha, float cos_h);
float smith_g1(float alpha, float cos_v);
float smith_v_height_correlated(float alpha, float cos_o, float cos_i);  // G2 / (4 cos_o cos_i)
glm::vec3 schlick_fresnel(const glm::vec3& f0, float cos_theta);
glm::vec3 sample_ggx_vndf(float alpha, const glm::vec3& wo, glm::vec2 u);  // a half vector
// C(wo, wi) per channel, for a dielectric with Fresnel F0 = f0.
glm::vec3 diffuse_coupling(const BrdfParams& p, const glm::vec3& f0, float alpha, float cos_o, float cos_i);

}  // namespace engine::material
