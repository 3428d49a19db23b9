#include "eval/scene_fingerprint.h"

#include <cstdio>

#include "engine/core/fnv1a.h"
#include "engine/scene/components.h"
#include "engine/scene/scene_assets.h"
#include "engine/transform/transform.h"
#include "model/transfer_model.h"

namespace transgi::eval {


std::uint64_t scene_fingerprint(engine::ecs::World& world) {
  using namespace engine;
  core::Fnv1a f;
  const auto& assets = world.resource<scene::SceneAssets>();
  for (std::uint32_t m = 0; m < assets.meshes.size(); ++m) f.value(model::mesh_content_hash(assets, m));
  if (assets.environment) {
    const auto& img = assets.environment->image();
    f.bytes(img.pixels.data(), img.pixels.size() * sizeof(glm::vec3));
    f.value(assets.environment->strength());
    f.value(assets.environment->to_world(glm::vec3(1, 2, 3)));
  }
  world.view<const scene::MeshInstance, const transform::WorldTransform>().each(
      [&](const scene::MeshInstance& m, const transform::WorldTransform& w) {
        f.value(m.mesh);
        f.value(w.translation);
        f.value(w.rotation);
        f.value(w.scale);
      });
  world.view<const scene::PunctualLight, const transform::WorldTransform>().each(
      [&](const scene::PunctualLight& l, const transform::WorldTransform& w) {
        f.value(static_cast<int>(l.type));
        f.value(l.color);
        f.value(l.intensity);
        f.value(l.range);
        f.value(l.inner_cone_angle);
        f.value(l.outer_cone_angle);
        f.value(l.enabled);
        f.value(w.translation);
        f.value(w.rotation);
      });
  world.view<const scene::Camera, const transform::WorldTransform>().each(
      [&](const scene::Camera& c, const transform::WorldTransform& w) {
        f.value(c.yfov_radians);
        f.value(c.aspect_ratio);
        f.value(w.translation);
        f.value(w.rotation);
      });
  return f.h;
}

std::string hex64(std::uint64_t v) {
  char s[17];
  std::snprintf(s, sizeof(s), "%016llx", static_cast<unsigned long long>(v));
  return s;
}

}  // namespace transgi::eval
