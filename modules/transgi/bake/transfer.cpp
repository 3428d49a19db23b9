#include "bake/transfer.h"

#include <algorithm>
#include <numeric>

#include "engine/math/sampling.h"
#include "engine/render/surface.h"
#include "model/transfer_model.h"

namespace transgi::bake {

using engine::math::Pcg32;

std::unique_ptr<engine::rt::RtScene> make_object_tracer(const engine::scene::SceneAssets& assets, std::uint32_t mesh) {
  auto tracer = std::make_unique<engine::rt::RtScene>();
  tracer->set_assets(&assets);
  tracer->upsert_instance(engine::ecs::Entity{mesh, 0}, mesh, engine::transform::Similarity{});
  tracer->commit();
  return tracer;
}

float default_visibility_distance(const engine::scene::MeshAsset& mesh) {
  return model::kDefaultVisibilityFraction * glm::length(mesh.bounds_max - mesh.bounds_min);
}

MeshTransfer::MeshTransfer(const engine::rt::RtScene& tracer, const engine::scene::MeshAsset& mesh,
                           const engine::scene::SceneAssets& assets, float visibility_distance)
    : tracer_(tracer), mesh_(mesh), assets_(assets), visibility_distance_(visibility_distance) {
  std::vector<float> areas(mesh.triangles.size());
  for (std::size_t t = 0; t < areas.size(); ++t) {
    const glm::uvec3 tri = mesh.triangles[t];
    areas[t] = 0.5f * glm::length(glm::cross(mesh.positions[tri.y] - mesh.positions[tri.x],
                                             mesh.positions[tri.z] - mesh.positions[tri.x]));
    area_ += areas[t];
  }
  triangle_distribution_ = engine::math::Distribution1D(areas);
}

SurfacePoint MeshTransfer::sample_point(Pcg32& rng) const {
  std::size_t t = 0;
  (void)triangle_distribution_.sample_continuous(rng.next_float(), nullptr, &t);
  return point_at(static_cast<std::uint32_t>(t), engine::math::sample_uniform_triangle({rng.next_float(), rng.next_float()}));
}

SurfacePoint MeshTransfer::point_at(std::uint32_t t, glm::vec2 b) const {
  SurfacePoint p;
  p.triangle = t;
  p.barycentric = b;
  const glm::uvec3 tri = mesh_.triangles[t];
  const float b0 = 1.0f - b.x - b.y;
  p.position = b0 * mesh_.positions[tri.x] + b.x * mesh_.positions[tri.y] + b.y * mesh_.positions[tri.z];
  glm::vec3 ns = b0 * mesh_.normals[tri.x] + b.x * mesh_.normals[tri.y] + b.y * mesh_.normals[tri.z];
  const float len = glm::length(ns);
  glm::vec3 ng = glm::cross(mesh_.positions[tri.y] - mesh_.positions[tri.x], mesh_.positions[tri.z] - mesh_.positions[tri.x]);
  const float glen = glm::length(ng);
  ng = glen > 0 ? ng / glen : glm::vec3(0, 0, 1);
  ns = len > 0 ? ns / len : ng;
  if (glm::dot(ng, ns) < 0) ng = -ng;
  p.shading_normal = ns;
  p.geometric_normal = ng;
  if (!mesh_.uvs.empty()) p.uv = b0 * mesh_.uvs[tri.x] + b.x * mesh_.uvs[tri.y] + b.y * mesh_.uvs[tri.z];
  p.brdf = engine::render::evaluate_material(assets_, mesh_.triangle_material[t], p.uv);
  return p;
}

glm::vec3 MeshTransfer::sample_outgoing(const SurfacePoint& p, Pcg32& rng) {
  const glm::vec3 local = engine::math::sample_uniform_hemisphere({rng.next_float(), rng.next_float()});
  return engine::math::Frame::from_normal(p.shading_normal).to_world(local);
}

void MeshTransfer::estimate(const SurfacePoint& p, std::span<const glm::vec3> wo_object, int rays, Pcg32& rng,
                            std::span<float> out, Proposal proposal) const {
  using namespace engine;
  const int K = static_cast<int>(wo_object.size());
  std::fill(out.begin(), out.end(), 0.0f);
  if (K == 0 || rays <= 0) return;
  const math::Frame frame = math::Frame::from_normal(p.shading_normal);
  std::vector<glm::vec3> wo(static_cast<std::size_t>(K));
  for (int j = 0; j < K; ++j) wo[static_cast<std::size_t>(j)] = frame.to_local(wo_object[static_cast<std::size_t>(j)]);

  // Draw the pooled directions (local frame), Latin-hypercube stratified per proposal.
  const int proposals = proposal == Proposal::CosineOnly ? 1 : K;
  const int per = std::max(1, rays / proposals);
  std::vector<glm::vec3> dirs;
  dirs.reserve(static_cast<std::size_t>(per * proposals));
  std::vector<int> perm(static_cast<std::size_t>(per));
  for (int k = 0; k < proposals; ++k) {
    std::iota(perm.begin(), perm.end(), 0);
    for (int i = per - 1; i > 0; --i) std::swap(perm[static_cast<std::size_t>(i)], perm[rng.next_u32() % static_cast<std::uint32_t>(i + 1)]);
    for (int s = 0; s < per; ++s) {
      const glm::vec2 u((static_cast<float>(s) + rng.next_float()) / static_cast<float>(per),
                        (static_cast<float>(perm[static_cast<std::size_t>(s)]) + rng.next_float()) / static_cast<float>(per));
      if (proposal == Proposal::CosineOnly) {
        dirs.push_back(math::sample_cosine_hemisphere(u));
      } else {
        material::BrdfSample bs;
        if (material::brdf_sample(p.brdf, wo[static_cast<std::size_t>(k)], u, rng.next_float(), bs)) dirs.push_back(bs.wi);
      }
    }
  }
  const float total = static_cast<float>(per * proposals);  // failed draws count as zero samples

  const glm::vec3 origin = rt::offset_ray_origin(p.position, p.geometric_normal, tracer_.offset_scale());
  for (const glm::vec3& wi : dirs) {
    const glm::vec3 wi_obj = frame.to_world(wi);
    if (glm::dot(wi_obj, p.geometric_normal) <= 0) continue;  // blocked by the surface itself
    rt::Hit hit;
    if (tracer_.intersect(rt::Ray{origin, wi_obj, 0.0f, visibility_distance_}, hit)) continue;  // V = 0
    float pdf = 0;
    if (proposal == Proposal::CosineOnly) {
      pdf = math::cosine_hemisphere_pdf(wi.z);
    } else {
      for (int k = 0; k < K; ++k) pdf += material::brdf_pdf(p.brdf, wo[static_cast<std::size_t>(k)], wi);
      pdf /= static_cast<float>(K);
    }
    if (!(pdf > 0)) continue;
    const math::ShBasis y = math::sh_eval(wi_obj);
    for (int j = 0; j < K; ++j) {
      const glm::vec3 f = material::brdf_eval(p.brdf, wo[static_cast<std::size_t>(j)], wi);
      const glm::vec3 w = f * (wi.z / (pdf * total));
      float* o = out.data() + static_cast<std::size_t>(j) * kTransferValues;
      for (int c = 0; c < 3; ++c)
        for (int k = 0; k < math::kShCount; ++k) o[c * math::kShCount + k] += w[c] * y[static_cast<std::size_t>(k)];
    }
  }
}

}  // namespace transgi::bake
