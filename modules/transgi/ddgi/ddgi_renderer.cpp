#include "ddgi/ddgi_renderer.h"

#include "engine/jobs/parallel_for.h"
#include "engine/math/rng.h"
#include "engine/math/sampling.h"
#include "engine/render/surface.h"

namespace transgi::ddgi {

engine::image::ImageRGB render_ddgi_gi(const engine::rt::RtScene& scene, const DdgiVolume& volume,
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
          const glm::vec2 u(rng.next_float(), rng.next_float());
          const rt::Ray ray = camera.generate_filtered(x, y, u, s.filter_width);
          rt::Hit hit;
          if (!scene.intersect(ray, hit)) continue;
          const render::Surface surf = render::make_surface(scene, hit, ray.direction);
          sum += material::diffuse_albedo(surf.brdf) * math::kInvPi * volume.irradiance(surf.position, surf.shading_normal, ray.direction);
        }
        img.pixels[pixel] = sum / static_cast<float>(s.spp);
      }
  });
  return img;
}

}  // namespace transgi::ddgi
