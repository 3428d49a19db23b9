#include "shading/realtime_reflections.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cmath>
#include <limits>

#include "engine/jobs/parallel_for.h"
#include "engine/material/specular_albedo.h"
#include "engine/math/rng.h"
#include "probes/cascades.h"
#include "shading/sh_light.h"

namespace transgi::shading {

// The directional albedo of a dielectric's specular layer towards the
// viewer, per channel: the mean weight of its reflection rays.
glm::vec3 specular_layer_albedo(const GSample& s) {
  using namespace engine::material;
  const float cos_o = std::clamp(glm::dot(s.normal_world, s.wo_world), 0.0f, 1.0f);
  const SpecularAlbedo e = ggx_albedo(cos_o, std::max(s.brdf.roughness * s.brdf.roughness, kMinAlpha));
  const glm::vec3 f0 = glm::min(kDielectricF0 * s.brdf.specular_color, glm::vec3(1.0f));
  return s.brdf.specular * glm::vec3(e.with_f0(f0.r), e.with_f0(f0.g), e.with_f0(f0.b));
}

void ReflectionHistory::begin(const GBuffer& g) {
  const Frame& prev = frames_[current_ ^ 1];
  has_prev_ = prev.camera && g.camera && prev.width == g.width && prev.height == g.height;
  Frame& next = frames_[current_];
  next.width = g.width;
  next.height = g.height;
  next.jitter = g.jitter;
  next.camera = g.camera;
  next.frames.assign(g.samples.size(), 0);
  next.position.resize(g.samples.size());
  next.direct.resize(g.samples.size());
  next.gi.resize(g.samples.size());
  spread_ = g.camera ? g.camera->pixel_spread() : 0.0f;
}

void ReflectionHistory::blend(const GBuffer& g, std::size_t p, glm::vec3& direct, glm::vec3& gi) {
  const Frame& prev = frames_[current_ ^ 1];
  Frame& next = frames_[current_];
  const glm::vec3& position = g.position[p];
  std::uint8_t frames = 1;
  if (has_prev_) {
    if (const std::optional<glm::vec2> film = prev.camera->project(position)) {
      const int px = static_cast<int>(std::lround(film->x - 0.5f - prev.jitter.x));
      const int py = static_cast<int>(std::lround(film->y - 0.5f - prev.jitter.y));
      if (px >= 0 && py >= 0 && px < prev.width && py < prev.height) {
        const std::size_t q = static_cast<std::size_t>(py) * static_cast<std::size_t>(prev.width) + static_cast<std::size_t>(px);
        const float reach = 3.0f * spread_ * g.guide[p].w;
        const glm::vec3 d = prev.position[q] - position;
        if (prev.frames[q] > 0 && glm::dot(d, d) < reach * reach) {
          frames = static_cast<std::uint8_t>(std::min<int>(prev.frames[q] + 1, kFrames));
          const float a = 1.0f / static_cast<float>(frames);
          direct = prev.direct[q] + a * (direct - prev.direct[q]);
          gi = prev.gi[q] + a * (gi - prev.gi[q]);
        }
      }
    }
  }
  next.frames[p] = frames;
  next.position[p] = position;
  next.direct[p] = direct;
  next.gi[p] = gi;
}

namespace {

// The light of the punctual lights at a reflection ray's hit: a shadow ray
// to each (none without lights).
glm::vec3 punctual_irradiance(const engine::rt::RtScene& scene, const engine::render::LightSet* lights, const engine::render::Surface& hit) {
  using namespace engine;
  glm::vec3 irradiance(0.0f);
  if (!lights) return irradiance;
  const glm::vec3 origin = rt::offset_ray_origin(hit.position, hit.geometric_normal, scene.offset_scale());
  for (std::size_t l = 0; l < lights->punctual_count(); ++l) {
    render::LightSample ls;
    if (!lights->sample_punctual(l, hit.position, glm::vec2(0.5f), ls) || glm::dot(ls.direction, hit.geometric_normal) <= 0) continue;
    const float cos_i = glm::dot(ls.direction, hit.shading_normal);
    if (cos_i <= 0) continue;
    const float tmax = std::isinf(ls.distance) ? std::numeric_limits<float>::infinity() : ls.distance * (1.0f - 1e-4f);
    if (!scene.occluded(rt::Ray{origin, ls.direction, 0.0f, tmax})) irradiance += ls.radiance * cos_i;
  }
  return irradiance;
}

// The antialiasing's jitter phase as a number: the stream a reflection's
// random choices follow, so each of the resolve's points sees other rays and
// it averages them; no seed.
std::uint64_t jitter_phase(const GBuffer& g) {
  return static_cast<std::uint64_t>(std::bit_cast<std::uint32_t>(g.jitter.x)) << 32 | std::bit_cast<std::uint32_t>(g.jitter.y);
}


// Where two G-buffer pixels lie on one surface, for the reflection filter:
// q within 2 % of p's depth of p's tangent plane and its normal within about
// 25 degrees. The weight falls to 0 at those limits.
float same_plane_weight(const GBuffer& g, std::size_t p, std::size_t q) {
  const glm::vec3 n = glm::vec3(g.guide[p]);
  const float plane = glm::dot(n, g.position[q] - g.position[p]) / (0.02f * g.guide[p].w);
  const float cos_n = glm::dot(n, glm::vec3(g.guide[q]));
  if (!(plane * plane < 1.0f) || cos_n < 0.9f) return 0.0f;
  return (1.0f - plane * plane) * (cos_n - 0.9f) * 10.0f;
}

// The glossy dielectric pixels (the tiles whose least roughness says they
// may hold one) and their rays' pixels, directions and weights: row of
// tiles by row in parallel, then joined in row order, so the lists are the
// same whatever the thread count. See trace_dielectric_rays for which
// pixels trace.
void choose_dielectric_rays(const GBuffer& g, float max_roughness, DielectricRays& rays) {
  using namespace engine;
  const std::uint64_t phase = jitter_phase(g);
  const int ox = g.jitter.x >= 0 ? 1 : 0, oy = g.jitter.y >= 0 ? 1 : 0;
  const std::size_t width = static_cast<std::size_t>(g.width);
  const int bw = (g.width + 1) / 2, bh = (g.height + 1) / 2;
  if (bw != rays.bw || bh != rays.bh) {
    rays.bw = bw;
    rays.bh = bh;
    rays.ray_of_block.assign(static_cast<std::size_t>(bw) * bh, kNoRay);
  } else {
    for (const std::size_t blk : rays.traced) rays.ray_of_block[blk] = kNoRay;  // the last frame's
  }
  const int tiles_x = (g.width + 3) / 4, tiles_y = (g.height + 3) / 4;
  rays.rows.resize(static_cast<std::size_t>(tiles_y));
  jobs::parallel_for(0, tiles_y, 4, [&](int r0, int r1) {
    for (int row = r0; row < r1; ++row) {
      DielectricRays::Row& out = rays.rows[static_cast<std::size_t>(row)];
      out.glossy.clear();
      out.glossy_albedo.clear();
      out.ray_pixel.clear();
      out.direction.clear();
      out.weight.clear();
      for (int tile = 0; tile < tiles_x; ++tile) {
        if (!(g.tile_dielectric_roughness[static_cast<std::size_t>(row) * tiles_x + tile] <= max_roughness)) continue;
        for (int y = row * 4; y < std::min(row * 4 + 4, g.height); ++y)
          for (int x = tile * 4; x < std::min(tile * 4 + 4, g.width); ++x) {
            const std::size_t p = static_cast<std::size_t>(y) * width + static_cast<std::size_t>(x);
            if (!(g.dielectric_roughness[p] <= max_roughness)) continue;
            const GSample& s = g.samples[p];
            const glm::vec3 albedo = specular_layer_albedo(s);
            out.glossy.push_back(p);
            out.glossy_albedo.push_back(albedo);
            if (x % 2 != ox || y % 2 != oy) continue;
            math::Pcg32 rng = math::make_rng(0xD1E1ull, p, phase);
            glm::vec3 wi, weight;
            if (!sample_reflection(s, false, {rng.next_float(), rng.next_float()}, wi, weight)) continue;
            out.ray_pixel.push_back(p);
            out.direction.push_back(wi);
            out.weight.push_back(weight / glm::max(albedo, glm::vec3(1e-6f)));
          }
      }
    }
  });
  rays.glossy.clear();
  rays.glossy_albedo.clear();
  rays.traced.clear();
  rays.ray_x.clear();
  rays.ray_y.clear();
  rays.ray_pixel.clear();
  rays.direction.clear();
  rays.weight.clear();
  for (const DielectricRays::Row& row : rays.rows) {
    rays.glossy.insert(rays.glossy.end(), row.glossy.begin(), row.glossy.end());
    rays.glossy_albedo.insert(rays.glossy_albedo.end(), row.glossy_albedo.begin(), row.glossy_albedo.end());
    for (const std::size_t p : row.ray_pixel) {
      rays.ray_of_block[rays.block_of(p, width)] = static_cast<std::uint32_t>(rays.traced.size());
      rays.traced.push_back(rays.block_of(p, width));
      rays.ray_x.push_back(static_cast<int>(p % width));
      rays.ray_y.push_back(static_cast<int>(p / width));
    }
    rays.ray_pixel.insert(rays.ray_pixel.end(), row.ray_pixel.begin(), row.ray_pixel.end());
    rays.direction.insert(rays.direction.end(), row.direction.begin(), row.direction.end());
    rays.weight.insert(rays.weight.end(), row.weight.begin(), row.weight.end());
  }
}

// Up to 16 reflection rays from G-buffer pixels at once: what
// reflected_light gives each (light[i]), with one Embree packet for the rays
// (a surface's neighbouring rays run alike) and the hits lit by the probes
// in one batch (probes::interpolate_fields_many) and by a shadow ray to each
// punctual light.
constexpr int kPacket = 16;
struct ReflectionPacket {
  std::array<ReflectedLight, kPacket> light;

  void reflect(const GBuffer& g, const engine::rt::RtScene& scene, std::span<const probes::ProbeField* const> fields,
               const engine::render::LightSet* lights, const std::size_t* pixel, const glm::vec3* direction, int n) {
    using namespace engine;
    const scene::Environment* sky = lights ? lights->environment() : nullptr;
    int lanes = 0;
    for (int k = 0; k < n; ++k) {
      light[static_cast<std::size_t>(k)] = {};
      if (reflection_ray(scene, g.samples[pixel[k]], direction[k], rays_[static_cast<std::size_t>(lanes)]))
        ray_of_[static_cast<std::size_t>(lanes++)] = k;
    }
    scene.intersect16(rays_.data(), lanes, hits_.data(), found_);
    std::size_t count = 0;
    for (int i = 0; i < lanes; ++i) {
      const int k = ray_of_[static_cast<std::size_t>(i)];
      if (!found_[i]) {
        light[static_cast<std::size_t>(k)] = *reflected_without_irradiance(nullptr, direction[k], sky);
        continue;
      }
      surface_[count] = render::make_surface(scene, hits_[static_cast<std::size_t>(i)], direction[k]);
      if (surface_[count].brdf.metallic >= 0.5f) {
        light[static_cast<std::size_t>(k)] = {glm::vec3(0.0f), metal_bounce(g, scene, fields, lights, surface_[count], direction[k], pixel[k])};
        continue;
      }
      if (const std::optional<ReflectedLight> r = reflected_without_irradiance(&surface_[count], direction[k], sky)) {
        light[static_cast<std::size_t>(k)] = *r;
        continue;
      }
      position_[count] = surface_[count].position;
      normal_[count] = surface_[count].shading_normal;
      lit_[count++] = k;
    }
    probes::interpolate_fields_many(
        fields, position_.data(), normal_.data(), count, [](std::size_t, const probes::ProbeField* f) { return f->light_sh_all().data(); },
        [](std::size_t, const probes::ProbeField* f) { return f->direct_sh_all().data(); }, sh_, sh_direct_);
    for (std::size_t j = 0; j < count; ++j) {
      const render::Surface& hit = surface_[j];
      const glm::vec3 irradiance = sh_irradiance(sh_ + j * 75, hit.shading_normal) + sh_irradiance(sh_direct_ + j * 75, hit.shading_normal) +
                                   punctual_irradiance(scene, lights, hit);
      light[static_cast<std::size_t>(lit_[j])].gi = reflected_gi(hit, direction[lit_[j]], irradiance);
    }
  }

 private:
  // A metal met by a reflection ray reflects what its own reflection ray
  // finds, one bounce further (reflected_light: the sky or an emitter as
  // they are, a surface lit as the packet's hits are), times the metal's
  // weight. All of it is GI at the pixel: it reached the pixel's surface
  // after the metal's bounce.
  static glm::vec3 metal_bounce(const GBuffer& g, const engine::rt::RtScene& scene, std::span<const probes::ProbeField* const> fields,
                                const engine::render::LightSet* lights, const engine::render::Surface& metal, const glm::vec3& wi,
                                std::size_t pixel) {
    using namespace engine;
    GSample at;
    at.hit = true;
    at.position = metal.position;
    at.normal_world = metal.shading_normal;
    at.geometric_normal = metal.geometric_normal;
    at.wo_world = -wi;
    at.brdf = metal.brdf;
    math::Pcg32 rng = math::make_rng(0x3E7A1ull, pixel, jitter_phase(g));
    glm::vec3 wi2, weight;
    if (!sample_reflection(at, false, {rng.next_float(), rng.next_float()}, wi2, weight)) return glm::vec3(0.0f);
    const HitIrradiance irradiance = [&](const render::Surface& s) {
      float sh[75], sh_direct[75];
      probes::interpolate_fields_many(
          fields, &s.position, &s.shading_normal, 1, [](std::size_t, const probes::ProbeField* f) { return f->light_sh_all().data(); },
          [](std::size_t, const probes::ProbeField* f) { return f->direct_sh_all().data(); }, sh, sh_direct);
      return sh_irradiance(sh, s.shading_normal) + sh_irradiance(sh_direct, s.shading_normal) + punctual_irradiance(scene, lights, s);
    };
    const ReflectedLight r = reflected_light(scene, at, wi2, lights ? lights->environment() : nullptr, irradiance);
    return weight * (r.direct + r.gi);
  }

  std::array<engine::rt::Ray, kPacket> rays_;
  std::array<engine::rt::Hit, kPacket> hits_;
  bool found_[kPacket] = {};
  std::array<int, kPacket> ray_of_{}, lit_{};  // lane -> ray; lit hit -> ray
  std::array<engine::render::Surface, kPacket> surface_;
  std::array<glm::vec3, kPacket> position_, normal_;
  float sh_[kPacket * 75], sh_direct_[kPacket * 75];
};

// Traces the rays choose_dielectric_rays picked: one per 2x2 block, from
// its pixel on the jitter's side of the centre, so the antialiasing's phases
// visit the four in turn; none where that pixel is no glossy dielectric or
// its sample falls below the surface. Each ray keeps its weight (F G1) and
// its weighted light, both over its pixel's specular albedo E: the filter
// divides the one sum by the other (a ratio estimator), so light the same
// in every direction comes out exactly E L, without the noise of the
// Fresnel's spread between samples (a plain mean of the weighted light) and
// keeping the Fresnel's correlation with where the light is (which a
// split-sum mean of the light alone loses; docs/image-quality.md).
void trace_dielectric_rays(const GBuffer& g, const engine::rt::RtScene& scene, std::span<const probes::ProbeField* const> fields,
                           const engine::render::LightSet* lights, DielectricRays& rays) {
  using namespace engine;
  const std::size_t n = rays.traced.size();
  rays.direct.resize(n);
  rays.gi.resize(n);
  const std::size_t packets = (n + kPacket - 1) / kPacket;
  jobs::parallel_for<std::size_t>(0, packets, 4, [&](std::size_t b, std::size_t e) {
    ReflectionPacket packet;
    for (std::size_t pk = b; pk < e; ++pk) {
      const std::size_t k0 = pk * kPacket, k1 = std::min(n, k0 + kPacket);
      packet.reflect(g, scene, fields, lights, rays.ray_pixel.data() + k0, rays.direction.data() + k0, static_cast<int>(k1 - k0));
      for (std::size_t k = k0; k < k1; ++k) {
        rays.direct[k] = rays.weight[k] * packet.light[k - k0].direct;
        rays.gi[k] = rays.weight[k] * packet.light[k - k0].gi;
      }
    }
  });
}

// Per ray: the light of the rays within kReach blocks on its plane, the sum
// of their weighted light over the sum of their weights, each Gaussian in
// their pixels' distance; a sharper lobe gathers from nearer rays (its
// reflection changes faster across the surface). At kSigma a ray 3 blocks
// away weighs exp(-2.88), about 6 %, of the ray's own: 2 blocks reach far enough.
void gather_rays(const GBuffer& g, DielectricRays& rays) {
  constexpr int kReach = 2;
  constexpr float kSigma = 2.5f;  // pixels, at roughness 0.4 and above
  const std::size_t width = static_cast<std::size_t>(g.width);
  rays.mean_direct.resize(rays.traced.size());
  rays.mean_gi.resize(rays.traced.size());
  rays.has_mean.resize(rays.traced.size());
  engine::jobs::parallel_for<std::size_t>(0, rays.traced.size(), 256, [&](std::size_t b, std::size_t e) {
    for (std::size_t k = b; k < e; ++k) {
      const std::size_t p = rays.ray_pixel[k];
      const float sigma = kSigma * std::clamp(g.dielectric_roughness[p] / 0.4f, 0.25f, 1.0f);
      const float inv_2s2 = 0.5f / (sigma * sigma);
      const int x = static_cast<int>(p % width), y = static_cast<int>(p / width);
      const int bx0 = x / 2, by0 = y / 2;
      // Every ray leaves its block's pixel on the same side (the jitter's),
      // so rays lie whole blocks apart, 2 pixels each: the Gaussian is a
      // product of one table per axis, not an exp per neighbour.
      std::array<float, kReach + 1> gauss{};
      for (int d = 0; d <= kReach; ++d) gauss[static_cast<std::size_t>(d)] = std::exp(-static_cast<float>(4 * d * d) * inv_2s2);
      glm::vec3 sum_direct(0.0f), sum_gi(0.0f), sum_weight(0.0f);
      for (int by = std::max(0, by0 - kReach); by <= std::min(rays.bh - 1, by0 + kReach); ++by)
        for (int bx = std::max(0, bx0 - kReach); bx <= std::min(rays.bw - 1, bx0 + kReach); ++bx) {
          const std::uint32_t j = rays.ray_of_block[static_cast<std::size_t>(by) * rays.bw + bx];
          if (j == kNoRay) continue;
          const std::size_t q = rays.ray_pixel[j];
          const float w = same_plane_weight(g, p, q) * gauss[static_cast<std::size_t>(std::abs(bx - bx0))] *
                          gauss[static_cast<std::size_t>(std::abs(by - by0))];
          sum_direct += w * rays.direct[j];
          sum_gi += w * rays.gi[j];
          sum_weight += w * rays.weight[j];
        }
      const bool some = sum_weight.r > 0 && sum_weight.g > 0 && sum_weight.b > 0;
      rays.has_mean[k] = some;
      rays.mean_direct[k] = some ? sum_direct / sum_weight : glm::vec3(0.0f);
      rays.mean_gi[k] = some ? sum_gi / sum_weight : glm::vec3(0.0f);
    }
  });
}

}  // namespace

// Metals' reflections at full resolution (transfer_renderer.h's MirrorRay):
// a metal's whole light, replacing its decoded GI (its direct light was left
// out of the composite); the sky and emitters its ray sees go to direct_out.
std::size_t shade_metal_reflections(const GBuffer& g, const engine::rt::RtScene& scene,
                                   std::span<const probes::ProbeField* const> fields, const MirrorRay& mirror,
                                   const engine::render::LightSet* lights, engine::image::ImageRGB& image,
                                   engine::image::ImageRGB* direct_out) {
  using namespace engine;
  const float metal_roughness = std::max(mirror.max_roughness, mirror.glossy_max_roughness);
  const std::uint64_t phase = jitter_phase(g);
  std::atomic<std::size_t> traced{0};
  jobs::parallel_for<std::size_t>(0, g.samples.size(), 1024, [&](std::size_t b, std::size_t e) {
    ReflectionPacket packet;
    std::array<std::size_t, kPacket> pixel;
    std::array<glm::vec3, kPacket> direction, weight;
    int lanes = 0;
    std::size_t n = 0;
    // A packet's pixels' light, times each one's weight; no history here,
    // unlike the glossy dielectrics': on the sample level's gold sphere a
    // running mean smeared its glints over neighbouring points while the
    // camera walked (docs/image-quality.md).
    const auto flush = [&] {
      packet.reflect(g, scene, fields, lights, pixel.data(), direction.data(), lanes);
      for (int i = 0; i < lanes; ++i) {
        const std::size_t p = pixel[static_cast<std::size_t>(i)];
        image.pixels[p] = weight[static_cast<std::size_t>(i)] * packet.light[static_cast<std::size_t>(i)].gi;
        if (direct_out) direct_out->pixels[p] += weight[static_cast<std::size_t>(i)] * packet.light[static_cast<std::size_t>(i)].direct;
      }
      lanes = 0;
    };
    for (std::size_t p = b; p < e; ++p) {
      // metal_roughness <= max_roughness is is_mirror() on the pixel's material.
      if (!(g.metal_roughness[p] <= metal_roughness)) continue;
      ++n;
      const bool mirror_direction = g.metal_roughness[p] <= mirror.max_roughness;
      math::Pcg32 rng = math::make_rng(0x6105ull, p, phase);
      const glm::vec2 u{rng.next_float(), rng.next_float()};
      glm::vec3 wi(0.0f, 0.0f, 1.0f), w(0.0f);
      if (!sample_reflection(g.samples[p], mirror_direction, u, wi, w)) {
        image.pixels[p] = glm::vec3(0.0f);  // no ray: black, as a zero weight gives
        continue;
      }
      pixel[static_cast<std::size_t>(lanes)] = p;
      direction[static_cast<std::size_t>(lanes)] = wi;
      weight[static_cast<std::size_t>(lanes++)] = w;
      if (lanes == kPacket) flush();
    }
    if (lanes > 0) flush();
    traced.fetch_add(n, std::memory_order_relaxed);
  });
  return traced.load();
}

// Glossy dielectrics' specular layer (MirrorRay::dielectric_max_roughness),
// added to the diffuse light their cells were given. A floor can fill half
// the screen, so a quarter of its pixels trace a ray a frame
// (trace_dielectric_rays), each ray gathers its neighbours' (gather_rays),
// and every glossy pixel takes the rays' means around it on its own plane,
// times its own specular albedo; the antialiasing's 16 phases average the
// rest. Work in proportion to the glossy pixels, none without.
std::size_t shade_dielectric_reflections(const GBuffer& g, const engine::rt::RtScene& scene,
                                  std::span<const probes::ProbeField* const> fields, const engine::render::LightSet* lights,
                                  float max_roughness, DielectricRays& rays, engine::image::ImageRGB& image,
                                  engine::image::ImageRGB* direct_out) {
  // The glossy pixels, tile by tile: most tiles have none.
  choose_dielectric_rays(g, max_roughness, rays);
  if (rays.glossy.empty()) return 0;
  trace_dielectric_rays(g, scene, fields, lights, rays);
  gather_rays(g, rays);
  const std::size_t width = static_cast<std::size_t>(g.width);
  rays.history.begin(g);
  engine::jobs::parallel_for<std::size_t>(0, rays.glossy.size(), 1024, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      const std::size_t p = rays.glossy[i];
      const int x = static_cast<int>(p % width), y = static_cast<int>(p / width);
      const int bx0 = x / 2, by0 = y / 2;
      glm::vec3 sum_direct(0.0f), sum_gi(0.0f);
      float sum_w = 0;
      for (int by = std::max(0, by0 - 1); by <= std::min(rays.bh - 1, by0 + 1); ++by)
        for (int bx = std::max(0, bx0 - 1); bx <= std::min(rays.bw - 1, bx0 + 1); ++bx) {
          const std::uint32_t j = rays.ray_of_block[static_cast<std::size_t>(by) * rays.bw + bx];
          if (j == kNoRay || !rays.has_mean[j]) continue;
          const std::size_t q = rays.ray_pixel[j];
          // A tent over the blocks' spacing, so neighbouring pixels blend
          // between blocks instead of taking their own block's value.
          const float dx = std::abs(static_cast<float>(rays.ray_x[j] - x));
          const float dy = std::abs(static_cast<float>(rays.ray_y[j] - y));
          const float w = same_plane_weight(g, p, q) * std::max(0.0f, 1.0f - dx / 3.0f) * std::max(0.0f, 1.0f - dy / 3.0f);
          sum_direct += w * rays.mean_direct[j];
          sum_gi += w * rays.mean_gi[j];
          sum_w += w;
        }
      if (!(sum_w > 0)) continue;
      glm::vec3 light_direct = sum_direct / sum_w, light_gi = sum_gi / sum_w;
      rays.history.blend(g, p, light_direct, light_gi);
      const glm::vec3& albedo = rays.glossy_albedo[i];
      image.pixels[p] += albedo * light_gi;
      if (direct_out) direct_out->pixels[p] += albedo * light_direct;
    }
  });
  rays.history.end();
  return rays.traced.size();
}

}  // namespace transgi::shading
