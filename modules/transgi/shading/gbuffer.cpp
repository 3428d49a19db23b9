#include "shading/gbuffer.h"

#include <glm/gtc/quaternion.hpp>

#include "engine/render/surface.h"

namespace transgi::shading {

GSample trace_gsample(const engine::rt::RtScene& scene, const engine::scene::SceneAssets& assets,
                      const engine::rt::Ray& ray, const engine::scene::Environment* background, float spread) {
  engine::rt::Hit hit;
  const bool found = scene.intersect(ray, hit);
  return make_gsample(scene, assets, ray, found ? &hit : nullptr, background, spread);
}

GSample make_gsample(const engine::rt::RtScene& scene, const engine::scene::SceneAssets& assets,
                     const engine::rt::Ray& ray, const engine::rt::Hit* found, const engine::scene::Environment* background,
                     float spread) {
  GSample out;
  make_gsample(scene, assets, ray, found, background, spread, out);
  return out;
}

void make_gsample(const engine::rt::RtScene& scene, const engine::scene::SceneAssets& assets, const engine::rt::Ray& ray,
                  const engine::rt::Hit* found, const engine::scene::Environment* background, float spread, GSample& out) {
  using namespace engine;
  if (!found) {
    out = GSample{};
    if (background) out.background = background->radiance(ray.direction);
    return;
  }
  const rt::Hit& hit = *found;
  const rt::InstanceRecord& inst = *scene.instance_of(hit);
  const scene::MeshAsset& mesh = *assets.meshes[hit.mesh];
  const glm::uvec3 t = mesh.triangles[hit.primitive];
  const float b1 = hit.barycentric.x, b2 = hit.barycentric.y, b0 = 1 - b1 - b2;
  glm::vec3 nobj = glm::normalize(b0 * mesh.normals[t.x] + b1 * mesh.normals[t.y] + b2 * mesh.normals[t.z]);
  // One normalisation per direction: rotations keep unit vectors unit, so
  // the object-space view and the world normals need none of their own.
  const glm::vec3 wo_world = glm::normalize(-ray.direction);
  const glm::quat inv = glm::conjugate(inst.to_world.rotation);
  const glm::vec3 wo = inv * wo_world;
  if (glm::dot(nobj, wo) < 0) nobj = -nobj;  // seen from the back of a two-sided surface
  out.normal_obj = nobj;
  out.wo_obj = wo;
  out.position = ray.origin + hit.t * ray.direction;
  out.normal_world = inst.to_world.apply_direction(nobj);
  out.wo_world = wo_world;
  glm::vec3 ng = glm::cross(mesh.positions[t.y] - mesh.positions[t.x], mesh.positions[t.z] - mesh.positions[t.x]);
  const float ng_length = glm::length(ng);
  ng = ng_length > 0 ? inst.to_world.apply_direction(ng / ng_length) : out.normal_world;
  const float ng_dot_wo = glm::dot(ng, out.wo_world);
  set_gsample_material(assets, hit, mesh, inst.to_world.scale, spread, ng_dot_wo, out);
  out.geometric_normal = ng_dot_wo < 0 ? -ng : ng;
}

void set_gsample_material(const engine::scene::SceneAssets& assets, const engine::rt::Hit& hit, const engine::scene::MeshAsset& mesh,
                          float instance_scale, float spread, float ng_dot_wo, GSample& out) {
  using namespace engine;
  const float b1 = hit.barycentric.x, b2 = hit.barycentric.y, b0 = 1 - b1 - b2;
  glm::vec2 uv(0.0f);
  if (!mesh.uvs.empty()) {
    const glm::uvec3 t = mesh.triangles[hit.primitive];
    uv = b0 * mesh.uvs[t.x] + b1 * mesh.uvs[t.y] + b2 * mesh.uvs[t.z];
  }
  out.hit = true;
  out.background = glm::vec3(0.0f);
  out.entity = hit.entity;
  out.mesh = hit.mesh;
  out.triangle = hit.primitive;
  out.bary = hit.barycentric;
  const std::uint32_t material = mesh.triangle_material[hit.primitive];
  const float footprint = spread > 0 && assets.materials[material].is_textured()
                              ? render::uv_footprint(mesh, hit.primitive, instance_scale, hit.t * spread, ng_dot_wo)
                              : 0.0f;
  out.brdf = render::evaluate_material(assets, material, uv, footprint);
  out.albedo = out.brdf.base_color;  // the network's input
  out.diffuse = material::diffuse_albedo(out.brdf);
  out.emission = render::evaluate_emission(assets, material, uv, footprint);
  out.depth = hit.t;
}

}  // namespace transgi::shading
