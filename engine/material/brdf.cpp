#include "engine/material/brdf.h"

#include <algorithm>
#include <cmath>

#include "engine/material/specular_albedo.h"
#include "engine/math/sampling.h"

namespace engine::material {

using math::kInvPi;
using math::kPi;

namespace {

float alpha_of(const BrdfParams& p) { return std::max(kMinAlpha, p.roughness * p.roughness); }
float pow5(float x) {
  const float x2 = x * x;
  return x2 * x2 * x;
}
}  // namespace

namespace {
// The specular layer's albedo in one channel (F0 = f0), at most 1.
float layer_albedo(const BrdfParams& p, const SpecularAlbedo& e, float f0) { return std::min(1.0f, p.specular * e.with_f0(f0)); }
}  // namespace

glm::vec3 diffuse_coupling(const BrdfParams& p, const glm::vec3& f0, float alpha, float cos_o, float cos_i) {
  if (p.specular <= 0) return glm::vec3(1.0f);
  const SpecularAlbedo eo = ggx_albedo(cos_o, alpha), ei = ggx_albedo(cos_i, alpha);
  const SpecularAlbedo avg = ggx_average_albedo(alpha);
  glm::vec3 c;
  for (int k = 0; k < 3; ++k) {
    const float e_o = layer_albedo(p, eo, f0[k]), e_i = layer_albedo(p, ei, f0[k]), e_avg = layer_albedo(p, avg, f0[k]);
    c[k] = e_avg < 1.0f ? (1.0f - e_o) * (1.0f - e_i) / (1.0f - e_avg) : 0.0f;
  }
  return c;
}

float ggx_d(float alpha, float cos_h) {
  if (cos_h <= 0) return 0.0f;
  const float a2 = alpha * alpha;
  const float d = cos_h * cos_h * (a2 - 1.0f) + 1.0f;
  return a2 / (kPi * d * d);
}

float smith_g1(float alpha, float cos_v) {
  if (cos_v <= 0) return 0.0f;
  const float a2 = alpha * alpha;
  return 2.0f * cos_v / (cos_v + std::sqrt(a2 + (1.0f - a2) * cos_v * cos_v));
}

float smith_v_height_correlated(float alpha, float cos_o, float cos_i) {
  const float a2 = alpha * alpha;
  const float lo = cos_i * std::sqrt(cos_o * cos_o * (1.0f - a2) + a2);
  const float li = cos_o * std::sqrt(cos_i * cos_i * (1.0f - a2) + a2);
  const float denom = lo + li;
  return denom > 0 ? 0.5f / denom : 0.0f;
}

glm::vec3 schlick_fresnel(const glm::vec3& f0, float cos_theta) {
  return f0 + (glm::vec3(1.0f) - f0) * pow5(1.0f - std::clamp(cos_theta, 0.0f, 1.0f));
}

glm::vec3 sample_ggx_vndf(float alpha, const glm::vec3& wo, glm::vec2 u) {
  // Heitz 2018, "Sampling the GGX Distribution of Visible Normals".
  const glm::vec3 vh = glm::normalize(glm::vec3(alpha * wo.x, alpha * wo.y, wo.z));
  const float len2 = vh.x * vh.x + vh.y * vh.y;
  const glm::vec3 t1 = len2 > 0 ? glm::vec3(-vh.y, vh.x, 0) / std::sqrt(len2) : glm::vec3(1, 0, 0);
  const glm::vec3 t2 = glm::cross(vh, t1);
  const float r = std::sqrt(u.x);
  const float phi = 2.0f * kPi * u.y;
  const float p1 = r * std::cos(phi);
  float p2 = r * std::sin(phi);
  const float s = 0.5f * (1.0f + vh.z);
  p2 = (1.0f - s) * std::sqrt(std::max(0.0f, 1.0f - p1 * p1)) + s * p2;
  const glm::vec3 nh = p1 * t1 + p2 * t2 + std::sqrt(std::max(0.0f, 1.0f - p1 * p1 - p2 * p2)) * vh;
  return glm::normalize(glm::vec3(alpha * nh.x, alpha * nh.y, std::max(1e-6f, nh.z)));
}

float spec_probability(const BrdfParams& p, float cos_o) {
  const float alpha = alpha_of(p);
  const float f0_dielectric = std::min(kDielectricF0 * math::luminance(p.specular_color), 1.0f);
  const SpecularAlbedo e = ggx_albedo(cos_o, alpha);
  const float spec_dielectric = p.specular * e.with_f0(f0_dielectric);
  const float spec_metal = e.with_f0(math::luminance(p.base_color));
  const float spec = (1.0f - p.metallic) * spec_dielectric + p.metallic * spec_metal;
  const float diffuse = (1.0f - p.metallic) * math::luminance(p.base_color) * (1.0f - spec_dielectric);
  if (spec <= 0) return 0.0f;
  if (diffuse <= 0) return 1.0f;
  // Keep both lobes reachable so MIS never divides by a vanishing pdf.
  return std::clamp(spec / (spec + diffuse), 0.1f, 0.9f);
}

namespace {
glm::vec3 dielectric_f0(const BrdfParams& p) { return glm::min(kDielectricF0 * p.specular_color, glm::vec3(1.0f)); }
// The non-metal part's diffuse lobe, before the (1 - metallic) weight.
glm::vec3 diffuse_lobe(const BrdfParams& p, const glm::vec3& f0, float alpha, float cos_o, float cos_i) {
  return kInvPi * p.base_color * diffuse_coupling(p, f0, alpha, cos_o, cos_i);
}
}  // namespace

glm::vec3 brdf_eval_diffuse(const BrdfParams& p, const glm::vec3& wo, const glm::vec3& wi) {
  const float cos_o = wo.z, cos_i = wi.z;
  if (cos_o <= 0 || cos_i <= 0 || !(p.metallic < 1.0f)) return glm::vec3(0.0f);
  return (1.0f - p.metallic) * diffuse_lobe(p, dielectric_f0(p), alpha_of(p), cos_o, cos_i);
}

glm::vec3 directional_albedo(const BrdfParams& p, float cos_o) {
  if (!(cos_o > 0)) return glm::vec3(0.0f);
  const float alpha = alpha_of(p);
  const SpecularAlbedo e = ggx_albedo(cos_o, alpha);
  glm::vec3 dielectric(0.0f), metal(0.0f);
  if (p.metallic < 1.0f && p.specular <= 0) {
    dielectric = p.base_color;  // no layer: the coupling is 1
  } else if (p.metallic < 1.0f) {
    // The diffuse lobe's coupling (1 - E_o)(1 - E_i) / (1 - E_avg) integrates
    // over wi to 1 - E_o: what the specular layer does not reflect.
    const glm::vec3 f0 = dielectric_f0(p);
    const SpecularAlbedo avg = ggx_average_albedo(alpha);
    for (int k = 0; k < 3; ++k) {
      const float e_o = layer_albedo(p, e, f0[k]);
      dielectric[k] = (layer_albedo(p, avg, f0[k]) < 1.0f ? p.base_color[k] * (1.0f - e_o) : 0.0f) + e_o;
    }
  }
  if (p.metallic > 0.0f)
    for (int k = 0; k < 3; ++k) metal[k] = e.with_f0(p.base_color[k]);
  return (1.0f - p.metallic) * dielectric + p.metallic * metal;
}

glm::vec3 dielectric_layer_albedo(const BrdfParams& p, float cos_o) {
  if (!(cos_o > 0) || p.specular <= 0) return glm::vec3(0.0f);
  const SpecularAlbedo e = ggx_albedo(cos_o, alpha_of(p));
  const glm::vec3 f0 = dielectric_f0(p);
  return {layer_albedo(p, e, f0.r), layer_albedo(p, e, f0.g), layer_albedo(p, e, f0.b)};
}

glm::vec3 metal_albedo(const BrdfParams& p, float cos_o) {
  if (!(cos_o > 0)) return glm::vec3(0.0f);
  const SpecularAlbedo e = ggx_albedo(cos_o, alpha_of(p));
  return {e.with_f0(p.base_color.r), e.with_f0(p.base_color.g), e.with_f0(p.base_color.b)};
}

glm::vec3 brdf_eval(const BrdfParams& p, const glm::vec3& wo, const glm::vec3& wi) {
  const float cos_o = wo.z, cos_i = wi.z;
  if (cos_o <= 0 || cos_i <= 0) return glm::vec3(0.0f);
  const float alpha = alpha_of(p);
  const glm::vec3 h = glm::normalize(wo + wi);
  const float ggx = ggx_d(alpha, h.z) * smith_v_height_correlated(alpha, cos_o, cos_i);
  const float cos_oh = std::max(0.0f, glm::dot(wo, h));

  glm::vec3 dielectric(0.0f);
  if (p.metallic < 1.0f) {
    const glm::vec3 f0 = dielectric_f0(p);
    dielectric = diffuse_lobe(p, f0, alpha, cos_o, cos_i);
    if (p.specular > 0) dielectric += p.specular * ggx * schlick_fresnel(f0, cos_oh);
  }
  glm::vec3 metal(0.0f);
  if (p.metallic > 0.0f) metal = schlick_fresnel(p.base_color, cos_oh) * ggx;
  return (1.0f - p.metallic) * dielectric + p.metallic * metal;
}

float brdf_pdf(const BrdfParams& p, const glm::vec3& wo, const glm::vec3& wi) {
  if (wo.z <= 0 || wi.z <= 0) return 0.0f;
  const float ps = spec_probability(p, wo.z);
  float pdf = (1.0f - ps) * math::cosine_hemisphere_pdf(wi.z);
  if (ps > 0) {
    const float alpha = alpha_of(p);
    const glm::vec3 h = glm::normalize(wo + wi);
    // VNDF: pdf(h) = G1(wo) max(0, wo.h) D(h) / wo.z; Jacobian of reflection 1 / (4 wo.h).
    pdf += ps * smith_g1(alpha, wo.z) * ggx_d(alpha, h.z) / (4.0f * wo.z);
  }
  return pdf;
}

bool brdf_sample(const BrdfParams& p, const glm::vec3& wo, glm::vec2 u, float u_lobe, BrdfSample& out) {
  if (wo.z <= 0) return false;
  const float ps = spec_probability(p, wo.z);
  out.specular_lobe = u_lobe < ps;
  if (out.specular_lobe) {
    const glm::vec3 h = sample_ggx_vndf(alpha_of(p), wo, u);
    out.wi = glm::reflect(-wo, h);
  } else {
    out.wi = math::sample_cosine_hemisphere(u);
  }
  if (out.wi.z <= 0) return false;
  out.pdf = brdf_pdf(p, wo, out.wi);
  if (!(out.pdf > 0) || !std::isfinite(out.pdf)) return false;
  out.f = brdf_eval(p, wo, out.wi);
  return true;
}

}  // namespace engine::material
