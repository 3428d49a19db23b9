#pragma once
// Per-vertex latent codes of one mesh asset (paper Eq. 7). Vertices at the
// same position share one latent ("welded"), so UV and normal seams, which
// split vertices in the mesh, do not show as seams in the decoded transfer.
#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "engine/scene/mesh_asset.h"

namespace transgi::model {

struct LatentTable {
  int dimension = 7;
  std::vector<std::uint32_t> vertex_to_latent;  // mesh vertex -> welded latent row
  std::vector<float> values;                    // rows x dimension

  [[nodiscard]] std::size_t rows() const { return dimension > 0 ? values.size() / static_cast<std::size_t>(dimension) : 0; }
  [[nodiscard]] float* row(std::uint32_t r) { return values.data() + static_cast<std::size_t>(r) * dimension; }
  [[nodiscard]] const float* row(std::uint32_t r) const { return values.data() + static_cast<std::size_t>(r) * dimension; }

  // z = b0 z(v0) + b1 z(v1) + b2 z(v2) for triangle `tri` of `mesh` at
  // barycentrics (b1, b2) (Embree's convention: b0 = 1 - b1 - b2).
  void interpolate(const engine::scene::MeshAsset& mesh, std::uint32_t tri, glm::vec2 bary, float* out) const;
  // Adds dL/dz scattered back to the three latent rows (the adjoint of interpolate).
  void scatter_gradient(const engine::scene::MeshAsset& mesh, std::uint32_t tri, glm::vec2 bary, const float* dz,
                        std::span<float> grad) const;
  // scatter_gradient into the rows `rows` alone (ascending, each a row index
  // plus `first_row`, holding every row the triangle's vertices use), their
  // values `dimension` floats a row: the same additions in the same order.
  void scatter_gradient_rows(const engine::scene::MeshAsset& mesh, std::uint32_t tri, glm::vec2 bary, const float* dz,
                             std::uint64_t first_row, std::span<const std::uint64_t> rows, std::span<float> row_values) const;
};

// Welds vertices whose positions agree to `tolerance` (relative to the mesh
// size) and allocates one zero-initialised latent per welded vertex.
LatentTable make_latent_table(const engine::scene::MeshAsset& mesh, int dimension, float tolerance = 1e-5f);

}  // namespace transgi::model
