// make_gsamples (a camera tile's G-buffer samples in SIMD lanes) against
// make_gsample, its scalar oracle: every field of every sample, and every
// side-array entry it writes beside them, equal bit for bit, at whichever instruction set the dispatch runs (CTest runs this suite
// again capped at AVX2 and at scalar). The scene has what each branch needs:
// textured walls under rotated and scaled instances (the mip footprint), one
// seen from the back (the normal turns to the viewer), a sphere with
// interpolated normals, a metal (diffuse albedo 0), an emitter, and sky
// (misses); and hand-made hits on a triangle with no area, which no ray
// finds (the geometric normal falls back to the shading normal).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>

#include <glm/gtc/quaternion.hpp>

#include "engine/app/app.h"
#include "engine/render/camera_rays.h"
#include "engine/rt/rt_plugin.h"
#include "engine/scene/components.h"
#include "engine/scene/procedural.h"
#include "lambert.h"
#include "shading/gbuffer.h"

using namespace engine;
namespace shading = transgi::shading;

namespace {

struct TileScene {
  app::App app{app::AppOptions{.jobs = {.threads = 2}}};
  ecs::Entity camera;

  TileScene() {
    scene::SceneAssets a;
    a.generation = scene::next_scene_generation();
    // The box's first triangle collapsed to a line: no area.
    auto box = std::make_shared<scene::MeshAsset>(scene::make_box({0.3f, 0.3f, 0.3f}, false, 2));
    const glm::uvec3 first = box->triangles[0];
    box->positions[first.z] = 0.5f * (box->positions[first.x] + box->positions[first.y]);
    a.meshes = {std::make_shared<scene::MeshAsset>(scene::make_quad({1, 1}, 0)),
                std::make_shared<scene::MeshAsset>(scene::make_uv_sphere(0.5f, 24, 12, 1)), std::move(box)};
    scene::Texture t;
    t.width = t.height = 64;
    t.rgba.resize(64 * 64 * 4);
    for (int y = 0; y < 64; ++y)
      for (int x = 0; x < 64; ++x) {
        std::uint8_t* p = &t.rgba[(static_cast<std::size_t>(y) * 64 + x) * 4];
        p[0] = static_cast<std::uint8_t>(x * 4);
        p[1] = static_cast<std::uint8_t>(y * 4);
        p[2] = static_cast<std::uint8_t>(((x / 4 + y / 4) & 1) * 255);
        p[3] = 255;
      }
    t.build_mips(true);
    a.textures = {std::move(t)};
    material::Material wall = lambert(glm::vec3(1));
    wall.base_color_texture = 0;
    material::Material metal;
    metal.base_color_factor = glm::vec4(0.9f, 0.6f, 0.2f, 1);
    metal.metallic_factor = 1;
    metal.roughness_factor = 0.3f;
    material::Material lamp = lambert(glm::vec3(0.5f));
    lamp.emissive_factor = glm::vec3(2.0f, 1.5f, 1.0f);
    lamp.specular_factor = 0.5f;  // a glossy dielectric: finite dielectric_roughness
    lamp.roughness_factor = 0.4f;
    a.materials = {wall, metal, lamp};
    app.world().insert_resource<scene::SceneAssets>(std::move(a));
    app.add_plugin<rt::RtPlugin>();
    ecs::World& w = app.world();
    const auto place = [&](std::uint32_t mesh, const transform::Transform& at) {
      const ecs::Entity e = w.spawn();
      w.emplace<transform::Transform>(e, at);
      w.emplace<scene::MeshInstance>(e, scene::MeshInstance{mesh});
    };
    transform::Transform wall_at = transform::Transform::from_translation({0.2f, -0.4f, -0.3f});
    wall_at.rotation = glm::angleAxis(0.7f, glm::normalize(glm::vec3(0.3f, 1.0f, 0.2f)));
    wall_at.scale = 1.7f;
    place(0, wall_at);
    // A second wall turned upside down: the camera sees its back.
    transform::Transform under_at = transform::Transform::from_translation({-0.9f, -0.9f, 0.4f});
    under_at.rotation = glm::angleAxis(2.9f, glm::vec3(1.0f, 0.0f, 0.0f));
    under_at.scale = 0.8f;
    place(0, under_at);
    transform::Transform sphere_at = transform::Transform::from_translation({-0.6f, 0.3f, 0.6f});
    sphere_at.rotation = glm::angleAxis(-1.1f, glm::normalize(glm::vec3(1.0f, 0.2f, -0.5f)));
    place(1, sphere_at);
    transform::Transform box_at = transform::Transform::from_translation({0.7f, 0.4f, 0.8f});
    box_at.rotation = glm::angleAxis(2.3f, glm::normalize(glm::vec3(-0.2f, 0.8f, 0.4f)));
    box_at.scale = 0.6f;
    place(2, box_at);
    // The camera inside the sphere's far side for a corner of the view: it
    // sees the sphere's inner wall there.
    transform::Transform ct = transform::Transform::from_translation({-0.3f, 0.5f, 3.0f});
    ct.rotation = glm::quatLookAt(glm::normalize(glm::vec3(0.1f, -0.3f, -1.0f)), glm::vec3(0, 1, 0));
    camera = w.spawn();
    w.emplace<transform::Transform>(camera, ct);
    w.emplace<scene::Camera>(camera, scene::Camera{.yfov_radians = 1.2f});
    app.update();
  }
};

bool same_bits(const shading::GSample& a, const shading::GSample& b) {
  const auto eq = [](const auto& x, const auto& y) { return std::memcmp(&x, &y, sizeof(x)) == 0; };
  return a.hit == b.hit && a.entity == b.entity && a.mesh == b.mesh && a.triangle == b.triangle && eq(a.bary, b.bary) &&
         eq(a.normal_obj, b.normal_obj) && eq(a.wo_obj, b.wo_obj) && eq(a.albedo, b.albedo) && eq(a.diffuse, b.diffuse) &&
         eq(a.background, b.background) && eq(a.position, b.position) && eq(a.normal_world, b.normal_world) &&
         eq(a.brdf.base_color, b.brdf.base_color) && eq(a.brdf.metallic, b.brdf.metallic) &&
         eq(a.brdf.roughness, b.brdf.roughness) && eq(a.brdf.specular, b.brdf.specular) &&
         eq(a.brdf.specular_color, b.brdf.specular_color) && eq(a.emission, b.emission) &&
         eq(a.geometric_normal, b.geometric_normal) && eq(a.wo_world, b.wo_world) && eq(a.depth, b.depth);
}

}  // namespace

TEST(GSampleTile, EveryFieldEqualsTheScalarSamplesBitForBit) {
  TileScene scene;
  const auto& rt = scene.app.world().resource<rt::RtScene>();
  const auto& assets = scene.app.world().resource<scene::SceneAssets>();
  const int width = 96, height = 64;
  const render::CameraRays camera(scene.app.world().get<scene::Camera>(scene.camera),
                                  scene.app.world().get<transform::WorldTransform>(scene.camera), width, height);
  const float spread = camera.pixel_spread();
  int tiles = 0, hits = 0, misses = 0, turned = 0, textured = 0, different = 0, different_sides = 0, glossy = 0, metallic = 0;
  rt::Hit on_box{};
  bool box_seen = false;
  const auto compare_tile = [&](const rt::Ray* rays, const rt::Hit* found_hits, const bool* found, int count) {
    shading::GSample tile[shading::kGSampleTile], oracle[shading::kGSampleTile];
    shading::GSample* out[shading::kGSampleTile];
    for (int i = 0; i < count; ++i) {
      out[i] = &tile[i];
      tile[i].depth = -1;  // every field must be written over
      shading::make_gsample(rt, assets, rays[i], found[i] ? &found_hits[i] : nullptr, nullptr, spread, oracle[i]);
    }
    // The side arrays, each entry first set to a value no sample gives.
    std::size_t pixel[shading::kGSampleTile];
    glm::vec4 guide[shading::kGSampleTile];
    glm::vec3 position[shading::kGSampleTile], albedo[shading::kGSampleTile];
    float metal[shading::kGSampleTile], dielectric[shading::kGSampleTile];
    ecs::Entity entity[shading::kGSampleTile];
    for (int i = 0; i < count; ++i) {
      pixel[i] = static_cast<std::size_t>(count - 1 - i);  // lanes land at other indices
      guide[i] = glm::vec4(-7.0f);
      position[i] = albedo[i] = glm::vec3(-7.0f);
      metal[i] = dielectric[i] = -7.0f;
      entity[i] = scene.camera;
    }
    const shading::GSampleSideArrays sides{pixel, guide, position, albedo, metal, dielectric, entity};
    shading::make_gsamples(rt, assets, rays, found_hits, found, count, spread, out, &sides);
    ++tiles;
    for (int i = 0; i < count; ++i) {
      if (!same_bits(tile[i], oracle[i])) ++different;
      // What each side array holds, from the oracle's sample.
      const shading::GSample& o = oracle[i];
      const std::size_t p = pixel[i];
      const float inf = std::numeric_limits<float>::infinity();
      const glm::vec4 want_guide = o.hit ? glm::vec4(o.normal_world, std::max(o.depth, 1e-30f)) : glm::vec4(0.0f);
      const float want_metal = o.hit && o.brdf.metallic >= 0.5f ? o.brdf.roughness : inf;
      const float want_dielectric = o.hit && o.brdf.metallic < 0.5f && o.brdf.specular > 0 ? o.brdf.roughness : inf;
      const bool sides_equal = std::memcmp(&guide[p], &want_guide, sizeof(glm::vec4)) == 0 &&
                               position[p] == (o.hit ? o.position : glm::vec3(0.0f)) &&
                               albedo[p] == (o.hit ? o.albedo : glm::vec3(0.0f)) && metal[p] == want_metal &&
                               dielectric[p] == want_dielectric && entity[p] == o.entity;
      if (!sides_equal) ++different_sides;
      if (std::isfinite(want_dielectric)) ++glossy;
      if (std::isfinite(want_metal)) ++metallic;
      if (!found[i]) {
        ++misses;
        continue;
      }
      ++hits;
      const rt::Hit& h = found_hits[i];
      const scene::MeshAsset& mesh = *assets.meshes[h.mesh];
      const glm::uvec3 t = mesh.triangles[h.primitive];
      const glm::vec3 interpolated = mesh.normals[t.x] + mesh.normals[t.y] + mesh.normals[t.z];
      if (glm::dot(interpolated, oracle[i].normal_obj) < 0) ++turned;
      if (h.mesh == 0) ++textured;
      if (h.mesh == 2 && !box_seen) {
        on_box = h;
        box_seen = true;
      }
    }
  };
  // Every tile size from 1 to 16 rays, so partial tiles are covered too.
  for (int first = 0, n = 1; first < width * height; first += n, n = n % shading::kGSampleTile + 1) {
    const int count = std::min(n, width * height - first);
    rt::Ray rays[shading::kGSampleTile];
    rt::Hit found_hits[shading::kGSampleTile];
    bool found[shading::kGSampleTile];
    for (int i = 0; i < count; ++i) {
      const int p = first + i;
      rays[i] = camera.generate({static_cast<float>(p % width) + 0.5f, static_cast<float>(p / width) + 0.5f});
      found[i] = rt.intersect(rays[i], found_hits[i]);
    }
    compare_tile(rays, found_hits, found, count);
  }
  // The triangle with no area, at 16 points.
  ASSERT_TRUE(box_seen) << "the camera must see the box";
  rt::Ray rays[shading::kGSampleTile];
  rt::Hit degenerate[shading::kGSampleTile];
  bool found[shading::kGSampleTile];
  for (int i = 0; i < shading::kGSampleTile; ++i) {
    rays[i] = camera.generate({40.5f + static_cast<float>(i), 20.5f});
    degenerate[i] = on_box;
    degenerate[i].primitive = 0;
    degenerate[i].barycentric = {static_cast<float>(i) / 20.0f, 0.25f};
    found[i] = true;
  }
  compare_tile(rays, degenerate, found, shading::kGSampleTile);
  std::printf("%d tiles: %d hits (%d textured, %d metallic, %d glossy dielectric, %d whose normal turned to the viewer, 16 on a triangle with no area), %d misses; %d samples and %d side entries differ\n",
              tiles, hits, textured, metallic, glossy, turned, misses, different, different_sides);
  EXPECT_EQ(different, 0);
  EXPECT_EQ(different_sides, 0);
  // What the comparison covered (or it shows nothing).
  EXPECT_GT(textured, 100);
  EXPECT_GT(misses, 100);
  EXPECT_GT(hits, 1000);
  EXPECT_GT(turned, 100);
  EXPECT_GT(glossy, 16);
  EXPECT_GT(metallic, 100);
}
