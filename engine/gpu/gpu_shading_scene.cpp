#include "engine/gpu/gpu_shading_scene.h"

#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstring>
#include <string>
#include <glm/gtc/quaternion.hpp>

#include "engine/gpu/gpu_error.h"
#include "engine/material/specular_albedo.h"
#include "engine/scene/environment.h"
#include "engine/scene/texture.h"
#include "shading_shared.h"

namespace engine::gpu {
namespace {

// `what` names the data in the error where it is larger than a kernel can bind.
template <class T>
void upload_to(VulkanContext& ctx, GpuBuffer& b, std::vector<T> v, GpuBuffer::Placement placement, const char* what) {
  if (v.empty()) v.push_back(T{});  // a binding needs a buffer
  const std::size_t bytes = v.size() * sizeof(T);
  require_storage_range(ctx, bytes, "GpuShadingScene", what);
  if (b.handle() == VK_NULL_HANDLE || b.size() < bytes) b = GpuBuffer(ctx, bytes, placement);
  b.upload(std::span<const T>(v));
}

constexpr GpuBuffer::Placement kStatic = GpuBuffer::Placement::DeviceOnly;
constexpr GpuBuffer::Placement kPerFrame = GpuBuffer::Placement::Mapped;

std::uint32_t wrap_bits(const scene::Texture& t) {
  return static_cast<std::uint32_t>(t.wrap_s) | static_cast<std::uint32_t>(t.wrap_t) << 8;
}

// Rows of a column-major glm matrix.
void rows_of(const glm::mat3& m, float* r0, float* r1, float* r2) {
  for (int c = 0; c < 3; ++c) {
    r0[c] = m[c][0];
    r1[c] = m[c][1];
    r2[c] = m[c][2];
  }
}

// Rows of m as three (x, y, z, pad) groups of the header from byte `offset`.
void put_rows(LightSetGpu& h, std::size_t offset, const glm::mat3& m) {
  for (int r = 0; r < 3; ++r) {
    const float row[4] = {m[0][r], m[1][r], m[2][r], 0.0f};
    std::memcpy(reinterpret_cast<char*>(&h) + offset + static_cast<std::size_t>(r) * sizeof(row), row, sizeof(row));
  }
}

std::uint32_t punctual_type(scene::PunctualLight::Type t) {
  switch (t) {
    case scene::PunctualLight::Type::Spot:
      return kPunctualSpot;
    case scene::PunctualLight::Type::Directional:
      return kPunctualDirectional;
    case scene::PunctualLight::Type::Point:
    default:
      return kPunctualPoint;
  }
}

// A distribution's densities as Distribution1D::pdf returns them per bin.
float bin_pdf(const math::Distribution1D& d, std::size_t i) {
  return d.integral() > 0 ? static_cast<float>(d.func()[i] / d.integral()) : 1.0f;
}

}  // namespace

void GpuShadingScene::sync(const rt::RtScene& rt, const render::LightSet& lights) {
  const scene::SceneAssets* assets = rt.assets();
  if (!assets) throw GpuError("GpuShadingScene::sync: the ray-tracing scene has no assets");
  if (assets->generation != generation_) {
    sync_assets(*assets);
    generation_ = assets->generation;
  }
  std::vector<ShadingInstanceGpu> instances(rt.instance_id_end());
  for (std::uint32_t id = 0; id < rt.instance_id_end(); ++id) {
    const rt::InstanceRecord* r = rt.instance(id);
    if (!r) continue;
    ShadingInstanceGpu& g = instances[id];
    const glm::mat3 rot = glm::mat3_cast(r->to_world.rotation);
    float r0[3], r1[3], r2[3];
    rows_of(rot, r0, r1, r2);
    g = {r0[0], r0[1], r0[2], r->to_world.translation.x, r1[0], r1[1], r1[2], r->to_world.translation.y,
         r2[0], r2[1], r2[2], r->to_world.translation.z, r->to_world.scale, r->mesh, 1u, 0u};
  }
  upload_to(ctx_, instances_, std::move(instances), kPerFrame, "instances");
  sync_lights(lights);
}

void GpuShadingScene::sync_assets(const scene::SceneAssets& assets) {
  std::vector<std::uint32_t> mesh_first(assets.meshes.size());
  std::vector<ShadingTriangleGpu> tris;
  for (std::size_t m = 0; m < assets.meshes.size(); ++m) {
    const scene::MeshAsset& mesh = *assets.meshes[m];
    mesh_first[m] = static_cast<std::uint32_t>(tris.size());
    const bool has_uv = !mesh.uvs.empty();
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
      const glm::uvec3 v = mesh.triangles[t];
      const glm::vec3 &p0 = mesh.positions[v.x], &p1 = mesh.positions[v.y], &p2 = mesh.positions[v.z];
      const glm::vec3 &n0 = mesh.normals[v.x], &n1 = mesh.normals[v.y], &n2 = mesh.normals[v.z];
      const glm::vec2 u0 = has_uv ? mesh.uvs[v.x] : glm::vec2(0.0f), u1 = has_uv ? mesh.uvs[v.y] : glm::vec2(0.0f),
                      u2 = has_uv ? mesh.uvs[v.z] : glm::vec2(0.0f);
      const std::uint32_t material = t < mesh.triangle_material.size() ? mesh.triangle_material[t] : 0;
      tris.push_back({p0.x, p0.y, p0.z, material, p1.x, p1.y, p1.z, has_uv ? 1u : 0u, p2.x, p2.y, p2.z, 0.0f,
                      n0.x, n0.y, n0.z, n1.x, n1.y, n1.z, n2.x, n2.y, n2.z, u0.x, u0.y, u1.x, u1.y, u2.x, u2.y, 0.0f});
    }
  }
  std::vector<MaterialGpu> materials;
  for (const material::Material& m : assets.materials) {
    const glm::vec3 e = m.emission();
    materials.push_back({m.base_color_factor.r, m.base_color_factor.g, m.base_color_factor.b, m.base_color_factor.a,
                         m.metallic_factor, m.roughness_factor, m.specular_factor, m.base_color_texture,
                         m.specular_color_factor.r, m.specular_color_factor.g, m.specular_color_factor.b,
                         m.metallic_roughness_texture, e.r, e.g, e.b, m.emissive_texture, m.double_sided ? 1u : 0u, 0u, 0u,
                         0u});
  }
  std::vector<TextureGpu> textures;
  std::vector<std::uint32_t> texels;
  for (const scene::Texture& t : assets.textures) {
    const std::size_t n = t.width > 0 && t.height > 0 ? static_cast<std::size_t>(t.width) * static_cast<std::size_t>(t.height) : 0;
    textures.push_back({static_cast<std::uint32_t>(texels.size()), n ? t.width : 0, n ? t.height : 0,
                        wrap_bits(t) | (t.cut_out ? 1u << 16 : 0u)});
    for (std::size_t i = 0; i < n; ++i) {
      const std::uint8_t* p = &t.rgba[i * 4];
      texels.push_back(std::uint32_t{p[0]} | std::uint32_t{p[1]} << 8 | std::uint32_t{p[2]} << 16 | std::uint32_t{p[3]} << 24);
    }
  }
  std::vector<float> tables(kShadingTableFloats);
  const float* srgb = scene::srgb_decode_table();
  for (std::uint32_t i = 0; i < 256; ++i) tables[kShadingSrgbLut + i] = srgb[i];
  const material::SpecularAlbedo* dir = material::ggx_albedo_directional_table();
  for (std::uint32_t i = 0; i < kShadingAlbedoMu * kShadingAlbedoAlpha; ++i) {
    tables[kShadingAlbedoDirectional + 2 * i] = dir[i].a;
    tables[kShadingAlbedoDirectional + 2 * i + 1] = dir[i].b;
  }
  const material::SpecularAlbedo* avg = material::ggx_albedo_average_table();
  for (std::uint32_t j = 0; j < kShadingAlbedoAlpha; ++j) {
    tables[kShadingAlbedoAverage + 2 * j] = avg[j].a;
    tables[kShadingAlbedoAverage + 2 * j + 1] = avg[j].b;
  }
  upload_to(ctx_, mesh_first_, std::move(mesh_first), kStatic, "meshes");
  upload_to(ctx_, triangles_, std::move(tris), kStatic, "triangles");
  upload_to(ctx_, materials_, std::move(materials), kStatic, "materials");
  upload_to(ctx_, textures_, std::move(textures), kStatic, "textures");
  upload_to(ctx_, texels_, std::move(texels), kStatic, "texels");
  upload_to(ctx_, tables_, std::move(tables), kStatic, "shading tables");
}

void GpuShadingScene::sync_lights(const render::LightSet& lights) {
  LightSetGpu h{};
  h.groups = lights.groups();
  const auto& tris = lights.emissive_triangles();
  h.triangles = static_cast<int>(tris.size());
  h.punctual = static_cast<int>(lights.punctual_count());

  std::vector<EmissiveTriangleGpu> emissive;
  std::vector<float> cdf;
  if (!tris.empty()) {
    const math::Distribution1D& d = lights.triangle_distribution();
    for (std::size_t i = 0; i < tris.size(); ++i) {
      const render::EmissiveTriangle& t = tris[i];
      emissive.push_back({t.p0.x, t.p0.y, t.p0.z, t.material, t.p1.x, t.p1.y, t.p1.z, t.area, t.p2.x, t.p2.y, t.p2.z,
                          bin_pdf(d, i), t.uv0.x, t.uv0.y, t.uv1.x, t.uv1.y, t.uv2.x, t.uv2.y, 0.0f, 0.0f});
    }
    for (double c : d.cdf()) cdf.push_back(static_cast<float>(c));
  }
  std::vector<PunctualLightGpu> punctual;
  for (const render::PunctualInstance& p : lights.punctual_lights()) {
    const scene::PunctualLight& l = p.light;
    const glm::vec3 power = l.color * l.intensity;
    punctual.push_back({p.position.x, p.position.y, p.position.z, punctual_type(l.type), p.direction.x, p.direction.y,
                        p.direction.z, l.range, power.r, power.g, power.b, p.angular_radius, std::cos(l.inner_cone_angle),
                        std::cos(l.outer_cone_angle), 0.0f, 0.0f});
  }

  const scene::Environment* env = lights.environment();
  h.has_environment = env ? 1 : 0;
  if (env) {
    const image::ImageRGB& img = env->image();
    const int w = img.width, ht = img.height;
    h.env_width = w;
    h.env_height = ht;
    h.env_strength = env->strength();
    put_rows(h, offsetof(LightSetGpu, to_world_r0_x), env->to_world_matrix());
    put_rows(h, offsetof(LightSetGpu, to_local_r0_x), env->to_local_matrix());
    const std::size_t texels = static_cast<std::size_t>(w) * static_cast<std::size_t>(ht);
    h.env_texels = 0;
    h.env_alias = static_cast<std::uint32_t>(3 * texels);
    // The texels and distribution are what an environment is loaded with;
    // turning or dimming the sky changes only the header.
    if (img.pixels.data() != env_pixels_ || w != env_width_ || ht != env_height_) {
      std::vector<float> t;
      t.reserve(h.env_alias + 4 * texels);
      for (int y = 0; y < ht; ++y)
        for (int x = 0; x < w; ++x) {
          const glm::vec3 c = img.at(x, y);
          t.insert(t.end(), {c.r, c.g, c.b});
        }
      for (const math::AliasDistribution2D::Entry& e : env->distribution().entries())
        t.insert(t.end(), {e.threshold, std::bit_cast<float>(e.alias), e.pdf, e.alias_pdf});
      if (t.size() != h.env_alias + 4 * texels) throw GpuError("GpuShadingScene: environment tables of unexpected size");
      upload_to(ctx_, light_tables_, std::move(t), kStatic, "environment map's tables");
      env_pixels_ = img.pixels.data();
      env_width_ = w;
      env_height_ = ht;
    }
  } else if (light_tables_.handle() == VK_NULL_HANDLE) {
    upload_to(ctx_, light_tables_, std::vector<float>{}, kStatic, "environment map's tables");
  }
  upload_to(ctx_, light_set_, std::vector<LightSetGpu>{h}, kPerFrame, "light set");
  upload_to(ctx_, emissive_, std::move(emissive), kPerFrame, "emissive triangles");
  upload_to(ctx_, triangle_cdf_, std::move(cdf), kPerFrame, "emissive triangles' distribution");
  upload_to(ctx_, punctual_, std::move(punctual), kPerFrame, "punctual lights");
}

void GpuShadingScene::bind(ComputePipeline& pipeline, std::uint32_t first) const {
  if (light_set_.handle() == VK_NULL_HANDLE) throw GpuError("GpuShadingScene::bind before sync");
  const GpuBuffer* order[kBindings] = {&instances_, &mesh_first_, &triangles_, &materials_, &textures_, &texels_,
                                       &tables_,    &light_set_,  &emissive_,  &punctual_,  &light_tables_, &triangle_cdf_};
  for (std::uint32_t i = 0; i < kBindings; ++i) pipeline.bind(first + i, *order[i]);
}

}  // namespace engine::gpu
