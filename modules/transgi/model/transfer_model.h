#pragma once
// A baked object-centric neural transfer model: the scene-wide decoder plus
// each mesh asset's welded per-vertex latents, and how it was made.
#include <cstdint>
#include <string>
#include <vector>

#include "engine/scene/scene_assets.h"
#include "model/latent_mesh.h"
#include "model/mlp.h"

namespace transgi::model {

struct MeshLatents {
  std::string name;
  std::uint64_t content_hash = 0;  // of the mesh and its materials, see mesh_content_hash()
  LatentTable latents;
};

// The transfer's visibility V tests the object itself and counts hits closer
// than this fraction of its mesh's bounding-box diagonal (paper Section 4.2;
// bake::DatasetSettings::visibility_fraction), the default of a bake.
inline constexpr float kDefaultVisibilityFraction = 0.5f;

struct TransferModel {
  Mlp decoder;
  int latent_dim = 7;
  std::vector<MeshLatents> meshes;  // by SceneAssets::meshes index
  // The decoder predicts the transfer divided by the surface's base colour
  // (demodulation()): shading multiplies the pixel's own base colour back,
  // so a texture's detail and hue in the GI are exact whatever the network
  // smooths (issue 37). False for models baked before format 2.
  bool demodulated = false;
  // What the bake's V used (kDefaultVisibilityFraction). Within that distance
  // of a point, its own object's surfaces are masked by its transfer: their
  // light is not in the decoded transfer, and shading must add it
  // (shading/near_field.h). Read from bake_settings_json on load.
  float visibility_fraction = kDefaultVisibilityFraction;
  std::string bake_settings_json;   // what produced it (free-form JSON)
  std::string metrics_json;         // training and validation results (free-form JSON)

  [[nodiscard]] std::size_t decoder_bytes() const { return decoder.params().size() * sizeof(float); }
  [[nodiscard]] std::size_t latent_bytes() const;
  // The distance, in the mesh's own units, within which a point's transfer
  // masks the mesh's own surfaces.
  [[nodiscard]] float self_masked_within(const engine::scene::MeshAsset& mesh) const;
};

// Base colours are floored here before transfer or light is divided by
// them: a black channel would otherwise carry its rounding into the rest.
inline constexpr float kMinAlbedo = 0.01f;
// What a demodulated model's transfer is divided by at a surface point: its
// base colour (the texture's, per pixel), floored at kMinAlbedo. The bake
// and every shading path use this one function. The base colour scales the
// diffuse lobe and a metal's Fresnel; what does not follow it (a
// dielectric's faint specular) the network learns from its albedo input.
// And it is what the real-time path has per pixel at no cost.
inline glm::vec3 demodulation(const glm::vec3& base_color) { return glm::max(base_color, glm::vec3(kMinAlbedo)); }

// Inputs after the latent: albedo (3), normal (3), wo (3).
inline constexpr int kTransferInputExtra = 9;

// Decoder input for one shading point: [z (latent_dim), albedo (3), normal (3), wo (3)],
// all in the object's space. Writes latent_dim + 9 floats.
void assemble_input(const float* latent, int latent_dim, const glm::vec3& albedo, const glm::vec3& normal,
                    const glm::vec3& wo, float* out);

// FNV-1a 64 over the mesh's positions, triangles, normals, UVs and the
// parameters (and texture texels) of the materials its triangles use.
std::uint64_t mesh_content_hash(const engine::scene::SceneAssets& assets, std::uint32_t mesh);

}  // namespace transgi::model
