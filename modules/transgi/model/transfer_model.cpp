#include "model/transfer_model.h"

#include <set>

#include "engine/core/fnv1a.h"

namespace transgi::model {

std::size_t TransferModel::latent_bytes() const {
  std::size_t n = 0;
  for (const auto& m : meshes) n += m.latents.values.size() * sizeof(float);
  return n;
}

float TransferModel::self_masked_within(const engine::scene::MeshAsset& mesh) const {
  return visibility_fraction * glm::length(mesh.bounds_max - mesh.bounds_min);
}

void assemble_input(const float* latent, int latent_dim, const glm::vec3& albedo, const glm::vec3& normal,
                    const glm::vec3& wo, float* out) {
  for (int i = 0; i < latent_dim; ++i) out[i] = latent[i];
  float* rest = out + latent_dim;
  rest[0] = albedo.r;
  rest[1] = albedo.g;
  rest[2] = albedo.b;
  rest[3] = normal.x;
  rest[4] = normal.y;
  rest[5] = normal.z;
  rest[6] = wo.x;
  rest[7] = wo.y;
  rest[8] = wo.z;
}

using engine::core::Fnv1a;

std::uint64_t mesh_content_hash(const engine::scene::SceneAssets& assets, std::uint32_t mesh_index) {
  const engine::scene::MeshAsset& mesh = *assets.meshes[mesh_index];
  Fnv1a f;
  f.vec(mesh.positions);
  f.vec(mesh.triangles);
  f.vec(mesh.normals);
  f.vec(mesh.uvs);
  f.vec(mesh.triangle_material);
  const std::set<std::uint32_t> used(mesh.triangle_material.begin(), mesh.triangle_material.end());
  for (std::uint32_t m : used) {
    const auto& mat = assets.materials[m];
    f.value(mat.base_color_factor);
    f.value(mat.metallic_factor);
    f.value(mat.roughness_factor);
    f.value(mat.specular_factor);
    f.value(mat.specular_color_factor);
    f.value(mat.alpha_mode);
    f.value(mat.alpha_cutoff);
    for (std::int32_t tex : {mat.base_color_texture, mat.metallic_roughness_texture}) {
      f.value(tex);
      if (tex >= 0) f.vec(assets.textures[static_cast<std::size_t>(tex)].rgba);
    }
  }
  return f.h;
}

}  // namespace transgi::model
