#include "engine/render/surface.h"

namespace engine::render {

material::BrdfParams evaluate_material(const scene::SceneAssets& assets, std::uint32_t index, glm::vec2 uv) {
  const material::Material& m = assets.materials[index];
  material::BrdfParams p;
  glm::vec4 base = m.base_color_factor;
  if (m.base_color_texture >= 0) base *= assets.textures[static_cast<std::size_t>(m.base_color_texture)].sample(uv, true);
  p.base_color = glm::vec3(base);
  p.metallic = m.metallic_factor;
  p.roughness = m.roughness_factor;
  if (m.metallic_roughness_texture >= 0) {
    const glm::vec4 mr = assets.textures[static_cast<std::size_t>(m.metallic_roughness_texture)].sample(uv, false);
    p.roughness *= mr.g;
    p.metallic *= mr.b;
  }
  p.specular = m.specular_factor;
  p.specular_color = m.specular_color_factor;
  return p;
}

glm::vec3 evaluate_emission(const scene::SceneAssets& assets, std::uint32_t index, glm::vec2 uv) {
  const material::Material& m = assets.materials[index];
  glm::vec3 e = m.emission();
  if (m.emissive_texture >= 0 && (e.r > 0 || e.g > 0 || e.b > 0))
    e *= glm::vec3(assets.textures[static_cast<std::size_t>(m.emissive_texture)].sample(uv, true));
  return e;
}

Surface make_surface(const rt::RtScene& scene, const rt::Hit& hit, const glm::vec3& incoming_dir) {
  const rt::InstanceRecord& inst = *scene.instance_of(hit.entity);
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
