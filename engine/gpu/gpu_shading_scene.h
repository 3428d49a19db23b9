#pragma once
// What a kernel needs to shade a ray hit as the CPU does (render::make_surface,
// render::LightSet::sample, material::brdf_eval), mirrored from an RtScene
// and a LightSet: mesh attributes, materials, textures (level 0), the GGX
// albedo and sRGB tables, and the lights. Kernels include
// shaders/scene_shading.glsl (then brdf.glsl, light_sampling.glsl) and bind
// bind() at kBindings consecutive slots.
//
// Meshes, materials and textures are uploaded once per asset generation;
// instances and lights at every sync (a few KB), except the environment's
// texels and distribution, uploaded again only when its map changes.
#include <cstdint>

#include "engine/gpu/compute_pipeline.h"
#include "engine/gpu/gpu_buffer.h"
#include "engine/gpu/vulkan_context.h"
#include "engine/render/light_set.h"
#include "engine/rt/rt_scene.h"

namespace engine::gpu {

class GpuShadingScene {
 public:
  explicit GpuShadingScene(VulkanContext& ctx) : ctx_(ctx) {}

  void sync(const rt::RtScene& rt, const render::LightSet& lights);
  // Binds the shading buffers at first .. first + kBindings - 1
  // (scene_shading.glsl's order). Throws GpuError before the first sync.
  void bind(ComputePipeline& pipeline, std::uint32_t first) const;

  static constexpr std::uint32_t kBindings = 12;

 private:
  void sync_assets(const scene::SceneAssets& assets);
  void sync_lights(const render::LightSet& lights);

  VulkanContext& ctx_;
  std::uint64_t generation_ = ~std::uint64_t{0};
  GpuBuffer instances_, mesh_first_, triangles_, materials_, textures_, texels_, tables_;
  GpuBuffer light_set_, emissive_, punctual_, light_tables_, triangle_cdf_;
  // The environment whose tables light_tables_ holds (its image's address and size).
  const void* env_pixels_ = nullptr;
  int env_width_ = 0, env_height_ = 0;
};

}  // namespace engine::gpu
