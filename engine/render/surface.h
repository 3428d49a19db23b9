#pragma once
// Shading data at a ray hit: world-space position and normals (both turned
// to face the incoming ray, so every surface is two-sided as in Cycles),
// texture coordinates, and the material evaluated there.
#include "engine/material/brdf.h"
#include "engine/math/sampling.h"
#include "engine/rt/rt_scene.h"

namespace engine::render {

struct Surface {
  glm::vec3 position{0.0f};
  glm::vec3 geometric_normal{0.0f, 0.0f, 1.0f};  // unit, facing the incoming ray
  glm::vec3 shading_normal{0.0f, 0.0f, 1.0f};    // unit, same side as geometric_normal
  glm::vec2 uv{0.0f};
  glm::vec3 emission{0.0f};
  material::BrdfParams brdf;
  std::uint32_t material = 0;
  float area_scale = 1.0f;  // world area / object area (uniform scale squared)
  // The ray arrived from the side opposite the triangle's winding normal of
  // a single-sided material. Shading is two-sided either way; this is for
  // callers that need to know whether a point lies inside closed geometry
  // (probe classification). A double-sided material has no back face: its
  // winding says nothing about where the solid is.
  bool back_face = false;
  math::Frame frame;        // around shading_normal
};

// incoming_dir: the direction of the ray that found the hit.
Surface make_surface(const rt::RtScene& scene, const rt::Hit& hit, const glm::vec3& incoming_dir);

// A texture read at the mip level a footprint asks for (0: the finest).
glm::vec4 sample_texture(const scene::Texture& t, glm::vec2 uv, bool srgb, float footprint);

// The material at a point on a mesh (base colour, roughness, ... from
// factors and textures). Shared by the renderer and the bake. footprint:
// the width of the area to average, in UV units (0 = a point sample, as
// Monte Carlo renderers take); textures are then read at the mip level it
// asks for (Texture::sample with lod). Inline: a G-buffer builds one per
// pixel and reads fields of it back at once; returned from another unit,
// each read waits on a store it cannot forward.
inline material::BrdfParams evaluate_material(const scene::SceneAssets& assets, std::uint32_t index, glm::vec2 uv,
                                              float footprint = 0) {
  const material::Material& m = assets.materials[index];
  material::BrdfParams p;
  glm::vec4 base = m.base_color_factor;
  if (m.base_color_texture >= 0) base *= sample_texture(assets.textures[static_cast<std::size_t>(m.base_color_texture)], uv, true, footprint);
  p.base_color = glm::vec3(base);
  p.metallic = m.metallic_factor;
  p.roughness = m.roughness_factor;
  if (m.metallic_roughness_texture >= 0) {
    const glm::vec4 mr = sample_texture(assets.textures[static_cast<std::size_t>(m.metallic_roughness_texture)], uv, false, footprint);
    p.roughness *= mr.g;
    p.metallic *= mr.b;
  }
  p.specular = m.specular_factor;
  p.specular_color = m.specular_color_factor;
  return p;
}
glm::vec3 evaluate_emission(const scene::SceneAssets& assets, std::uint32_t material, glm::vec2 uv, float uv_footprint = 0);

// Ray cones (Akenine-Moller et al. 2019, "Texture Level of Detail Strategies
// for Real-Time Ray Tracing"): a cone `cone_width` wide where it meets
// triangle `triangle` of `mesh` (scaled by `scale` into the world) at an angle
// whose cosine is cos_theta covers this width in UV units. 0 when the mesh
// has no UVs or the triangle no area.
float uv_footprint(const scene::MeshAsset& mesh, std::uint32_t triangle, float scale, float cone_width, float cos_theta);

// The mip level for a footprint on a texture of w x h texels.
float texture_lod(float uv_footprint, int w, int h);

}  // namespace engine::render
