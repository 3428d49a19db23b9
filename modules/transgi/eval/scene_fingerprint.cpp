#include "eval/scene_fingerprint.h"

#include <cstdio>
#include <cstring>

#include "engine/scene/components.h"
#include "engine/scene/scene_assets.h"
#include "engine/transform/transform.h"
#include "model/transfer_model.h"

namespace transgi::eval {

namespace {
struct Fnv {
  std::uint64_t h = 1469598103934665603ull;
  void bytes(const void* p, std::size_t n) {
    const auto* b = static_cast<const unsigned char*>(p);
    for (std::size_t i = 0; i < n; ++i) {
      h ^= b[i];
      h *= 1099511628211ull;
    }
  }
  template <class T>
  void value(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    bytes(&v, sizeof(T));
  }
};
}  // namespace

std::uint64_t scene_fingerprint(engine::ecs::World& world) {
  using namespace engine;
  Fnv f;
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
