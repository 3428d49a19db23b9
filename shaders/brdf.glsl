// material::brdf_eval (engine/material/brdf.h): the glTF BRDF with the
// Kelemen and Szirmay-Kalos layer coupling, its GGX albedo read from the
// tables GpuShadingScene uploads (specular_albedo.cpp's, bilinear in
// (sqrt(mu), sqrt(alpha)) as ggx_albedo reads them). Include after
// scene_shading.glsl.

const float kMinAlpha = 1e-3;
const float kDielectricF0 = 0.04;

float alpha_of(Brdf p) { return max(kMinAlpha, p.roughness * p.roughness); }
float pow5(float x) {
  const float x2 = x * x;
  return x2 * x2 * x;
}

// specular_albedo.cpp's locate and r_coord.
void albedo_locate(float x, uint size, out int i0, out float t) {
  const float g = clamp(x, 0.0, 1.0) * float(size - 1u);
  i0 = min(int(g), int(size) - 2);
  t = g - float(i0);
}
float albedo_r_coord(float alpha) {
  const float r_min = sqrt(kMinAlpha);
  return (sqrt(clamp(alpha, kMinAlpha, 1.0)) - r_min) / (1.0 - r_min);
}
vec2 albedo_directional(int i, int j) {
  const uint at = kShadingAlbedoDirectional + 2u * uint(j * int(kShadingAlbedoMu) + i);
  return vec2(sh_tables[at], sh_tables[at + 1u]);
}
// (a, b) of ggx_albedo(mu, alpha): E = f0 a + b.
vec2 ggx_albedo(float mu, float alpha) {
  int i, j;
  float tu, ta;
  albedo_locate(sqrt(clamp(mu, 0.0, 1.0)), kShadingAlbedoMu, i, tu);
  albedo_locate(albedo_r_coord(alpha), kShadingAlbedoAlpha, j, ta);
  const vec2 e00 = albedo_directional(i, j), e10 = albedo_directional(i + 1, j);
  const vec2 e01 = albedo_directional(i, j + 1), e11 = albedo_directional(i + 1, j + 1);
  return (1.0 - ta) * ((1.0 - tu) * e00 + tu * e10) + ta * ((1.0 - tu) * e01 + tu * e11);
}
vec2 ggx_average_albedo(float alpha) {
  int j;
  float ta;
  albedo_locate(albedo_r_coord(alpha), kShadingAlbedoAlpha, j, ta);
  const uint at = kShadingAlbedoAverage + 2u * uint(j);
  return (1.0 - ta) * vec2(sh_tables[at], sh_tables[at + 1u]) + ta * vec2(sh_tables[at + 2u], sh_tables[at + 3u]);
}

vec3 diffuse_coupling(Brdf p, vec3 f0, float alpha, float cos_o, float cos_i) {
  if (p.specular <= 0.0) return vec3(1.0);
  const vec2 eo = ggx_albedo(cos_o, alpha), ei = ggx_albedo(cos_i, alpha), avg = ggx_average_albedo(alpha);
  vec3 c;
  for (int k = 0; k < 3; ++k) {
    const float e_o = min(1.0, p.specular * (f0[k] * eo.x + eo.y));
    const float e_i = min(1.0, p.specular * (f0[k] * ei.x + ei.y));
    const float e_avg = min(1.0, p.specular * (f0[k] * avg.x + avg.y));
    c[k] = e_avg < 1.0 ? (1.0 - e_o) * (1.0 - e_i) / (1.0 - e_avg) : 0.0;
  }
  return c;
}

float ggx_d(float alpha, float cos_h) {
  if (cos_h <= 0.0) return 0.0;
  const float a2 = alpha * alpha;
  const float d = cos_h * cos_h * (a2 - 1.0) + 1.0;
  return a2 / (kShadingPi * d * d);
}

float smith_v_height_correlated(float alpha, float cos_o, float cos_i) {
  const float a2 = alpha * alpha;
  const float lo = cos_i * sqrt(cos_o * cos_o * (1.0 - a2) + a2);
  const float li = cos_o * sqrt(cos_i * cos_i * (1.0 - a2) + a2);
  const float denom = lo + li;
  return denom > 0.0 ? 0.5 / denom : 0.0;
}

vec3 schlick_fresnel(vec3 f0, float cos_theta) { return f0 + (vec3(1.0) - f0) * pow5(1.0 - clamp(cos_theta, 0.0, 1.0)); }

vec3 brdf_eval(Brdf p, vec3 wo, vec3 wi) {
  const float cos_o = wo.z, cos_i = wi.z;
  if (cos_o <= 0.0 || cos_i <= 0.0) return vec3(0.0);
  const float alpha = alpha_of(p);
  const vec3 h = normalize(wo + wi);
  const float ggx = ggx_d(alpha, h.z) * smith_v_height_correlated(alpha, cos_o, cos_i);
  const float cos_oh = max(0.0, dot(wo, h));
  vec3 dielectric = vec3(0.0);
  if (p.metallic < 1.0) {
    const vec3 f0 = min(kDielectricF0 * p.specular_color, vec3(1.0));
    dielectric = kShadingInvPi * p.base_color * diffuse_coupling(p, f0, alpha, cos_o, cos_i);
    if (p.specular > 0.0) dielectric += p.specular * ggx * schlick_fresnel(f0, cos_oh);
  }
  vec3 metal = vec3(0.0);
  if (p.metallic > 0.0) metal = schlick_fresnel(p.base_color, cos_oh) * ggx;
  return (1.0 - p.metallic) * dielectric + p.metallic * metal;
}

// material::diffuse_albedo.
vec3 diffuse_albedo(Brdf p) { return p.base_color * (1.0 - p.metallic); }

// material::directional_albedo: the whole BRDF's reflectance of light
// arriving evenly, towards cos_o.
vec3 directional_albedo(Brdf p, float cos_o) {
  if (!(cos_o > 0.0)) return vec3(0.0);
  const float alpha = alpha_of(p);
  const vec2 e = ggx_albedo(cos_o, alpha);
  vec3 dielectric = vec3(0.0), metal = vec3(0.0);
  if (p.metallic < 1.0) {
    const vec3 f0 = min(kDielectricF0 * p.specular_color, vec3(1.0));
    const vec2 avg = ggx_average_albedo(alpha);
    for (int k = 0; k < 3; ++k) {
      const float spec = p.specular > 0.0 ? min(1.0, p.specular * (f0[k] * e.x + e.y)) : 0.0;
      const float e_avg = p.specular > 0.0 ? min(1.0, p.specular * (f0[k] * avg.x + avg.y)) : 0.0;
      dielectric[k] = (e_avg < 1.0 ? p.base_color[k] * (1.0 - spec) : 0.0) + spec;
    }
  }
  if (p.metallic > 0.0)
    for (int k = 0; k < 3; ++k) metal[k] = p.base_color[k] * e.x + e.y;
  return (1.0 - p.metallic) * dielectric + p.metallic * metal;
}
