#include "shading/realtime_direct.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <vector>
#include <cmath>

#include "engine/jobs/parallel_for.h"
#include "engine/math/sampling.h"

namespace transgi::shading {

glm::vec2 disk_pattern(int x, int y) {
  // Index in the 8x8 block in bit-reversed order, so neighbouring pixels
  // take far-apart points of the sequence.
  const unsigned i = static_cast<unsigned>((x & 7) | ((y & 7) << 3));
  unsigned r = 0;
  for (int b = 0; b < 6; ++b) r |= ((i >> b) & 1u) << (5 - b);
  const float a1 = 0.7548776662f, a2 = 0.5698402910f;  // R2: 1 / plastic number, its square
  const float k = static_cast<float>(r);
  return {std::fmod(0.5f + a1 * k, 1.0f), std::fmod(0.5f + a2 * k, 1.0f)};
}

DirectTileShader::DirectTileShader(const engine::rt::RtScene& scene, const engine::render::LightSet& lights,
                                   const engine::render::CameraRays& camera, int width, int height)
    : scene_(scene), lights_(lights), camera_(camera), out_(width, height), n_lights_(lights.punctual_count()) {
  using namespace engine;
  // A directional light's sample does not depend on the point: its 64
  // pattern directions are computed once per frame, not per pixel.
  directional_.resize(n_lights_);
  is_directional_.assign(n_lights_, 0);
  for (std::size_t l = 0; l < n_lights_; ++l) {
    if (lights.punctual_lights()[l].light.type != scene::PunctualLight::Type::Directional) continue;
    is_directional_[l] = 1;
    for (int i = 0; i < 64; ++i) lights.sample_punctual(l, glm::vec3(0.0f), disk_pattern(i & 7, i >> 3), directional_[l][static_cast<std::size_t>(i)]);
  }
}

void DirectTileShader::shade_tile(const GBuffer& g, int tx, int ty) {
  using namespace engine;
  rt::Ray rays[16];
  bool blocked[16];
  std::size_t pixel[16];
  const GSample* samples[16];
  std::array<glm::vec3, 2> local[16];  // wo, wi in the shading frame
  glm::vec3 light[16];
  std::size_t traced = 0;
  const scene::Environment* background = lights_.background();
  const std::size_t tile = static_cast<std::size_t>(ty / 4) * static_cast<std::size_t>((g.width + 3) / 4) + static_cast<std::size_t>(tx / 4);
  const bool collecting = batch_.collect != nullptr;
  std::size_t answer = batch_.answers ? (*batch_.first)[tile] : 0;
  // Emission and background first.
  for (int y = ty; y < std::min(ty + 4, g.height); ++y)
    for (int x = tx; x < std::min(tx + 4, g.width); ++x) {
      const std::size_t p = static_cast<std::size_t>(y) * g.width + x;
      const GSample& s = g.samples[p];
      if (collecting) break;
      if (s.hit)
        out_.pixels[p] = s.emission;
      else if (background)
        out_.pixels[p] = background->radiance(camera_.generate({static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f}).direction);
    }
  for (std::size_t l = 0; l < n_lights_; ++l) {
    int n = 0;
    for (int y = ty; y < std::min(ty + 4, g.height); ++y)
      for (int x = tx; x < std::min(tx + 4, g.width); ++x) {
        const std::size_t p = static_cast<std::size_t>(y) * g.width + x;
        const GSample& s = g.samples[p];
        if (!s.hit) continue;
        render::LightSample ls;
        if (is_directional_[l])
          ls = directional_[l][static_cast<std::size_t>((x & 7) | ((y & 7) << 3))];
        else if (!lights_.sample_punctual(l, s.position, disk_pattern(x, y), ls))
          continue;
        if (glm::dot(ls.direction, s.geometric_normal) <= 0) continue;
        const math::Frame frame = math::Frame::from_normal(s.normal_world);
        const glm::vec3 wo = frame.to_local(s.wo_world), wi = frame.to_local(ls.direction);
        if (wo.z <= 0 || wi.z <= 0 || ls.radiance == glm::vec3(0.0f)) continue;
        const float tmax = std::isinf(ls.distance) ? std::numeric_limits<float>::infinity() : ls.distance * (1.0f - 1e-4f);
        rays[n] = rt::Ray{rt::offset_ray_origin(s.position, s.geometric_normal, scene_.offset_scale()), ls.direction, 0.0f, tmax};
        pixel[n] = p;
        samples[n] = &s;
        local[n] = {wo, wi};
        light[n] = ls.radiance;
        ++n;
      }
    if (n == 0) continue;
    if (collecting) {
      (*batch_.collect)[tile].insert((*batch_.collect)[tile].end(), rays, rays + n);
      continue;
    }
    if (batch_.answers) {
      for (int i = 0; i < n; ++i) blocked[i] = (*batch_.answers)[answer++] != 0;
    } else {
      scene_.occluded16(rays, n, blocked);
    }
    traced += static_cast<std::size_t>(n);
    // The BRDF only where the light arrives: most of a room's pixels that face
    // the sun are in shadow.
    for (int i = 0; i < n; ++i) {
      if (blocked[i]) continue;
      const glm::vec3 c = material::brdf_eval(samples[i]->brdf, local[i][0], local[i][1]) * local[i][1].z * light[i];
      if (c.r > 0 || c.g > 0 || c.b > 0) out_.pixels[pixel[i]] += c;
    }
  }
  if (collecting) return;
  // The pass's boundary: an infinite emitter or light leaves no non-finite pixel.
  std::size_t bad = 0;
  for (int y = ty; y < std::min(ty + 4, g.height); ++y)
    for (int x = tx; x < std::min(tx + 4, g.width); ++x) {
      glm::vec3& v = out_.pixels[static_cast<std::size_t>(y) * g.width + x];
      if (std::isfinite(v.r) && std::isfinite(v.g) && std::isfinite(v.b)) continue;
      v = glm::vec3(0.0f);
      ++bad;
    }
  if (bad) nonfinite_.fetch_add(bad, std::memory_order_relaxed);
  rays_traced_.fetch_add(traced, std::memory_order_relaxed);
}

engine::image::ImageRGB DirectTileShader::take(RealtimeDirectStats* stats) {
  if (stats) {
    stats->shadow_rays = rays_traced_.load();
    stats->lights = n_lights_;
    stats->nonfinite_pixels = nonfinite_.load();
  }
  return std::move(out_);
}

engine::image::ImageRGB shade_direct_realtime(const GBuffer& g, const engine::rt::RtScene& scene,
                                              const engine::render::LightSet& lights,
                                              const engine::render::CameraRays& camera, RealtimeDirectStats* stats,
                                              engine::rt::RayBatchTracer* tracer) {
  DirectTileShader shader(scene, lights, camera, g.width, g.height);
  const int tiles_x = (g.width + 3) / 4, tiles_y = (g.height + 3) / 4;
  auto each_tile = [&] {
    engine::jobs::parallel_for(0, tiles_x * tiles_y, 16, [&](int t0, int t1) {
      for (int t = t0; t < t1; ++t) shader.shade_tile(g, t % tiles_x * 4, t / tiles_x * 4);
    });
  };
  // The shader reads `blocked` and `first` in the second pass: they live
  // as long as the function.
  std::vector<engine::rt::Ray> rays;
  std::vector<std::size_t> first;
  std::vector<std::uint8_t> blocked;
  if (tracer) {
    std::vector<std::vector<engine::rt::Ray>> per_tile(static_cast<std::size_t>(tiles_x) * tiles_y);
    shader.set_batch({&per_tile, nullptr, nullptr});
    each_tile();
    first.resize(per_tile.size());
    std::size_t count = 0;
    for (std::size_t t = 0; t < per_tile.size(); ++t) {
      first[t] = count;
      count += per_tile[t].size();
    }
    rays.resize(count);
    engine::jobs::parallel_for<std::size_t>(0, per_tile.size(), 256, [&](std::size_t b, std::size_t e) {
      for (std::size_t t = b; t < e; ++t) std::copy(per_tile[t].begin(), per_tile[t].end(), rays.begin() + static_cast<std::ptrdiff_t>(first[t]));
    });
    blocked.resize(rays.size());
    if (!tracer->occluded(scene, rays, blocked))
      engine::jobs::parallel_for<std::size_t>(0, rays.size(), 256, [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) blocked[i] = scene.occluded(rays[i]) ? 1 : 0;
      });
    shader.set_batch({nullptr, &blocked, &first});
  }
  each_tile();
  return shader.take(stats);
}

void add_image(engine::image::ImageRGB& to, const engine::image::ImageRGB& from) {
  engine::jobs::parallel_for<std::size_t>(0, to.size(), 16384, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) to.pixels[i] += from.pixels[i];
  });
}

}  // namespace transgi::shading
