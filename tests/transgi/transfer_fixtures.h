#pragma once
// A small scene, random decoders and random shading points for the transfer
// inference tests (tests/transgi/runtime_test.cpp on the CPU,
// tests/gpu/fused_inference_test.cpp on Vulkan).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "bake/trainer.h"
#include "engine/math/rng.h"
#include "engine/math/sampling.h"
#include "engine/scene/procedural.h"
#include "lambert.h"
#include "model/transfer_model.h"
#include "shading/transfer_inference.h"

// A grey floor with an orange cube on it, lit by a low sun (no sky): all GI
// is light bounced between the two.
inline engine::scene::SceneAssets floor_and_cube() {
  engine::scene::SceneAssets a;
  a.generation = engine::scene::next_scene_generation();
  a.meshes = {std::make_shared<engine::scene::MeshAsset>(engine::scene::make_quad({3, 3}, 0)),
              std::make_shared<engine::scene::MeshAsset>(engine::scene::make_box(glm::vec3(0.5f), false, 1))};
  a.materials = {lambert(glm::vec3(0.7f)), lambert({0.9f, 0.5f, 0.2f})};
  return a;
}

// A decoder of the given width with random latents, and biases too, so
// every layer's bias path is exercised.
inline transgi::model::TransferModel random_model(const engine::scene::SceneAssets& assets, int width,
                                                  engine::math::Pcg32& rng) {
  auto m = transgi::bake::make_untrained_model(assets, 7, transgi::model::MlpLayout{.width = width, .hidden_layers = 3}, 11);
  for (auto& mesh : m.meshes)
    for (float& v : mesh.latents.values) v = 2.0f * rng.next_float() - 1.0f;
  for (float& v : m.decoder.params()) v += 0.05f * (2.0f * rng.next_float() - 1.0f);
  return m;
}

// Shading points spread over the two meshes, with random albedo and directions.
inline std::vector<transgi::shading::TransferQuery> random_queries(const engine::scene::SceneAssets& assets, std::size_t n,
                                                                   engine::math::Pcg32& rng) {
  std::vector<transgi::shading::TransferQuery> queries(n);
  for (auto& q : queries) {
    q.mesh = rng.next_float() < 0.5f ? 0u : 1u;
    q.triangle = static_cast<std::uint32_t>(rng.next_float() * static_cast<float>(assets.meshes[q.mesh]->triangles.size())) %
                 static_cast<std::uint32_t>(assets.meshes[q.mesh]->triangles.size());
    const float b1 = rng.next_float(), b2 = rng.next_float() * (1 - b1);
    q.barycentric = {b1, b2};
    q.albedo = {rng.next_float(), rng.next_float(), rng.next_float()};
    q.normal = engine::math::sample_uniform_sphere({rng.next_float(), rng.next_float()});
    q.wo = engine::math::sample_uniform_sphere({rng.next_float(), rng.next_float()});
  }
  return queries;
}

// A tile fill (shade_transfer_fused, shade_transfer_batched) that copies
// each query's two lights from whole-batch arrays (n x 75 each) and counts
// how often each query was filled (each must be, once).
inline transgi::shading::TileLightFill copying_fill(const std::vector<float>& light, const std::vector<float>& light2,
                                                    std::vector<int>& filled) {
  return [&light, &light2, &filled](std::size_t b, std::size_t e, float* l, float* l2) {
    for (std::size_t i = b; i < e; ++i) ++filled[i];
    std::copy(light.begin() + static_cast<std::ptrdiff_t>(b * 75), light.begin() + static_cast<std::ptrdiff_t>(e * 75), l);
    if (l2) std::copy(light2.begin() + static_cast<std::ptrdiff_t>(b * 75), light2.begin() + static_cast<std::ptrdiff_t>(e * 75), l2);
  };
}
