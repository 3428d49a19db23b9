#include "shading/near_field.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <stdexcept>

#include "engine/jobs/parallel_for.h"
#include "engine/math/sampling.h"
#include "engine/math/sh.h"
#include "engine/rt/ray.h"
#include "probes/probe_rays.h"
#include "shading/sh_light.h"
#include "shading/upsampling.h"

namespace transgi::shading {

glm::vec3 near_field_irradiance(const engine::rt::RtScene& scene, const engine::render::LightSet* lights,
                                const GSample& s, const float* light_sh, float reach, float own_masked_within, int rays,
                                const NearLightAt& light_at, engine::math::Pcg32& rng) {
  using namespace engine;
  if (!s.hit || rays <= 0 || !(reach > 0)) return glm::vec3(0.0f);
  const float own_reach = std::isfinite(own_masked_within) ? std::max(own_masked_within, 0.0f) : 0.0f;
  static const render::LightSet kNoLights;
  const render::LightSet& light_set = lights ? *lights : kNoLights;
  const math::Frame frame = math::Frame::from_normal(s.normal_world);
  const glm::vec3 origin = rt::offset_ray_origin(s.position, s.geometric_normal, scene.offset_scale());
  const auto feedback = [&](const glm::vec3& p, const glm::vec3& n, const glm::vec3&) {
    float sh[75];
    light_at(p, n, sh);
    return sh_irradiance(sh, n);
  };
  float own_sh[75];
  const float* probes_sh = light_sh;
  glm::vec3 sum(0.0f);
  // Stratified over a sqrt(rays) x sqrt(rays) grid of the unit square where
  // it divides evenly, else plain random.
  const int side = static_cast<int>(std::lround(std::sqrt(static_cast<float>(rays))));
  const bool stratified = side * side == rays;
  for (int k = 0; k < rays; ++k) {
    glm::vec2 u{rng.next_float(), rng.next_float()};
    if (stratified) u = (glm::vec2(static_cast<float>(k % side), static_cast<float>(k / side)) + u) / static_cast<float>(side);
    const glm::vec3 dir = frame.to_world(math::sample_cosine_hemisphere(u));
    if (glm::dot(dir, s.geometric_normal) <= 0) continue;
    rt::Hit hit;
    if (!scene.intersect(rt::Ray{origin, dir, 0.0f, std::max(reach, own_reach)}, hit)) continue;
    const bool masked = hit.entity == s.entity && hit.t < own_reach;
    if (!masked && !(hit.t < reach)) continue;
    // The hit's diffuse lobe only: the near field carries contact light, and
    // a glint (the sun in a metal) met by one ray would be spread into a
    // bright box by the filter; the probes keep what the glossy lobes reflect.
    const probes::ProbeRayHit h = probes::shade_probe_ray(scene, light_set, dir, &hit, rng, feedback, probes::HitLobes::Diffuse);
    if (masked) {
      sum += h.radiance;
      continue;
    }
    if (!probes_sh) {
      light_at(s.position, s.normal_world, own_sh);
      probes_sh = own_sh;
    }
    const math::ShBasis y = math::sh_eval(dir);
    glm::vec3 probe_radiance(0.0f);
    for (int c = 0; c < 3; ++c)
      for (int i = 0; i < math::kShCount; ++i) probe_radiance[c] += probes_sh[c * math::kShCount + i] * y[static_cast<std::size_t>(i)];
    sum += h.radiance - probe_radiance;
  }
  const glm::vec3 e = sum * (math::kPi / static_cast<float>(rays));
  return std::isfinite(e.r + e.g + e.b) ? e : glm::vec3(0.0f);
}

namespace {
// The upsampling's default similarity (RealtimeGiSettings).
constexpr float kDepthTolerance = 0.05f;
constexpr int kNormalPower = 8;
}  // namespace

std::vector<glm::vec3> filter_near_field(std::span<const glm::vec4> guide, int width, int height, int spp,
                                         std::span<const glm::vec3> values, int radius) {
  std::vector<glm::vec3> out(values.size(), glm::vec3(0.0f));
  const auto at = [&](int x, int y, int k) { return (static_cast<std::size_t>(y) * width + x) * spp + k; };
  engine::jobs::parallel_for(0, height, 4, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < width; ++x)
        for (int k = 0; k < spp; ++k) {
          const glm::vec4& c = guide[at(x, y, k)];
          if (!(c.w > 0)) continue;
          glm::vec3 sum(0.0f);
          float weight = 0;
          for (int dy = -radius; dy <= radius; ++dy)
            for (int dx = -radius; dx <= radius; ++dx) {
              const int nx = x + dx, ny = y + dy;
              if (nx < 0 || ny < 0 || nx >= width || ny >= height) continue;
              for (int j = 0; j < spp; ++j) {
                const std::size_t i = at(nx, ny, j);
                const float w = guide_similarity(c, guide[i], kDepthTolerance, kNormalPower);
                if (!(w > 0)) continue;
                sum += w * values[i];
                weight += w;
              }
            }
          out[at(x, y, k)] = weight > 0 ? sum / weight : glm::vec3(0.0f);
        }
  });
  return out;
}

void filter_near_field_separable(std::span<const glm::vec4> guide, int width, int height, std::span<const glm::vec3> values,
                                 std::span<const std::uint8_t> valid, std::span<const std::uint8_t> wanted, int radius,
                                 std::vector<glm::vec4>& row, std::vector<glm::vec3>& out, std::vector<std::uint8_t>& estimated) {
  const std::size_t n = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  if (guide.size() != n || values.size() != n || valid.size() != n || wanted.size() != n)
    throw std::invalid_argument("filter_near_field_separable: guide, values, valid and wanted must hold width x height entries");
  // Rows with no valid pixel contribute nothing to the vertical pass.
  std::vector<std::uint8_t> row_has(static_cast<std::size_t>(height), 0);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width && !row_has[static_cast<std::size_t>(y)]; ++x)
      row_has[static_cast<std::size_t>(y)] = valid[static_cast<std::size_t>(y) * width + x];
  // A tent over the window, not a box: the sparse lattice's estimates then
  // blend into their neighbours' like a bilinear reconstruction instead of
  // each filling a square (a bright one-ray estimate showed as a block).
  // Every tap within the radius keeps a positive weight, so the pixels an
  // estimate reaches are the same.
  const auto tent = [&](int d) { return static_cast<float>(radius + 1 - std::abs(d)); };
  // Pass 1 keeps, per pixel, the weighted sum and weight along its row; pass
  // 2 sums those down the column, each tap weighted against the centre.
  // Only rows with a valid pixel are written, and only they are read.
  row.resize(n);
  out.resize(n);
  estimated.resize(n);
  engine::jobs::parallel_for(0, height, 8, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y) {
      if (!row_has[static_cast<std::size_t>(y)]) continue;
      for (int x = 0; x < width; ++x) {
        const std::size_t p = static_cast<std::size_t>(y) * width + x;
        const glm::vec4& c = guide[p];
        row[p] = glm::vec4(0.0f);
        if (!(c.w > 0)) continue;
        glm::vec4 acc(0.0f);
        for (int nx = std::max(0, x - radius); nx <= std::min(width - 1, x + radius); ++nx) {
          const std::size_t i = static_cast<std::size_t>(y) * width + nx;
          if (!valid[i]) continue;
          const float w = guide_similarity(c, guide[i], kDepthTolerance, kNormalPower) * tent(nx - x);
          if (w > 0) acc += glm::vec4(w * values[i], w);
        }
        row[p] = acc;
      }
    }
  });
  engine::jobs::parallel_for(0, height, 8, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < width; ++x) {
        const std::size_t p = static_cast<std::size_t>(y) * width + x;
        const glm::vec4& c = guide[p];
        out[p] = glm::vec3(0.0f);
        estimated[p] = 0;
        if (!wanted[p] || !(c.w > 0)) continue;
        glm::vec4 acc(0.0f);
        for (int ny = std::max(0, y - radius); ny <= std::min(height - 1, y + radius); ++ny) {
          if (!row_has[static_cast<std::size_t>(ny)]) continue;
          const std::size_t i = static_cast<std::size_t>(ny) * width + x;
          if (!(row[i].w > 0)) continue;
          const float w = guide_similarity(c, guide[i], kDepthTolerance, kNormalPower) * tent(ny - y);
          if (w > 0) acc += w * row[i];
        }
        if (acc.w > 0) {
          out[p] = glm::vec3(acc) / acc.w;
          estimated[p] = 1;
        }
      }
  });
}

}  // namespace transgi::shading
