#include "model/latent_mesh.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>

namespace transgi::model {

void LatentTable::interpolate(const engine::scene::MeshAsset& mesh, std::uint32_t tri, glm::vec2 bary, float* out) const {
  const glm::uvec3 t = mesh.triangles[tri];
  const float w[3] = {1.0f - bary.x - bary.y, bary.x, bary.y};
  const float* r[3] = {row(vertex_to_latent[t.x]), row(vertex_to_latent[t.y]), row(vertex_to_latent[t.z])};
  for (int d = 0; d < dimension; ++d) out[d] = w[0] * r[0][d] + w[1] * r[1][d] + w[2] * r[2][d];
}

void LatentTable::scatter_gradient(const engine::scene::MeshAsset& mesh, std::uint32_t tri, glm::vec2 bary,
                                   const float* dz, std::span<float> grad) const {
  const glm::uvec3 t = mesh.triangles[tri];
  const float w[3] = {1.0f - bary.x - bary.y, bary.x, bary.y};
  const std::uint32_t rows_[3] = {vertex_to_latent[t.x], vertex_to_latent[t.y], vertex_to_latent[t.z]};
  for (int v = 0; v < 3; ++v) {
    float* g = grad.data() + static_cast<std::size_t>(rows_[v]) * dimension;
    for (int d = 0; d < dimension; ++d) g[d] += w[v] * dz[d];
  }
}

void LatentTable::scatter_gradient_rows(const engine::scene::MeshAsset& mesh, std::uint32_t tri, glm::vec2 bary, const float* dz,
                                        std::uint64_t first_row, std::span<const std::uint64_t> rows, std::span<float> row_values) const {
  const glm::uvec3 t = mesh.triangles[tri];
  const float w[3] = {1.0f - bary.x - bary.y, bary.x, bary.y};
  const std::uint32_t rows_[3] = {vertex_to_latent[t.x], vertex_to_latent[t.y], vertex_to_latent[t.z]};
  for (int v = 0; v < 3; ++v) {
    const auto at = std::lower_bound(rows.begin(), rows.end(), first_row + rows_[v]);
    float* g = row_values.data() + static_cast<std::size_t>(at - rows.begin()) * static_cast<std::size_t>(dimension);
    for (int d = 0; d < dimension; ++d) g[d] += w[v] * dz[d];
  }
}

LatentTable make_latent_table(const engine::scene::MeshAsset& mesh, int dimension, float tolerance) {
  LatentTable t;
  t.dimension = dimension;
  const float size = glm::length(mesh.bounds_max - mesh.bounds_min);
  const double cell = std::max(1e-12, static_cast<double>(tolerance) * std::max(size, 1e-6f));
  // Quantised positions: exact-duplicate seams (the common case) always weld.
  std::map<std::tuple<long long, long long, long long>, std::uint32_t> welded;
  t.vertex_to_latent.resize(mesh.positions.size());
  for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
    const glm::vec3& p = mesh.positions[v];
    const auto key = std::make_tuple(std::llround(p.x / cell), std::llround(p.y / cell), std::llround(p.z / cell));
    auto [it, inserted] = welded.try_emplace(key, static_cast<std::uint32_t>(welded.size()));
    t.vertex_to_latent[v] = it->second;
  }
  t.values.assign(welded.size() * static_cast<std::size_t>(dimension), 0.0f);
  return t;
}

}  // namespace transgi::model
