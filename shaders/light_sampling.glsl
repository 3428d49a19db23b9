// render::LightSet::sample: one group picked with equal probability
// (environment, area lights, punctual lights, in that order), then a
// direction from the environment's importance distribution, a triangle by
// emitted power, or a punctual light uniformly. The distributions' CDFs are
// floats here and doubles on the CPU: a sample within a float's rounding of
// a bin border can land in the neighbouring bin. Include after
// scene_shading.glsl.

struct LightSample {
  vec3 radiance, direction;
  float distance, pdf;
  bool delta;
};

// Distribution1D::sample_continuous over n bins. Triangles: the CDF is
// sh_triangle_cdf and the densities are in their records; else the CDF
// (n + 1 values) starts at cdf_at and the densities at pdf_at in
// sh_light_tables.
float cdf_value(bool triangles, uint at) { return triangles ? sh_triangle_cdf[at] : sh_light_tables[at]; }
float distribution_sample(bool triangles, uint cdf_at, uint pdf_at, uint n, float u, out float pdf, out uint index) {
  // Largest i with cdf[i] <= u, within [0, n - 1] (upper_bound over cdf[0 .. n]).
  uint lo = 0u, hi = n + 1u;
  while (lo < hi) {
    const uint mid = (lo + hi) >> 1;
    if (cdf_value(triangles, cdf_at + mid) <= u) lo = mid + 1u; else hi = mid;
  }
  uint i = lo > 0u ? lo - 1u : 0u;
  i = min(i, n - 1u);
  index = i;
  float du = u - cdf_value(triangles, cdf_at + i);
  const float width = cdf_value(triangles, cdf_at + i + 1u) - cdf_value(triangles, cdf_at + i);
  if (width > 0.0) du /= width;
  pdf = triangles ? sh_emissive[i].pdf : sh_light_tables[pdf_at + i];
  return min((float(i) + du) / float(n), 1.0 - 1.0 / 16777216.0);
}

// math::sample_uniform_cone and sample_uniform_triangle (Heitz 2019).
vec3 sample_uniform_cone(vec2 u, float cos_r) {
  const float z = 1.0 - u.x * (1.0 - cos_r), s = sqrt(max(0.0, 1.0 - z * z)), phi = 2.0 * kShadingPi * u.y;
  return vec3(s * cos(phi), s * sin(phi), z);
}
vec2 sample_uniform_triangle(vec2 u) {
  float b0, b1;
  if (u.x < u.y) {
    b0 = u.x / 2.0;
    b1 = u.y - b0;
  } else {
    b1 = u.y / 2.0;
    b0 = u.x - b1;
  }
  return vec2(b1, 1.0 - b0 - b1);
}

// LightSet::sample_punctual (not divided by any selection probability).
bool sample_punctual(uint i, vec3 p, vec2 u, out LightSample ls) {
  const PunctualLightGpu l = sh_punctual[i];
  const vec3 power = vec3(l.power_r, l.power_g, l.power_b);
  const vec3 shines = vec3(l.direction_x, l.direction_y, l.direction_z);
  ls.delta = true;
  ls.pdf = 0.0;
  if (l.type == kPunctualDirectional) {
    ls.direction = -shines;
    if (l.angular_radius > 0.0) ls.direction = to_world(frame_from_normal(-shines), sample_uniform_cone(u, cos(l.angular_radius)));
    ls.distance = shading_infinity();
    ls.radiance = power;
    return true;
  }
  vec3 d = vec3(l.position_x, l.position_y, l.position_z) - p;
  const float dist2 = dot(d, d);
  if (!(dist2 > 0.0)) return false;
  const float dist = sqrt(dist2);
  d /= dist;
  float window = 1.0;
  if (l.range > 0.0) {
    const float r = dist / l.range;
    window = clamp(1.0 - r * r * r * r, 0.0, 1.0);
  }
  float atten = window / dist2;
  if (l.type == kPunctualSpot) {
    const float cos_angle = dot(shines, -d);
    float falloff;
    if (l.cos_inner - l.cos_outer < 1e-6) {
      falloff = cos_angle >= l.cos_outer ? 1.0 : 0.0;
    } else {
      const float t = clamp((cos_angle - l.cos_outer) / (l.cos_inner - l.cos_outer), 0.0, 1.0);
      falloff = t * t;
    }
    atten *= falloff;
  }
  ls.direction = d;
  ls.distance = dist;
  ls.radiance = power * atten;
  return atten > 0.0;
}

bool sample_light(vec3 p, float u_select, vec2 u, out LightSample ls) {
  ls.radiance = vec3(0.0);
  ls.direction = vec3(0.0);
  ls.distance = 0.0;
  ls.pdf = 0.0;
  ls.delta = false;
  const LightSetGpu L = sh_lights;
  if (L.groups == 0) return false;
  int group = min(L.groups - 1, int(u_select * float(L.groups)));
  const float pg = 1.0 / float(L.groups);
  if (L.has_environment != 0 && group-- == 0) {
    // math::AliasDistribution2D::sample.
    const float below_one = 1.0 - 1.0 / 16777216.0;
    const uint w = uint(L.env_width), h = uint(L.env_height), n = w * h;
    const float scaled = u.x * float(n);
    const uint i = min(uint(max(scaled, 0.0)), n - 1u);
    const float leftover = scaled - float(i);
    const uint at = L.env_alias + 4u * i;
    const float threshold = sh_light_tables[at];
    float down = u.y, map_pdf = sh_light_tables[at + 2u];
    uint bin = i;
    if (down < threshold) {
      down = down / threshold;
    } else {
      bin = floatBitsToUint(sh_light_tables[at + 1u]);
      map_pdf = sh_light_tables[at + 3u];
      down = (down - threshold) / (1.0 - threshold);
    }
    down = clamp(down, 0.0, below_one);
    const float spacing = min(1.0, float(n) / 16777216.0);
    const float across = clamp(leftover + spacing * fract(down * 1024.0), 0.0, below_one);
    float x = min((float(bin % w) + across) / float(w), below_one);
    float v = min((float(bin / w) + down) / float(h), below_one);
    if (uint(x * float(w)) > bin % w) x = uintBitsToFloat(floatBitsToUint(x) - 1u);  // rounded onto the next bin's edge
    if (uint(v * float(h)) > bin / w) v = uintBitsToFloat(floatBitsToUint(v) - 1u);
    const float sin_theta = sin(kShadingPi * v);
    ls.direction = normalize(env_to_world(env_uv_to_direction(vec2(x, v))));
    const float pdf = sin_theta > 0.0 ? map_pdf / (2.0 * kShadingPi * kShadingPi * sin_theta) : 0.0;
    // The sampled texel's radiance (Environment::sample): the direction may lie on its edge.
    const uint texel = L.env_texels + 3u * bin;
    ls.radiance = L.env_strength * vec3(sh_light_tables[texel], sh_light_tables[texel + 1u], sh_light_tables[texel + 2u]);
    ls.distance = shading_infinity();
    ls.pdf = pdf * pg;
    return pdf > 0.0;
  }
  if (L.triangles > 0 && group-- == 0) {
    float tri_pdf;
    uint i;
    const uint count = uint(L.triangles);
    const float x = distribution_sample(true, 0u, 0u, count, u.x, tri_pdf, i);
    const float n = float(count);
    const float ux = clamp(x * n - float(i), 0.0, 0.99999994);
    const EmissiveTriangleGpu t = sh_emissive[i];
    const vec3 p0 = vec3(t.p0_x, t.p0_y, t.p0_z), p1 = vec3(t.p1_x, t.p1_y, t.p1_z), p2 = vec3(t.p2_x, t.p2_y, t.p2_z);
    const vec2 b = sample_uniform_triangle(vec2(ux, u.y));
    const vec3 q = (1.0 - b.x - b.y) * p0 + b.x * p1 + b.y * p2;
    vec3 d = q - p;
    const float dist2 = dot(d, d);
    if (!(dist2 > 0.0)) return false;
    const float dist = sqrt(dist2);
    d /= dist;
    const vec3 n_light = normalize(cross(p1 - p0, p2 - p0));
    const float cos_l = abs(dot(n_light, d));
    if (cos_l <= 1e-7) return false;
    ls.pdf = pg * (tri_pdf / n) / t.area * dist2 / cos_l;
    ls.radiance = evaluate_emission(t.material, (1.0 - b.x - b.y) * vec2(t.u0, t.v0) + b.x * vec2(t.u1, t.v1) + b.y * vec2(t.u2, t.v2));
    ls.direction = d;
    ls.distance = dist;
    ls.delta = false;
    return true;
  }
  if (L.punctual > 0) {
    const float n = float(L.punctual);
    const uint i = min(uint(L.punctual) - 1u, uint(u.x * n));
    const float ux = clamp(u.x * n - float(i), 0.0, 0.99999994);
    if (!sample_punctual(i, p, vec2(ux, u.y), ls)) return false;
    ls.radiance /= pg / n;
    return true;
  }
  return false;
}
