#pragma once
// Ground-truth transfer samples (paper Eq. 5 / Eq. 8), in a mesh's object space:
//
//   t[c][k](x, wo) = integral over H(n) of f_c(x, wi, wo) V(x, wi, t) (wi . n) Y_k(wi) dwi
//
// for RGB channels c and the 25 real SH functions Y_k (engine/math/sh.h)
// evaluated in object space. V tests the object itself only, and only hits
// closer than the visibility distance t count (Section 4.2), so light from
// inside or beyond t is not blocked.
//
// Estimator: each point's K outgoing directions share one set of rays. Every
// direction contributes N/K samples drawn from its own BRDF (GGX visible
// normals + cosine, Latin-hypercube stratified); all N rays are then used for
// every direction with the balance-heuristic mixture pdf (1/K) sum_k p_k(wi).
// So visibility is traced once per point, and each wo still gets samples
// from its own lobe.
#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "engine/material/brdf.h"
#include "engine/math/distribution.h"
#include "engine/math/rng.h"
#include "engine/math/sh.h"
#include "engine/rt/rt_scene.h"
#include "engine/scene/scene_assets.h"

namespace transgi::bake {

inline constexpr int kTransferValues = 3 * engine::math::kShCount;  // 75, laid out [c * 25 + k]

struct SurfacePoint {
  std::uint32_t triangle = 0;
  glm::vec2 barycentric{0.0f};  // Embree convention (b1, b2)
  glm::vec3 position{0.0f};
  glm::vec3 shading_normal{0.0f, 0.0f, 1.0f};
  glm::vec3 geometric_normal{0.0f, 0.0f, 1.0f};  // on the shading normal's side
  glm::vec2 uv{0.0f};
  engine::material::BrdfParams brdf;
};

enum class Proposal {
  BrdfMixture,  // the default described above
  CosineOnly,   // cosine-weighted hemisphere only (for the estimator study)
};

// Area-weighted point sampling and transfer estimation on one mesh. The
// tracer must hold exactly this mesh at the identity transform.
class MeshTransfer {
 public:
  MeshTransfer(const engine::rt::RtScene& object_tracer, const engine::scene::MeshAsset& mesh,
               const engine::scene::SceneAssets& assets, float visibility_distance);

  SurfacePoint sample_point(engine::math::Pcg32& rng) const;
  // The surface point at barycentrics (b1, b2) of a triangle: position,
  // normals (geometric on the shading normal's side), UV and material.
  [[nodiscard]] SurfacePoint point_at(std::uint32_t triangle, glm::vec2 barycentric) const;
  // Fills out[j * 75 + c * 25 + k] for each wo[j] (object space, unit, above the surface).
  void estimate(const SurfacePoint& p, std::span<const glm::vec3> wo, int rays, engine::math::Pcg32& rng,
                std::span<float> out, Proposal proposal = Proposal::BrdfMixture) const;
  // Uniform direction over the shading normal's hemisphere.
  static glm::vec3 sample_outgoing(const SurfacePoint& p, engine::math::Pcg32& rng);

  [[nodiscard]] float visibility_distance() const { return visibility_distance_; }
  [[nodiscard]] double surface_area() const { return area_; }

 private:
  const engine::rt::RtScene& tracer_;
  const engine::scene::MeshAsset& mesh_;
  const engine::scene::SceneAssets& assets_;
  float visibility_distance_;
  engine::math::Distribution1D triangle_distribution_;
  double area_ = 0.0;
};

// An Embree scene holding only assets.meshes[mesh] at the identity transform
// (the object's own space), for self-visibility rays.
std::unique_ptr<engine::rt::RtScene> make_object_tracer(const engine::scene::SceneAssets& assets, std::uint32_t mesh);

// The default visibility distance t: half the diagonal of the mesh's bounds.
float default_visibility_distance(const engine::scene::MeshAsset& mesh);

}  // namespace transgi::bake
