#include "engine/render/light_set.h"

#include <algorithm>
#include <cmath>

#include "engine/math/sampling.h"
#include "engine/render/surface.h"
#include "engine/transform/transform.h"

namespace engine::render {

namespace {
std::uint64_t key(ecs::Entity e, std::uint32_t prim) { return (std::uint64_t{e.index} << 32) | prim; }

// glTF's recommended range window and spot cone falloff.
float range_window(float dist, float range) {
  if (range <= 0) return 1.0f;
  const float r = dist / range;
  return std::clamp(1.0f - r * r * r * r, 0.0f, 1.0f);
}
float spot_falloff(const scene::PunctualLight& l, float cos_angle) {
  const float cos_outer = std::cos(l.outer_cone_angle), cos_inner = std::cos(l.inner_cone_angle);
  if (cos_inner - cos_outer < 1e-6f) return cos_angle >= cos_outer ? 1.0f : 0.0f;
  const float t = std::clamp((cos_angle - cos_outer) / (cos_inner - cos_outer), 0.0f, 1.0f);
  return t * t;
}
}  // namespace

LightSet::LightSet(const rt::RtScene& scene, std::vector<PunctualInstance> punctual, const scene::Environment* env,
                   std::shared_ptr<const scene::SunSplit> sun_split)
    : punctual_(std::move(punctual)), env_(env && env->valid() ? env : nullptr) {
  background_ = env_;
  if (env_ && sun_split && sun_split->sun) {
    const scene::ExtractedSun& sun = *sun_split->sun;
    scene::PunctualLight light;
    light.type = scene::PunctualLight::Type::Directional;
    light.color = sun.irradiance;
    light.intensity = 1.0f;
    split_sun_index_ = static_cast<int>(punctual_.size());
    punctual_.push_back(PunctualInstance{light, glm::vec3(0.0f), -sun.direction, sun.angular_radius});
    sun_split_ = std::move(sun_split);
    env_ = &sun_split_->residual;
  }
  std::vector<float> power;
  assets_ = scene.assets();
  if (const scene::SceneAssets* assets = assets_) {
    scene.for_each_instance([&](const rt::InstanceRecord& inst) {
      const scene::MeshAsset& mesh = *assets->meshes[inst.mesh];
      for (std::uint32_t t = 0; t < mesh.triangles.size(); ++t) {
        const std::uint32_t mat = mesh.triangle_material[t];
        if (!assets->materials[mat].is_emissive()) continue;
        EmissiveTriangle tri;
        tri.p0 = inst.to_world.apply_point(mesh.positions[mesh.triangles[t].x]);
        tri.p1 = inst.to_world.apply_point(mesh.positions[mesh.triangles[t].y]);
        tri.p2 = inst.to_world.apply_point(mesh.positions[mesh.triangles[t].z]);
        tri.area = 0.5f * glm::length(glm::cross(tri.p1 - tri.p0, tri.p2 - tri.p0));
        if (!(tri.area > 0)) continue;
        tri.emission = assets->materials[mat].emission();
        tri.material = mat;
        if (!mesh.uvs.empty()) {
          tri.uv0 = mesh.uvs[mesh.triangles[t].x];
          tri.uv1 = mesh.uvs[mesh.triangles[t].y];
          tri.uv2 = mesh.uvs[mesh.triangles[t].z];
        }
        triangle_of_[key(inst.entity, t)] = static_cast<std::uint32_t>(triangles_.size());
        triangles_.push_back(tri);
        power.push_back(math::luminance(tri.emission) * tri.area);
      }
    });
  }
  if (!triangles_.empty()) triangle_distribution_ = math::Distribution1D(power);
  groups_ = (env_ ? 1 : 0) + (triangles_.empty() ? 0 : 1) + (punctual_.empty() ? 0 : 1);
}

bool LightSet::sample(const glm::vec3& p, float u_select, glm::vec2 u, LightSample& out) const {
  if (groups_ == 0) return false;
  int group = std::min(groups_ - 1, static_cast<int>(u_select * static_cast<float>(groups_)));
  const float pg = group_probability();
  // Groups in fixed order: environment, area lights, punctual lights.
  if (env_ && group-- == 0) {
    float pdf = 0;
    glm::vec3 dir;
    out.radiance = env_->sample(u, &dir, &pdf);
    out.direction = dir;
    out.distance = std::numeric_limits<float>::infinity();
    out.pdf = pdf * pg;
    out.delta = false;
    return pdf > 0;
  }
  if (!triangles_.empty() && group-- == 0) {
    return sample_area_light(p, u, pg, out);
  }
  if (!punctual_.empty()) {
    const float n = static_cast<float>(punctual_.size());
    const std::size_t i = std::min(punctual_.size() - 1, static_cast<std::size_t>(u.x * n));
    // The rest of u.x after selection places the point on a sun's disk.
    const float ux = std::clamp(u.x * n - static_cast<float>(i), 0.0f, 0.99999994f);
    if (!sample_punctual(i, p, {ux, u.y}, out)) return false;
    out.radiance /= pg / n;
    return true;
  }
  return false;
}

bool LightSet::sample_area_light(const glm::vec3& p, glm::vec2 u, LightSample& out) const {
  return sample_area_light(p, u, 1.0f, out);
}

bool LightSet::sample_area_light(const glm::vec3& p, glm::vec2 u, float group_pdf, LightSample& out) const {
  if (triangles_.empty()) return false;
  float tri_pdf = 0;
  std::size_t i = 0;
  // Reuse u.x for selection and stretch the remainder back to [0, 1).
  const float x = triangle_distribution_.sample_continuous(u.x, &tri_pdf, &i);
  const float n = static_cast<float>(triangles_.size());
  const float ux = std::clamp(x * n - static_cast<float>(i), 0.0f, 0.99999994f);
  const EmissiveTriangle& t = triangles_[i];
  const glm::vec2 b = math::sample_uniform_triangle({ux, u.y});
  const glm::vec3 q = (1 - b.x - b.y) * t.p0 + b.x * t.p1 + b.y * t.p2;
  glm::vec3 d = q - p;
  const float dist2 = glm::dot(d, d);
  if (!(dist2 > 0)) return false;
  const float dist = std::sqrt(dist2);
  d /= dist;
  const glm::vec3 n_light = glm::normalize(glm::cross(t.p1 - t.p0, t.p2 - t.p0));
  const float cos_l = std::abs(glm::dot(n_light, d));
  if (cos_l <= 1e-7f) return false;
  // Selection pdf of the triangle (its share of the total power) / area, to solid angle.
  const float p_tri = tri_pdf / n;
  out.pdf = group_pdf * p_tri / t.area * dist2 / cos_l;
  out.radiance = evaluate_emission(*assets_, t.material, (1 - b.x - b.y) * t.uv0 + b.x * t.uv1 + b.y * t.uv2);
  out.direction = d;
  out.distance = dist;
  out.delta = false;
  return true;
}

bool LightSet::sample_punctual(std::size_t i, const glm::vec3& p, glm::vec2 u, LightSample& out) const {
  if (i >= punctual_.size()) return false;
  const PunctualInstance& l = punctual_[i];
  const glm::vec3 power = l.light.color * l.light.intensity;
  out.delta = true;
  out.pdf = 0;
  if (l.light.type == scene::PunctualLight::Type::Directional) {
    out.direction = -l.direction;
    if (l.angular_radius > 0)  // a direction uniform over the disk
      out.direction = math::Frame::from_normal(-l.direction).to_world(math::sample_uniform_cone(u, std::cos(l.angular_radius)));
    out.distance = std::numeric_limits<float>::infinity();
    out.radiance = power;
    return true;
  }
  glm::vec3 d = l.position - p;
  const float dist2 = glm::dot(d, d);
  if (!(dist2 > 0)) return false;
  const float dist = std::sqrt(dist2);
  d /= dist;
  float atten = range_window(dist, l.light.range) / dist2;
  if (l.light.type == scene::PunctualLight::Type::Spot) atten *= spot_falloff(l.light, glm::dot(l.direction, -d));
  out.direction = d;
  out.distance = dist;
  out.radiance = power * atten;
  return atten > 0;
}

float LightSet::pdf_area_light(ecs::Entity entity, std::uint32_t primitive, const glm::vec3& dir, float dist,
                               const glm::vec3& light_normal) const {
  auto it = triangle_of_.find(key(entity, primitive));
  if (it == triangle_of_.end()) return 0.0f;
  const EmissiveTriangle& t = triangles_[it->second];
  const float cos_l = std::abs(glm::dot(light_normal, dir));
  if (cos_l <= 1e-7f) return 0.0f;
  const float p_tri = triangle_distribution_.pdf((static_cast<float>(it->second) + 0.5f) /
                                                 static_cast<float>(triangles_.size())) /
                      static_cast<float>(triangles_.size());
  return group_probability() * p_tri / t.area * dist * dist / cos_l;
}

float LightSet::pdf_environment(const glm::vec3& dir) const {
  return env_ ? group_probability() * env_->pdf(dir) : 0.0f;
}

std::optional<PunctualInstance> punctual_instance(const scene::PunctualLight& l, const transform::Similarity& w) {
  if (!l.enabled || l.intensity <= 0) return std::nullopt;
  return PunctualInstance{l, w.translation, glm::normalize(w.apply_direction({0, 0, -1})),
                          l.type == scene::PunctualLight::Type::Directional ? l.angular_radius : 0.0f};
}

std::vector<PunctualInstance> gather_punctual_lights(ecs::World& world) {
  std::vector<PunctualInstance> out;
  world.view<const scene::PunctualLight, const transform::WorldTransform>().each(
      [&](const scene::PunctualLight& l, const transform::WorldTransform& w) {
        if (auto p = punctual_instance(l, w)) out.push_back(*p);
      });
  return out;
}

}  // namespace engine::render
