#include "engine/render/view_shadows.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "engine/jobs/parallel_for.h"

namespace engine::render {

void trace_view_shadows(const rt::RtScene& scene, const CameraRays& camera, glm::vec2 film_offset,
                        std::span<const rt::Hit> hits, std::span<const std::uint8_t> found, const ViewShadowRequest& request,
                        std::span<float> out) {
  const int w = camera.width(), h = camera.height();
  const std::size_t pixels = static_cast<std::size_t>(w) * static_cast<std::size_t>(std::max(h, 0));
  if (hits.size() != pixels || found.size() != pixels || out.size() != request.lights.size() * pixels)
    throw std::invalid_argument("trace_view_shadows: " + std::to_string(pixels) + " pixels, " + std::to_string(hits.size()) +
                                " hits, " + std::to_string(found.size()) + " flags, " + std::to_string(out.size()) + " answers for " +
                                std::to_string(request.lights.size()) + " lights");
  const scene::SceneAssets* assets = scene.assets();
  if (!assets) throw std::invalid_argument("trace_view_shadows: the scene was built without its assets");
  constexpr float kInf = std::numeric_limits<float>::infinity(), kNotTraced = std::numeric_limits<float>::quiet_NaN();
  jobs::parallel_for<std::size_t>(0, pixels, 1024, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      const int x = static_cast<int>(i % static_cast<std::size_t>(w)), y = static_cast<int>(i / static_cast<std::size_t>(w));
      for (std::size_t l = 0; l < request.lights.size(); ++l) out[l * pixels + i] = kNotTraced;
      const rt::InstanceRecord* inst = found[i] ? scene.instance_of(hits[i]) : nullptr;
      if (!inst) continue;
      const rt::Ray view = camera.generate(glm::vec2(static_cast<float>(x), static_cast<float>(y)) + film_offset);
      const glm::vec3 p = view.origin + hits[i].t * view.direction;
      const scene::MeshAsset& mesh = *assets->meshes[inst->mesh];
      const glm::uvec3 t = mesh.triangles[hits[i].primitive];
      glm::vec3 ng = glm::cross(mesh.positions[t.y] - mesh.positions[t.x], mesh.positions[t.z] - mesh.positions[t.x]);
      const float length = glm::length(ng);
      if (!(length > 0)) continue;
      ng = inst->to_world.apply_direction(ng / length);
      if (glm::dot(ng, view.direction) > 0) ng = -ng;
      const glm::vec3 origin = rt::offset_ray_origin(p, ng, request.offset_scale);
      const int cell = view_shadow_cell(x, y, request.pattern_shift);
      for (std::size_t l = 0; l < request.lights.size(); ++l) {
        const ViewShadowLight& light = request.lights[l];
        rt::Ray ray{origin, glm::vec3(0.0f), 0.0f, kInf};
        if (light.directional) {
          ray.direction = light.directions[static_cast<std::size_t>(cell)];
        } else {
          const glm::vec3 d = light.position - p;
          const float distance = glm::length(d);
          if (!(distance > 0)) continue;
          ray.direction = d / distance;
          ray.tmax = distance * (1.0f - 1e-4f);
        }
        if (!(glm::dot(ray.direction, ng) > -kViewShadowSlack)) continue;
        float& answer = out[l * pixels + i];
        if (light.nearest) {
          rt::Hit blocker;
          answer = scene.intersect(ray, blocker) ? blocker.t : kInf;
        } else {
          answer = scene.occluded(ray) ? 0.0f : kInf;
        }
      }
    }
  });
}

}  // namespace engine::render
