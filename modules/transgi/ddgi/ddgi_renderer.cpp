#include "ddgi/ddgi_renderer.h"

#include <algorithm>

#include "engine/jobs/parallel_for.h"
#include "engine/math/rng.h"
#include "engine/math/sampling.h"
#include "engine/render/surface.h"
#include "probes/cascades.h"

namespace transgi::ddgi {

namespace {

// The volumes' irradiance at p, blended as mix_at says; a volume with no
// active probe weighing in hands its weight to the next holding p.
// lookup(volume, &lit) is that volume's DdgiVolume::irradiance at the point.
template <class Lookup>
glm::vec3 mixed_irradiance(std::span<const DdgiVolume* const> volumes, const glm::vec3& p, Lookup&& lookup) {
  const probes::FieldMixOf<DdgiVolume> m = probes::mix_at(volumes, p);
  const DdgiVolume* first = m.field[0];
  bool lit = false;
  glm::vec3 e = lookup(first, &lit);
  while (!lit) {
    first = probes::next_holding(volumes, first, p);
    if (!first) return glm::vec3(0.0f);
    e = lookup(first, &lit);
  }
  if (m.count == 1 || first != m.field[0]) return e;
  bool second_lit = false;
  const glm::vec3 e2 = lookup(m.field[1], &second_lit);
  return second_lit ? m.weight[0] * e + m.weight[1] * e2 : e;
}

}  // namespace

glm::vec3 irradiance_from(std::span<const DdgiVolume* const> volumes, const glm::vec3& p, const glm::vec3& n, const glm::vec3& v) {
  return mixed_irradiance(volumes, p, [&](const DdgiVolume* volume, bool* lit) { return volume->irradiance(p, n, v, lit); });
}

namespace {

// The batched path: every sample's ray traced by the backend, its surface
// made here, the irradiance looked up by the backend in every volume and
// blended here as irradiance_from does. False where the backend declines;
// then the per-pixel path below runs.
bool render_batched(const engine::rt::RtScene& scene, std::span<const DdgiVolume* const> volumes,
                    const engine::render::CameraRays& camera,
                    int width, int height, const DdgiRenderSettings& s, DdgiKernels& kernels, engine::image::ImageRGB& img) {
  using namespace engine;
  rt::RayBatchTracer* tracer = kernels.tracer();
  if (!tracer) return false;
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
  if (!tracer->intersect(scene, rays, hits, found)) return false;
  std::vector<glm::vec3> position(rays.size()), normal(rays.size()), view(rays.size()), albedo(rays.size(), glm::vec3(0.0f));
  jobs::parallel_for<std::size_t>(0, rays.size(), 256, [&](std::size_t b, std::size_t e) {
    for (std::size_t k = b; k < e; ++k) {
      if (!found[k]) continue;
      const render::Surface surf = render::make_surface(scene, hits[k], rays[k].direction);
      position[k] = surf.position;
      normal[k] = surf.shading_normal;
      view[k] = rays[k].direction;
      albedo[k] = material::diffuse_albedo(surf.brdf) * math::kInvPi;
    }
  });
  // Each volume at every point: cascades hand points on, so any may be asked.
  std::vector<std::vector<glm::vec3>> per_volume(volumes.size(), std::vector<glm::vec3>(rays.size()));
  std::vector<std::vector<std::uint8_t>> lit(volumes.size(), std::vector<std::uint8_t>(rays.size()));
  for (std::size_t v = 0; v < volumes.size(); ++v)
    if (!kernels.irradiance(*volumes[v], position, normal, view, per_volume[v], lit[v])) return false;
  std::vector<glm::vec3> e(rays.size());
  jobs::parallel_for<std::size_t>(0, rays.size(), 256, [&](std::size_t b, std::size_t end) {
    for (std::size_t k = b; k < end; ++k) {
      if (!found[k]) continue;
      e[k] = mixed_irradiance(volumes, position[k], [&](const DdgiVolume* volume, bool* is_lit) {
        const auto v = static_cast<std::size_t>(std::find(volumes.begin(), volumes.end(), volume) - volumes.begin());
        *is_lit = lit[v][k] != 0;
        return per_volume[v][k];
      });
    }
  });
  for (std::size_t pixel = 0; pixel < pixels; ++pixel) {
    glm::vec3 sum(0.0f);
    for (std::size_t si = 0; si < spp; ++si) {
      const std::size_t k = pixel * spp + si;
      if (found[k]) sum += albedo[k] * e[k];
    }
    img.pixels[pixel] = sum / static_cast<float>(s.spp);
  }
  return true;
}

}  // namespace

engine::image::ImageRGB render_ddgi_gi(const engine::rt::RtScene& scene, std::span<const DdgiVolume* const> volumes,
                                       const engine::render::CameraRays& camera, int width, int height,
                                       const DdgiRenderSettings& s, DdgiKernels* kernels) {
  using namespace engine;
  image::ImageRGB img(width, height);
  if (kernels && !volumes.empty() && render_batched(scene, volumes, camera, width, height, s, *kernels, img)) return img;
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
          sum += material::diffuse_albedo(surf.brdf) * math::kInvPi * irradiance_from(volumes, surf.position, surf.shading_normal, ray.direction);
        }
        img.pixels[pixel] = sum / static_cast<float>(s.spp);
      }
  });
  return img;
}

}  // namespace transgi::ddgi
