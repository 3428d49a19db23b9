#include "ddgi/ddgi_renderer.h"

#include <algorithm>
#include <limits>

#include "engine/gpu/gpu_error.h"
#include "engine/jobs/parallel_for.h"
#include "engine/material/brdf.h"
#include "engine/math/rng.h"
#include "engine/math/sampling.h"
#include "engine/render/surface.h"
#include "probes/cascades.h"

namespace transgi::ddgi {

namespace {

// What a surface reflects of irradiance known about two directions, each
// weight / pi: its diffuse lobe takes the irradiance about its normal, its
// glossy lobes (a dielectric's specular layer, a metal) the irradiance about
// its mirror direction, a blurred reflection (engines use reflection probes
// there; DDGI has none). Together they reflect the surface's directional
// albedo: a varnished floor's layer and a metal reflect the room, where the
// diffuse albedo alone leaves them out. `with_metal` false leaves the metal
// lobe out (the real-time path reflects a marked metal at its own pixel).
struct LobeWeights {
  glm::vec3 about_normal{0.0f}, about_mirror{0.0f};
};
LobeWeights lobe_weights(const engine::material::BrdfParams& brdf, const glm::vec3& diffuse, float cos_o, bool with_metal = true) {
  using namespace engine;
  // (Each albedo is a table lookup; a lobe that weighs nothing skips it.)
  const glm::vec3 layer = brdf.metallic < 1.0f ? (1.0f - brdf.metallic) * material::dielectric_layer_albedo(brdf, cos_o) : glm::vec3(0.0f);
  const glm::vec3 metal = with_metal && brdf.metallic > 0.0f ? brdf.metallic * material::metal_albedo(brdf, cos_o) : glm::vec3(0.0f);
  return {diffuse * (glm::vec3(1.0f) - layer) * math::kInvPi, (layer + metal) * math::kInvPi};
}

// The volumes' irradiance at p, blended as mix_at says; a volume with no
// active probe weighing in hands its weight to the next holding p.
// lookup(volume, &lit) is that volume's DdgiVolume::irradiance at the point.
// The value may be a glm::vec3 or several (a glm::mat2x3 of indirect and
// emitted irradiance).
template <class Lookup>
auto mixed_irradiance(std::span<const DdgiVolume* const> volumes, const glm::vec3& p, Lookup&& lookup) {
  using Value = decltype(lookup(volumes[0], nullptr));
  const probes::FieldMixOf<DdgiVolume> m = probes::mix_at(volumes, p);
  const DdgiVolume* first = m.field[0];
  bool lit = false;
  Value e = lookup(first, &lit);
  while (!lit) {
    first = probes::next_holding(volumes, first, p);
    if (!first) return Value(0.0f);
    e = lookup(first, &lit);
  }
  if (m.count == 1 || first != m.field[0]) return e;
  bool second_lit = false;
  const Value e2 = lookup(m.field[1], &second_lit);
  return second_lit ? m.weight[0] * e + m.weight[1] * e2 : e;
}

}  // namespace

glm::vec3 irradiance_from(std::span<const DdgiVolume* const> volumes, const glm::vec3& p, const glm::vec3& n, const glm::vec3& v) {
  return mixed_irradiance(volumes, p, [&](const DdgiVolume* volume, bool* lit) { return volume->irradiance(p, n, v, lit); });
}

glm::mat2x3 irradiance_and_emitted_from(std::span<const DdgiVolume* const> volumes, const glm::vec3& p, const glm::vec3& n,
                                        const glm::vec3& v) {
  return mixed_irradiance(volumes, p, [&](const DdgiVolume* volume, bool* is_lit) {
    glm::mat2x3 both(0.0f);
    both[0] = volume->irradiance(p, n, v, is_lit, &both[1]);
    return both;
  });
}

void mix_volume_batches(std::span<const DdgiVolume* const> volumes, std::span<const glm::vec3> positions,
                        const std::vector<std::vector<glm::mat2x3>>& value, const std::vector<std::vector<std::uint8_t>>& lit,
                        std::span<glm::mat2x3> out) {
  engine::jobs::parallel_for<std::size_t>(0, positions.size(), 256, [&](std::size_t b, std::size_t end) {
    for (std::size_t k = b; k < end; ++k)
      out[k] = mixed_irradiance(volumes, positions[k], [&](const DdgiVolume* volume, bool* is_lit) {
        const auto v = static_cast<std::size_t>(std::find(volumes.begin(), volumes.end(), volume) - volumes.begin());
        *is_lit = lit[v][k] != 0;
        return value[v][k];
      });
  });
}

engine::image::ImageRGB render_ddgi_gi_batched(const engine::rt::RtScene& scene, std::span<const DdgiVolume* const> volumes,
                                               const engine::render::CameraRays& camera, int width, int height,
                                               const DdgiRenderSettings& s, engine::rt::RayBatchTracer& tracer,
                                               DdgiKernels& kernels) {
  using namespace engine;
  image::ImageRGB img(width, height);
  if (volumes.empty()) return img;
  const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height), spp = static_cast<std::size_t>(s.spp);
  std::vector<rt::Ray> rays(pixels * spp);
  jobs::parallel_for<std::size_t>(0, pixels, 256, [&](std::size_t b, std::size_t e) {
    for (std::size_t pixel = b; pixel < e; ++pixel)
      for (std::size_t si = 0; si < spp; ++si) {
        math::Pcg32 rng = math::make_rng(s.seed, pixel, si);
        const glm::vec2 u{rng.next_float(), rng.next_float()};
        rays[pixel * spp + si] = camera.generate_filtered(static_cast<int>(pixel % static_cast<std::size_t>(width)),
                                                          static_cast<int>(pixel / static_cast<std::size_t>(width)), u, s.filter_width);
      }
  });
  std::vector<rt::Hit> hits(rays.size());
  std::vector<std::uint8_t> found(rays.size());
  tracer.intersect(scene, rays, hits, found);
  // Two lookups a sample: about its normal (2k), about its mirror direction (2k + 1).
  std::vector<glm::vec3> position(2 * rays.size()), normal(2 * rays.size()), view(2 * rays.size());
  std::vector<LobeWeights> weights(rays.size());
  jobs::parallel_for<std::size_t>(0, rays.size(), 256, [&](std::size_t b, std::size_t e) {
    for (std::size_t k = b; k < e; ++k) {
      if (!found[k]) continue;
      const render::Surface surf = render::make_surface(scene, hits[k], rays[k].direction);
      const glm::vec3 wo = -rays[k].direction;
      position[2 * k] = position[2 * k + 1] = surf.position;
      normal[2 * k] = surf.shading_normal;
      normal[2 * k + 1] = glm::reflect(rays[k].direction, surf.shading_normal);
      view[2 * k] = view[2 * k + 1] = rays[k].direction;
      weights[k] = lobe_weights(surf.brdf, material::diffuse_albedo(surf.brdf), glm::dot(surf.shading_normal, wo));
    }
  });
  std::vector<glm::mat2x3> e(position.size());
  kernels.irradiance(volumes, position, normal, view, e);
  for (std::size_t pixel = 0; pixel < pixels; ++pixel) {
    glm::vec3 sum(0.0f);
    for (std::size_t si = 0; si < spp; ++si) {
      const std::size_t k = pixel * spp + si;
      if (found[k]) sum += weights[k].about_normal * e[2 * k][0] + weights[k].about_mirror * e[2 * k + 1][0];
    }
    img.pixels[pixel] = sum / static_cast<float>(s.spp);
  }
  return img;
}

engine::image::ImageRGB render_ddgi_gi(const engine::rt::RtScene& scene, std::span<const DdgiVolume* const> volumes,
                                       const engine::render::CameraRays& camera, int width, int height,
                                       const DdgiRenderSettings& s) {
  using namespace engine;
  image::ImageRGB img(width, height);
  jobs::parallel_for(0, height, 1, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < width; ++x) {
        const std::size_t pixel = static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x);
        glm::vec3 sum(0.0f);
        for (int si = 0; si < s.spp; ++si) {
          math::Pcg32 rng = math::make_rng(s.seed, pixel, static_cast<std::uint64_t>(si));
          const glm::vec2 u{rng.next_float(), rng.next_float()};
          const rt::Ray ray = camera.generate_filtered(x, y, u, s.filter_width);
          rt::Hit hit;
          if (!scene.intersect(ray, hit)) continue;
          const render::Surface surf = render::make_surface(scene, hit, ray.direction);
          const LobeWeights w = lobe_weights(surf.brdf, material::diffuse_albedo(surf.brdf), glm::dot(surf.shading_normal, -ray.direction));
          sum += w.about_normal * irradiance_from(volumes, surf.position, surf.shading_normal, ray.direction);
          if (w.about_mirror != glm::vec3(0.0f))
            sum += w.about_mirror *
                   irradiance_from(volumes, surf.position, glm::reflect(ray.direction, surf.shading_normal), ray.direction);
        }
        img.pixels[pixel] = sum / static_cast<float>(s.spp);
      }
  });
  return img;
}

namespace {

// One irradiance lookup of shade_ddgi_gbuffer: at a G-buffer pixel's surface
// point, about `normal` (its own, or a metal's mirror direction).
struct Lookup {
  std::size_t pixel = 0;
  glm::vec3 normal{0.0f};
};

// Every lookup's indirect irradiance (column 0) and emitted irradiance
// (column 1: DdgiSettings::emitted_maps, else 0) through the volumes, in one
// batch through the backend.
std::vector<glm::mat2x3> look_up(const shading::GBuffer& g, std::span<const Lookup> lookups,
                                 std::span<const DdgiVolume* const> volumes, DdgiKernels& kernels) {
  std::vector<glm::vec3> positions(lookups.size()), normals(lookups.size()), views(lookups.size());
  for (std::size_t k = 0; k < lookups.size(); ++k) {
    positions[k] = g.samples[lookups[k].pixel].position;
    normals[k] = lookups[k].normal;
    views[k] = -g.samples[lookups[k].pixel].wo_world;
  }
  std::vector<glm::mat2x3> e(lookups.size(), glm::mat2x3(0.0f));
  kernels.irradiance(volumes, positions, normals, views, e);
  return e;
}

// A metal's specular albedo (GGX with Schlick's Fresnel) at its view angle, times its metallic.
glm::vec3 metal_albedo(const shading::GSample& s) {
  return s.brdf.metallic * engine::material::metal_albedo(s.brdf, std::max(glm::dot(s.normal_world, s.wo_world), 1e-4f));
}

}  // namespace

DdgiPixels shade_ddgi_gbuffer(const shading::GBuffer& g, std::span<const DdgiVolume* const> volumes,
                              const shading::RealtimeGiSettings& upsampling, shading::UpsamplingPlan& plan, DdgiKernels& kernels) {
  using namespace engine;
  using shading::UpsamplingPlan;
  DdgiPixels out{image::ImageRGB(g.width, g.height), image::ImageRGB(g.width, g.height)};
  if (volumes.empty()) return out;
  shading::plan_upsampling(g.guide, g.width, g.height, upsampling, plan);
  // The lookups: each grid cell's pixel about its normal and about its
  // mirror direction, each pixel decoded on its own alike, and each metal
  // pixel's mirror direction, in that order. A surface with no glossy lobe
  // (no specular layer, no metal) gets no lookup about its mirror direction:
  // it would weigh nothing, and the lookups are the stage's cost (its cell
  // lends its neighbours its irradiance about the normal instead). A metal
  // the G-buffer marks takes its metal lobe's light at its own pixel.
  std::vector<Lookup> lookups;
  const auto weights_of = [&](std::size_t p) {
    const shading::GSample& s = g.samples[p];
    // Most of a frame is plain diffuse: no view angle to read for it.
    if (s.brdf.metallic <= 0.0f && s.brdf.specular <= 0.0f) return LobeWeights{s.diffuse * math::kInvPi, glm::vec3(0.0f)};
    const bool marked_metal = g.metal_roughness[p] < std::numeric_limits<float>::infinity();
    return lobe_weights(s.brdf, s.diffuse, glm::dot(s.normal_world, s.wo_world), !marked_metal);
  };
  // Each pixel that gets lookups (a cell's, or one decoded on its own): the
  // index of its lookup about its normal, and of its mirror one (kNoMirror: none).
  constexpr std::size_t kNoMirror = std::numeric_limits<std::size_t>::max();
  struct Looked {
    std::size_t pixel = 0, normal = 0, mirror = kNoMirror;
  };
  const auto look = [&](std::size_t p) {
    const shading::GSample& s = g.samples[p];
    Looked l{p, lookups.size(), kNoMirror};
    lookups.push_back({p, s.normal_world});
    if (weights_of(p).about_mirror != glm::vec3(0.0f)) {
      l.mirror = lookups.size();
      lookups.push_back({p, glm::reflect(-s.wo_world, s.normal_world)});
    }
    return l;
  };
  std::vector<Looked> cells(plan.cell_pixel.size()), own;
  for (std::size_t c = 0; c < plan.cell_pixel.size(); ++c)
    if (plan.cell_guide[c].w > 0) cells[c] = look(plan.cell_pixel[c]);
  for (std::size_t p = 0; p < g.samples.size(); ++p)
    if (plan.kind[p] == UpsamplingPlan::kOwn) own.push_back(look(p));
  const std::size_t own_end = lookups.size();
  // Metals as the G-buffer marks them (metallic >= 0.5), as TransGI's mirror pass finds them.
  for (std::size_t p = 0; p < g.samples.size(); ++p)
    if (g.metal_roughness[p] < std::numeric_limits<float>::infinity())
      lookups.push_back({p, glm::reflect(-g.samples[p].wo_world, g.samples[p].normal_world)});
  const std::vector<glm::mat2x3> e = look_up(g, lookups, volumes, kernels);

  // Irradiance per grid cell about its normal and its mirror direction (a miss stays 0).
  std::vector<glm::mat2x3> cell_e(plan.cell_pixel.size(), glm::mat2x3(0.0f)), cell_mirror(plan.cell_pixel.size(), glm::mat2x3(0.0f));
  for (std::size_t c = 0; c < plan.cell_pixel.size(); ++c)
    if (plan.cell_guide[c].w > 0) {
      cell_e[c] = e[cells[c].normal];
      cell_mirror[c] = cells[c].mirror == kNoMirror ? cell_e[c] : e[cells[c].mirror];
    }
  // A pixel's light: lobe_weights of the irradiance about its normal and about its mirror direction.
  const auto shade = [&](std::size_t p, const LobeWeights& w, const glm::mat2x3& about_normal, const glm::mat2x3& about_mirror) {
    out.gi.pixels[p] = w.about_normal * about_normal[0] + w.about_mirror * about_mirror[0];
    out.emitted.pixels[p] = w.about_normal * about_normal[1] + w.about_mirror * about_mirror[1];
  };
  jobs::parallel_for(0, g.height, 4, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < g.width; ++x) {
        const std::size_t p = static_cast<std::size_t>(y) * static_cast<std::size_t>(g.width) + static_cast<std::size_t>(x);
        if (plan.kind[p] != UpsamplingPlan::kUpsampled) continue;
        const LobeWeights lobes = weights_of(p);
        const bool mirrored = lobes.about_mirror != glm::vec3(0.0f);
        glm::mat2x3 about_normal(0.0f), about_mirror(0.0f);
        for (int tap = 0; tap < 4; ++tap) {
          const float w = plan.weight[static_cast<std::size_t>(tap)][p];
          const std::size_t c = plan.cell(tap, x, y);
          about_normal += w * cell_e[c];
          if (mirrored) about_mirror += w * cell_mirror[c];
        }
        shade(p, lobes, about_normal, about_mirror);
      }
  });
  for (const Looked& l : own) shade(l.pixel, weights_of(l.pixel), e[l.normal], l.mirror == kNoMirror ? e[l.normal] : e[l.mirror]);
  for (std::size_t k = own_end; k < lookups.size(); ++k) {
    const glm::vec3 albedo = metal_albedo(g.samples[lookups[k].pixel]) * math::kInvPi;
    out.gi.pixels[lookups[k].pixel] += albedo * e[k][0];
    out.emitted.pixels[lookups[k].pixel] += albedo * e[k][1];
  }
  return out;
}

}  // namespace transgi::ddgi
