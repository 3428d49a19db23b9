// A ray hit's surface as render::make_surface builds it on the CPU: the
// instance's transform, the triangle's interpolated normal and texture
// coordinates, and the glTF material with its textures (level 0, bilinear,
// as Texture::sample). The includer defines SHADING_SET and SHADING_BINDING
// (the first of kShadingBindings consecutive bindings, GpuShadingScene's
// order) before including this file.
#include "shading_shared.h"

const uint kShadingBindings = 12u;
const float kShadingPi = 3.14159265358979;
const float kShadingInvPi = 1.0 / 3.14159265358979;

layout(std430, set = SHADING_SET, binding = SHADING_BINDING) readonly buffer ShInstances { ShadingInstanceGpu sh_instances[]; };
layout(std430, set = SHADING_SET, binding = SHADING_BINDING + 1) readonly buffer ShMeshFirst { uint sh_mesh_first[]; };
layout(std430, set = SHADING_SET, binding = SHADING_BINDING + 2) readonly buffer ShTriangles { ShadingTriangleGpu sh_triangles[]; };
layout(std430, set = SHADING_SET, binding = SHADING_BINDING + 3) readonly buffer ShMaterials { MaterialGpu sh_materials[]; };
layout(std430, set = SHADING_SET, binding = SHADING_BINDING + 4) readonly buffer ShTextures { TextureGpu sh_textures[]; };
layout(std430, set = SHADING_SET, binding = SHADING_BINDING + 5) readonly buffer ShTexels { uint sh_texels[]; };
layout(std430, set = SHADING_SET, binding = SHADING_BINDING + 6) readonly buffer ShTables { float sh_tables[]; };
layout(std430, set = SHADING_SET, binding = SHADING_BINDING + 7) readonly buffer ShLightSet { LightSetGpu sh_lights; };
layout(std430, set = SHADING_SET, binding = SHADING_BINDING + 8) readonly buffer ShEmissive { EmissiveTriangleGpu sh_emissive[]; };
layout(std430, set = SHADING_SET, binding = SHADING_BINDING + 9) readonly buffer ShPunctual { PunctualLightGpu sh_punctual[]; };
layout(std430, set = SHADING_SET, binding = SHADING_BINDING + 10) readonly buffer ShLightTables { float sh_light_tables[]; };
layout(std430, set = SHADING_SET, binding = SHADING_BINDING + 11) readonly buffer ShTriangleCdf { float sh_triangle_cdf[]; };

float shading_infinity() { return uintBitsToFloat(0x7f800000u); }
bool finite3(vec3 v) { return !any(isnan(v)) && !any(isinf(v)); }

// math::Frame (Duff et al. 2017) around n; copysign keeps -0 negative.
struct Frame {
  vec3 t, b, n;
};
Frame frame_from_normal(vec3 n) {
  const float sign = (floatBitsToUint(n.z) >> 31u) != 0u ? -1.0 : 1.0;
  const float a = -1.0 / (sign + n.z);
  const float b = n.x * n.y * a;
  Frame f;
  f.t = vec3(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
  f.b = vec3(b, sign + n.y * n.y * a, -n.y);
  f.n = n;
  return f;
}
vec3 to_local(Frame f, vec3 v) { return vec3(dot(v, f.t), dot(v, f.b), dot(v, f.n)); }
vec3 to_world(Frame f, vec3 v) { return v.x * f.t + v.y * f.b + v.z * f.n; }

#include "ray_offset.glsl"
#include "texture_wrap.glsl"

vec4 texel_at(TextureGpu t, int x, int y, bool srgb) {
  const int cx = texture_wrap(x, t.width, t.wrap & 0xffu), cy = texture_wrap(y, t.height, (t.wrap >> 8) & 0xffu);
  const uint v = sh_texels[t.first + uint(cy * t.width + cx)];
  const uvec4 b = uvec4(v & 0xffu, (v >> 8) & 0xffu, (v >> 16) & 0xffu, v >> 24);
  if (srgb) return vec4(sh_tables[kShadingSrgbLut + b.r], sh_tables[kShadingSrgbLut + b.g], sh_tables[kShadingSrgbLut + b.b], float(b.a) / 255.0);
  return vec4(b) / 255.0;
}

// Texture::sample(uv, srgb): bilinear on level 0.
vec4 texture_sample(int index, vec2 uv, bool srgb) {
  const TextureGpu t = sh_textures[index];
  if (t.width <= 0 || t.height <= 0) return vec4(1.0);
  if (isnan(uv.x) || isinf(uv.x) || isnan(uv.y) || isinf(uv.y)) uv = vec2(0.0);
  const vec2 r = uv - 4096.0 * trunc(uv / 4096.0);  // std::fmod
  const float x = r.x * float(t.width) - 0.5, y = r.y * float(t.height) - 0.5;
  const float fx = floor(x), fy = floor(y);
  const float tx = x - fx, ty = y - fy;
  const int x0 = int(fx), y0 = int(fy);
  const vec4 a = texel_at(t, x0, y0, srgb), b = texel_at(t, x0 + 1, y0, srgb);
  const vec4 c = texel_at(t, x0, y0 + 1, srgb), d = texel_at(t, x0 + 1, y0 + 1, srgb);
  const vec4 mean = (1.0 - ty) * ((1.0 - tx) * a + tx * b) + ty * ((1.0 - tx) * c + tx * d);
  if (((t.wrap >> 16) & 1u) == 0u || !(mean.a > 0.0)) return mean;
  // A cut-out's colour weighted by alpha, as Texture::sample's.
  const vec3 weighted = (1.0 - ty) * ((1.0 - tx) * a.a * a.rgb + tx * b.a * b.rgb) + ty * ((1.0 - tx) * c.a * c.rgb + tx * d.a * d.rgb);
  return vec4(weighted / mean.a, mean.a);
}

// material::BrdfParams.
struct Brdf {
  vec3 base_color;
  float metallic, roughness, specular;
  vec3 specular_color;
};

// render::evaluate_material with a point sample.
Brdf evaluate_material(uint index, vec2 uv) {
  const MaterialGpu m = sh_materials[index];
  vec4 base = vec4(m.base_r, m.base_g, m.base_b, m.base_a);
  if (m.base_texture >= 0) base *= texture_sample(m.base_texture, uv, true);
  Brdf p;
  p.base_color = base.rgb;
  p.metallic = m.metallic;
  p.roughness = m.roughness;
  if (m.metallic_roughness_texture >= 0) {
    const vec4 mr = texture_sample(m.metallic_roughness_texture, uv, false);
    p.roughness *= mr.g;
    p.metallic *= mr.b;
  }
  p.specular = m.specular;
  p.specular_color = vec3(m.specular_r, m.specular_g, m.specular_b);
  return p;
}

// render::evaluate_emission with a point sample.
vec3 evaluate_emission(uint index, vec2 uv) {
  const MaterialGpu m = sh_materials[index];
  vec3 e = vec3(m.emission_r, m.emission_g, m.emission_b);
  if (m.emissive_texture >= 0 && (e.r > 0.0 || e.g > 0.0 || e.b > 0.0)) e *= texture_sample(m.emissive_texture, uv, true).rgb;
  return e;
}

// render::Surface.
struct Surface {
  vec3 position, geometric_normal, shading_normal;
  vec2 uv;
  vec3 emission;
  Brdf brdf;
  uint material;
  bool back_face;
  Frame frame;
};

vec3 instance_rotate(ShadingInstanceGpu s, vec3 v) {
  return vec3(dot(vec3(s.r0_x, s.r0_y, s.r0_z), v), dot(vec3(s.r1_x, s.r1_y, s.r1_z), v), dot(vec3(s.r2_x, s.r2_y, s.r2_z), v));
}
vec3 instance_point(ShadingInstanceGpu s, vec3 p) { return vec3(s.t_x, s.t_y, s.t_z) + instance_rotate(s, s.scale * p); }

// render::make_surface for a hit of `instance` (RtScene id), triangle
// `primitive` of `mesh` at barycentrics (u, v), found by a ray along dir.
Surface make_surface(uint instance, uint mesh, uint primitive, float u, float v, vec3 dir) {
  const ShadingInstanceGpu inst = sh_instances[instance];
  const ShadingTriangleGpu t = sh_triangles[sh_mesh_first[mesh] + primitive];
  const float b1 = u, b2 = v, b0 = 1.0 - b1 - b2;
  Surface s;
  const vec3 p0 = instance_point(inst, vec3(t.p0_x, t.p0_y, t.p0_z));
  const vec3 p1 = instance_point(inst, vec3(t.p1_x, t.p1_y, t.p1_z));
  const vec3 p2 = instance_point(inst, vec3(t.p2_x, t.p2_y, t.p2_z));
  s.position = b0 * p0 + b1 * p1 + b2 * p2;
  vec3 ng = cross(p1 - p0, p2 - p0);
  const float len = length(ng);
  ng = len > 0.0 ? ng / len : vec3(0.0, 0.0, 1.0);
  vec3 ns = instance_rotate(inst, b0 * vec3(t.n0_x, t.n0_y, t.n0_z) + b1 * vec3(t.n1_x, t.n1_y, t.n1_z) + b2 * vec3(t.n2_x, t.n2_y, t.n2_z));
  const float ns_len = length(ns);
  ns = ns_len > 0.0 ? ns / ns_len : ng;
  s.material = t.material;
  const bool behind = dot(ng, dir) > 0.0;
  s.back_face = behind && sh_materials[s.material].double_sided == 0u;
  if (behind) ng = -ng;
  if (dot(ns, ng) < 0.0) ns = -ns;
  s.geometric_normal = ng;
  s.shading_normal = ns;
  s.frame = frame_from_normal(ns);
  s.uv = t.has_uv != 0u ? b0 * vec2(t.u0, t.v0) + b1 * vec2(t.u1, t.v1) + b2 * vec2(t.u2, t.v2) : vec2(0.0);
  s.brdf = evaluate_material(s.material, s.uv);
  s.emission = evaluate_emission(s.material, s.uv);
  return s;
}

// scene::Environment (the light set's: the residual where the sun is split out).
vec3 env_to_local(vec3 d) {
  const LightSetGpu l = sh_lights;
  return vec3(dot(vec3(l.to_local_r0_x, l.to_local_r0_y, l.to_local_r0_z), d),
              dot(vec3(l.to_local_r1_x, l.to_local_r1_y, l.to_local_r1_z), d),
              dot(vec3(l.to_local_r2_x, l.to_local_r2_y, l.to_local_r2_z), d));
}
vec3 env_to_world(vec3 d) {
  const LightSetGpu l = sh_lights;
  return vec3(dot(vec3(l.to_world_r0_x, l.to_world_r0_y, l.to_world_r0_z), d),
              dot(vec3(l.to_world_r1_x, l.to_world_r1_y, l.to_world_r1_z), d),
              dot(vec3(l.to_world_r2_x, l.to_world_r2_y, l.to_world_r2_z), d));
}
vec2 env_direction_to_uv(vec3 l) {
  float u = atan(l.x, -l.z) / (2.0 * kShadingPi);
  if (u < 0.0) u += 1.0;
  if (u >= 1.0) u = 0.0;
  return vec2(u, acos(clamp(l.y, -1.0, 1.0)) / kShadingPi);
}
vec3 env_uv_to_direction(vec2 uv) {
  const float phi = 2.0 * kShadingPi * uv.x, theta = kShadingPi * uv.y;
  return vec3(sin(phi) * sin(theta), cos(theta), -cos(phi) * sin(theta));
}
vec3 environment_radiance(vec3 world_dir) {
  if (sh_lights.has_environment == 0) return vec3(0.0);
  const vec2 uv = env_direction_to_uv(normalize(env_to_local(world_dir)));
  const int w = sh_lights.env_width, h = sh_lights.env_height;
  const int x = min(w - 1, int(uv.x * float(w))), y = min(h - 1, int(uv.y * float(h)));
  const uint at = sh_lights.env_texels + 3u * uint(y * w + x);
  return sh_lights.env_strength * vec3(sh_light_tables[at], sh_light_tables[at + 1u], sh_light_tables[at + 2u]);
}
