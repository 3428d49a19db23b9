#include "engine/render/surface.h"

#include <algorithm>
#include <cmath>

namespace engine::render {

float uv_footprint(const scene::MeshAsset& mesh, std::uint32_t triangle, float scale, float cone_width, float cos_theta) {
  if (mesh.uvs.empty() || !(cone_width > 0)) return 0.0f;
  const glm::uvec3 t = mesh.triangles[triangle];
  const float world_area = 0.5f * glm::length(glm::cross(mesh.positions[t.y] - mesh.positions[t.x], mesh.positions[t.z] - mesh.positions[t.x])) *
                           scale * scale;
  const glm::vec2 a = mesh.uvs[t.y] - mesh.uvs[t.x], b = mesh.uvs[t.z] - mesh.uvs[t.x];
  const float uv_area = 0.5f * std::abs(a.x * b.y - a.y * b.x);
  if (!(world_area > 0) || !(uv_area > 0)) return 0.0f;
  // Seen at a grazing angle the cone's footprint stretches; the isotropic
  // estimate takes its long side (over-blurs across it, as rasterisers
  // without anisotropic filtering do), capped at 20x.
  const float f = cone_width / std::max(std::abs(cos_theta), 0.05f) * std::sqrt(uv_area / world_area);
  return std::isfinite(f) ? f : 0.0f;
}

float texture_lod(float footprint, int w, int h) {
  if (!(footprint > 0) || w <= 0 || h <= 0) return 0.0f;
  return std::log2(footprint * std::sqrt(static_cast<float>(w) * static_cast<float>(h)));
}

glm::vec4 sample_texture(const scene::Texture& t, glm::vec2 uv, bool srgb, float footprint) {
  return footprint > 0 ? t.sample(uv, srgb, texture_lod(footprint, t.width, t.height)) : t.sample(uv, srgb);
}

glm::vec3 evaluate_emission(const scene::SceneAssets& assets, std::uint32_t index, glm::vec2 uv, float footprint) {
  const material::Material& m = assets.materials[index];
  glm::vec3 e = m.emission();
  if (m.emissive_texture >= 0 && (e.r > 0 || e.g > 0 || e.b > 0))
    e *= glm::vec3(sample_texture(assets.textures[static_cast<std::size_t>(m.emissive_texture)], uv, true, footprint));
  return e;
}

Surface make_surface(const rt::RtScene& scene, const rt::Hit& hit, const glm::vec3& incoming_dir) {
  const rt::InstanceRecord& inst = *scene.instance_of(hit);
  const scene::SceneAssets& assets = *scene.assets();
  const scene::MeshAsset& mesh = *assets.meshes[hit.mesh];
  const glm::uvec3 t = mesh.triangles[hit.primitive];
  const float b1 = hit.barycentric.x, b2 = hit.barycentric.y, b0 = 1.0f - b1 - b2;

  Surface s;
  const glm::vec3 p0 = inst.to_world.apply_point(mesh.positions[t.x]);
  const glm::vec3 p1 = inst.to_world.apply_point(mesh.positions[t.y]);
  const glm::vec3 p2 = inst.to_world.apply_point(mesh.positions[t.z]);
  s.position = b0 * p0 + b1 * p1 + b2 * p2;
  glm::vec3 ng = glm::cross(p1 - p0, p2 - p0);
  const float len = glm::length(ng);
  ng = len > 0 ? ng / len : glm::vec3(0, 0, 1);
  glm::vec3 ns = inst.to_world.apply_direction(b0 * mesh.normals[t.x] + b1 * mesh.normals[t.y] + b2 * mesh.normals[t.z]);
  const float ns_len = glm::length(ns);
  ns = ns_len > 0 ? ns / ns_len : ng;
  s.material = mesh.triangle_material[hit.primitive];
  const bool behind = glm::dot(ng, incoming_dir) > 0;
  // Only a single-sided material has an inside; a double-sided one met from
  // behind is a surface like any other (mixed winding in real content).
  s.back_face = behind && !assets.materials[s.material].double_sided;
  if (behind) ng = -ng;  // face the viewer
  if (glm::dot(ns, ng) < 0) ns = -ns;            // shading normal on the same side
  s.geometric_normal = ng;
  s.shading_normal = ns;
  s.frame = math::Frame::from_normal(ns);
  if (!mesh.uvs.empty()) s.uv = b0 * mesh.uvs[t.x] + b1 * mesh.uvs[t.y] + b2 * mesh.uvs[t.z];
  s.brdf = evaluate_material(assets, s.material, s.uv);
  s.emission = evaluate_emission(assets, s.material, s.uv);
  s.area_scale = inst.to_world.scale * inst.to_world.scale;
  return s;
}

}  // namespace engine::render
