#pragma once
// A closed room with rotated, scaled and overlapping meshes in it, for the
// tests that compare the GPU's traversal or raster with Embree or each other.
#include <memory>
#include <vector>

#include <glm/gtc/quaternion.hpp>

#include "engine/math/rng.h"
#include "engine/rt/rt_scene.h"
#include "engine/scene/procedural.h"

namespace gpu_test {

struct RtWorld {
  engine::scene::SceneAssets assets;
  engine::rt::RtScene rt;
  std::vector<engine::transform::Similarity> xf;
  std::vector<std::uint32_t> mesh_of;
};

// A closed room (inward box) with rotated, scaled and overlapping spheres,
// tori, boxes and tubes in it: concave, convex and thin geometry.
inline void build_world(RtWorld& w) {
  w.assets.generation = engine::scene::next_scene_generation();
  auto add = [&](engine::scene::MeshAsset m) {
    m.compute_bounds();
    w.assets.meshes.push_back(std::make_shared<engine::scene::MeshAsset>(std::move(m)));
  };
  add(engine::scene::make_box(glm::vec3(5.0f, 3.0f, 4.0f), true));
  add(engine::scene::make_uv_sphere(0.7f, 48, 24));
  add(engine::scene::make_torus(0.8f, 0.25f, 40, 16));
  add(engine::scene::make_box(glm::vec3(0.4f, 0.9f, 0.3f)));
  add(engine::scene::make_tube(0.3f, 1.5f, 24, 0.6f));
  w.assets.materials.resize(1);
  w.rt.set_assets(&w.assets);
  engine::math::Pcg32 rng(77, 1);
  for (std::uint32_t i = 0; i < 13; ++i) {
    engine::transform::Similarity s;
    const std::uint32_t mesh = i == 0 ? 0 : 1 + (i % 4);
    if (i > 0) {
      s.translation = glm::vec3(8.0f * rng.next_float() - 4.0f, 5.0f * rng.next_float() - 2.5f, 6.0f * rng.next_float() - 3.0f);
      s.rotation = glm::normalize(glm::quat(rng.next_float() - 0.5f, rng.next_float() - 0.5f, rng.next_float() - 0.5f, rng.next_float() - 0.5f));
      s.scale = 0.5f + 1.5f * rng.next_float();
    }
    w.rt.upsert_instance(engine::ecs::Entity{i, 0}, mesh, s);
    w.xf.push_back(s);
    w.mesh_of.push_back(mesh);
  }
  // One removed instance leaves a hole in the ids, as a despawn would.
  w.rt.upsert_instance(engine::ecs::Entity{99, 0}, 1, engine::transform::Similarity{});
  w.rt.remove_instance(engine::ecs::Entity{99, 0});
  w.rt.commit();
}

// A point inside build_world's room (its walls at +-5, +-3, +-4).
// The cut-out tests' pieces (make_quad lies in the XZ plane): a 4 x 4 wall
// of material 0, and a 2 x 2 screen of `material` whose UVs run to 3, so
// that its texture repeats.
inline engine::scene::MeshAsset wall_quad() {
  engine::scene::MeshAsset wall = engine::scene::make_quad({4.0f, 4.0f}, 0);
  wall.compute_bounds();
  return wall;
}

inline engine::scene::MeshAsset screen_quad(std::uint32_t material) {
  engine::scene::MeshAsset screen = engine::scene::make_quad({2.0f, 2.0f}, material);
  for (auto& uv : screen.uvs) uv *= 3.0f;
  screen.compute_bounds();
  return screen;
}

}  // namespace gpu_test
