// Contact light by short rays (shading/near_field.h). Known answer: a point
// at height h facing down over a Lambertian floor of albedo a, lit from
// straight above by a sun of E lux, with probes that say the radiance is L0
// from everywhere. The floor's radiance is L = a E / pi + a L0 (its direct
// light plus its own probe irradiance pi L0 through a / pi). Within reach R
// the point sees the floor over the cone cos(theta) > h / R, whose cosine-
// weighted solid angle is pi (1 - (h / R)^2); there the short rays replace
// L0 by L:  dE = pi (1 - (h / R)^2) (L - L0).
#include <cmath>
#include <cstdio>
#include <memory>

#include <gtest/gtest.h>

#include <glm/gtc/quaternion.hpp>

#include "engine/app/app.h"
#include "engine/material/brdf.h"
#include "engine/math/rng.h"
#include "engine/math/sh.h"
#include "engine/render/light_set.h"
#include "engine/rt/rt_plugin.h"
#include "engine/scene/components.h"
#include "engine/scene/procedural.h"
#include "lambert.h"
#include "probes/probe_field.h"
#include "shading/near_field.h"
#include "shading/realtime_gi.h"
#include "shading/transfer_renderer.h"

using namespace engine;
using namespace transgi;

namespace {

struct SunlitFloor {
  static constexpr float kAlbedo = 0.5f, kLux = 2.0f;
  app::App app{app::AppOptions{.jobs = {.threads = 2}}};
  ecs::Entity floor;
  explicit SunlitFloor(material::Material floor_material = lambert(glm::vec3(kAlbedo))) {
    scene::SceneAssets a;
    a.generation = scene::next_scene_generation();
    a.meshes = {std::make_shared<scene::MeshAsset>(scene::make_quad({100, 100}, 0))};
    a.materials = {floor_material};
    app.world().insert_resource<scene::SceneAssets>(std::move(a));
    app.add_plugin<rt::RtPlugin>();
    ecs::World& w = app.world();
    floor = w.spawn();
    w.emplace<transform::Transform>(floor);
    w.emplace<scene::MeshInstance>(floor, scene::MeshInstance{0});
    const ecs::Entity sun = w.spawn();
    transform::Transform st;
    st.rotation = glm::quatLookAt(glm::vec3(0, -1, 0), glm::vec3(0, 0, 1));  // travelling straight down
    w.emplace<transform::Transform>(sun, st);
    w.emplace<scene::PunctualLight>(sun, scene::PunctualLight{.type = scene::PunctualLight::Type::Directional, .intensity = kLux});
    app.update();
  }
  const rt::RtScene& rt() { return app.world().resource<rt::RtScene>(); }
};

// A point of some other object at height h, facing the floor.
shading::GSample facing_down(float h) {
  shading::GSample s;
  s.hit = true;
  s.position = glm::vec3(0.3f, h, -0.2f);
  s.normal_world = s.geometric_normal = glm::vec3(0, -1, 0);
  s.wo_world = glm::vec3(0, -1, 0);
  s.depth = 1.0f;
  return s;
}

// SH of a radiance L0 from every direction: only the constant band.
std::array<float, 75> uniform_sh(float l0) {
  std::array<float, 75> sh{};
  const float y00 = math::sh_eval(glm::vec3(0, 0, 1))[0];
  for (int c = 0; c < 3; ++c) sh[static_cast<std::size_t>(c * 25)] = l0 / y00;
  return sh;
}

// own_masked_within: where the sample's transfer masks its own object (0: no transfer).
glm::vec3 estimate(SunlitFloor& scene, const shading::GSample& s, float l0, float reach, float own_masked_within, int rays) {
  const render::LightSet lights(scene.rt(), render::gather_punctual_lights(scene.app.world()), nullptr);
  const std::array<float, 75> sh = uniform_sh(l0);
  const shading::NearLightAt light_at = [&](const glm::vec3&, const glm::vec3&, float* out) { std::copy(sh.begin(), sh.end(), out); };
  math::Pcg32 rng = math::make_rng(7, 0, 0);
  return shading::near_field_irradiance(scene.rt(), &lights, s, sh.data(), reach, own_masked_within, rays, light_at, rng);
}

// The filter's guide: normal and depth per sample, 0 depth for a miss.
std::vector<glm::vec4> guide_of(const std::vector<shading::GSample>& samples) {
  std::vector<glm::vec4> g;
  for (const auto& s : samples) g.push_back(s.hit ? glm::vec4(s.normal_world, s.depth) : glm::vec4(0.0f));
  return g;
}

}  // namespace

TEST(NearField, APointOverASunlitFloorGetsTheFloorsLightInsideItsReach) {
  SunlitFloor scene;
  const float a = SunlitFloor::kAlbedo, e = SunlitFloor::kLux, pi = glm::pi<float>();
  for (const auto& [h, reach, l0] : {std::tuple{0.1f, 1.0f, 0.0f}, std::tuple{0.5f, 1.0f, 0.0f}, std::tuple{0.1f, 1.0f, 0.2f},
                                     std::tuple{0.3f, 2.0f, 0.7f}}) {
    const float floor_radiance = a * e / pi + a * l0;
    const float c = h / reach;
    const float expected = pi * (1 - c * c) * (floor_radiance - l0);
    const glm::vec3 got = estimate(scene, facing_down(h), l0, reach, 0.0f, 4096);
    std::printf("h %.2f reach %.1f L0 %.2f: dE expected pi (1 - (h/R)^2) (L - L0) = %.5f, got %.5f %.5f %.5f\n", h, reach,
                l0, expected, got.r, got.g, got.b);
    // 64 x 64 stratified cosine rays: the cone's edge crosses about 64 strata,
    // each off by at most its own share (1/4096): under 2 % of the cone.
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(got[k], expected, 0.02f * std::abs(expected) + 1e-6f) << "channel " << k;
  }
}

// The near field carries diffuse contact light only. A polished metal floor
// under the sun reflects it straight up into the point above (a glint its few
// rays a frame would meet now and then, and the filter spread into a bright
// box); it reflects nothing diffusely, so with probes holding no light the
// estimate is exactly zero. A Lambertian floor's, the same scene otherwise,
// is not (the case above).
TEST(NearField, AGlintOnAMetalIsNotContactLight) {
  material::Material gold = lambert(glm::vec3(1.0f, 0.8f, 0.3f));
  gold.metallic_factor = 1.0f;
  gold.roughness_factor = 0.2f;
  gold.specular_factor = 1.0f;
  SunlitFloor metal(gold);
  EXPECT_EQ(estimate(metal, facing_down(0.3f), 0.0f, 1.0f, 0.0f, 256), glm::vec3(0.0f));
  SunlitFloor matte;
  EXPECT_GT(estimate(matte, facing_down(0.3f), 0.0f, 1.0f, 0.0f, 256).g, 0.1f);
  // The BRDF's diffuse lobe alone: all of a metal's f is glossy, all of a
  // Lambertian's diffuse.
  material::BrdfParams metal_brdf{.base_color = glm::vec3(1.0f, 0.8f, 0.3f), .metallic = 1.0f, .roughness = 0.2f};
  material::BrdfParams matte_brdf{.base_color = glm::vec3(0.5f), .metallic = 0.0f, .roughness = 1.0f, .specular = 0.0f};
  const glm::vec3 up(0, 0, 1);
  EXPECT_EQ(material::brdf_eval_diffuse(metal_brdf, up, up), glm::vec3(0.0f));
  EXPECT_GT(material::brdf_eval(metal_brdf, up, up).r, 1.0f) << "the glint the near field leaves out";
  EXPECT_EQ(material::brdf_eval_diffuse(matte_brdf, up, up), material::brdf_eval(matte_brdf, up, up));
}

// A sample's transfer masks its own object within the bake's visibility
// distance t (model::TransferModel::self_masked_within): neither the probes'
// light nor the object's own comes through those directions, so the near
// field adds the object's whole radiance there, out to t, not the difference
// from the probes. Known answer as above with the floor as the sample's own
// object: dE = pi (1 - (h / t)^2) L for t past the reach; the difference
// within the reach where the floor lies past t (no masking).
TEST(NearField, WhereTheTransferMasksItsOwnObjectThatObjectsWholeLightIsAdded) {
  SunlitFloor scene;
  const float a = SunlitFloor::kAlbedo, e = SunlitFloor::kLux, pi = glm::pi<float>();
  const float h = 0.2f, l0 = 0.3f, reach = 0.5f, floor_radiance = a * e / pi + a * l0;
  shading::GSample s = facing_down(h);
  s.entity = scene.floor;
  for (const auto& [masked_within, expected] :
       {std::pair{1.0f, pi * (1 - (h / 1.0f) * (h / 1.0f)) * floor_radiance},
        // the reach's cone gets the difference, and its masked inner cone the L0 back
        std::pair{0.4f, pi * (1 - (h / reach) * (h / reach)) * (floor_radiance - l0) + pi * (1 - (h / 0.4f) * (h / 0.4f)) * l0},
        std::pair{0.1f, pi * (1 - (h / reach) * (h / reach)) * (floor_radiance - l0)},
        std::pair{0.0f, pi * (1 - (h / reach) * (h / reach)) * (floor_radiance - l0)}}) {
    const glm::vec3 got = estimate(scene, s, l0, reach, masked_within, 4096);
    std::printf("masked within %.1f (reach %.1f): expected %.5f, got %.5f\n", masked_within, reach, expected, got.g);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(got[k], expected, 0.02f * std::abs(expected) + 1e-6f) << "channel " << k;
  }
}

TEST(NearField, WhatLiesBeyondReachAddsNothing) {
  SunlitFloor scene;
  shading::GSample s = facing_down(0.2f);
  EXPECT_GT(estimate(scene, s, 0.0f, 1.0f, 0.0f, 64).g, 0.5f) << "another object's floor is contact light";
  EXPECT_EQ(estimate(scene, s, 0.0f, 0.19f, 0.0f, 64), glm::vec3(0.0f)) << "the floor is 0.2 away, the reach 0.19";
  EXPECT_EQ(estimate(scene, s, 0.0f, 0.19f, 5.0f, 64), glm::vec3(0.0f)) << "another object's, masked or not";
  EXPECT_EQ(estimate(scene, s, 0.0f, 1.0f, 0.0f, 0), glm::vec3(0.0f)) << "no rays: off";
  // Facing up, away from the floor, no ray can meet it.
  s.normal_world = s.geometric_normal = glm::vec3(0, 1, 0);
  EXPECT_EQ(estimate(scene, s, 0.0f, 1.0f, 0.0f, 64), glm::vec3(0.0f));
}

TEST(NearField, TheFilterKeepsAConstantAndNeverCrossesADepthStep) {
  // 8 x 4 pixels, 2 samples each: the left half at depth 1, the right at
  // depth 2 (a silhouette), one pixel missed.
  const int w = 8, h = 4, spp = 2;
  std::vector<shading::GSample> samples(static_cast<std::size_t>(w * h * spp));
  std::vector<glm::vec3> values(samples.size());
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int k = 0; k < spp; ++k) {
        const std::size_t i = static_cast<std::size_t>((y * w + x) * spp + k);
        samples[i].hit = !(x == 2 && y == 1);
        samples[i].normal_world = glm::vec3(0, 0, 1);
        samples[i].depth = x < 4 ? 1.0f : 2.0f;
        values[i] = x < 4 ? glm::vec3(1, 2, 3) : glm::vec3(0.25f);
      }
  const std::vector<glm::vec3> out = shading::filter_near_field(guide_of(samples), w, h, spp, values, 2);
  for (std::size_t i = 0; i < out.size(); ++i) {
    const glm::vec3 expected = samples[i].hit ? values[i] : glm::vec3(0.0f);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(out[i][c], expected[c], 1e-6f) << "sample " << i << " channel " << c;
  }
  // A crease: normals at right angles do not mix either; noise on one
  // surface is averaged (the centre of 25 pixels of alternating 0 and 2 is
  // within 2/25 of 1).
  for (std::size_t i = 0; i < samples.size(); ++i) {
    samples[i].hit = true;
    samples[i].depth = 1.0f;
    const int x = static_cast<int>(i / spp) % w;
    samples[i].normal_world = x < 4 ? glm::vec3(0, 0, 1) : glm::vec3(1, 0, 0);
    values[i] = x < 4 ? glm::vec3(static_cast<float>((i / spp) % 2) * 2.0f) : glm::vec3(5.0f);
  }
  const std::vector<glm::vec3> crease = shading::filter_near_field(guide_of(samples), w, h, spp, values, 2);
  for (std::size_t i = 0; i < crease.size(); ++i) {
    const int x = static_cast<int>(i / spp) % w;
    if (x >= 4) EXPECT_FLOAT_EQ(crease[i].r, 5.0f) << "sample " << i;
    else EXPECT_NEAR(crease[i].r, 1.0f, 0.34f) << "sample " << i;
  }
}

// The real-time filter (a horizontal then a vertical pass, one sample a
// pixel) keeps a constant on each side of a depth step and of a crease, takes
// values only from `valid` pixels, writes only `wanted` ones (zero elsewhere),
// and averages noise on one surface as the full window does.
TEST(NearField, TheSeparableFilterKeepsAConstantTakesOnlyValidPixelsAndNeverCrossesAnEdge) {
  const int w = 12, h = 10;
  const std::size_t n = static_cast<std::size_t>(w * h);
  std::vector<shading::GSample> samples(n);
  std::vector<glm::vec3> values(n);
  std::vector<std::uint8_t> valid(n), wanted(n);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i = static_cast<std::size_t>(y * w + x);
      samples[i].hit = !(x == 2 && y == 1);
      samples[i].normal_world = y < 5 ? glm::vec3(0, 0, 1) : glm::vec3(0, 1, 0);  // a crease between rows 4 and 5
      samples[i].depth = x < 6 ? 1.0f : 2.0f;                                        // a silhouette between columns 5 and 6
      valid[i] = y % 3 == 0;  // one row in three traced rays
      wanted[i] = (x + y) % 2;
      // Invalid pixels hold garbage the filter must not read.
      values[i] = !valid[i] ? glm::vec3(1e6f) : x < 6 ? (y < 5 ? glm::vec3(1, 2, 3) : glm::vec3(4.0f)) : glm::vec3(0.25f);
    }
  std::vector<glm::vec4> row;
  std::vector<glm::vec3> out;
  std::vector<std::uint8_t> estimated;
  shading::filter_near_field_separable(guide_of(samples), w, h, values, valid, wanted, 3, row, out, estimated);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i = static_cast<std::size_t>(y * w + x);
      const glm::vec3 expected = !wanted[i] || !samples[i].hit ? glm::vec3(0.0f)
                                 : x < 6                       ? (y < 5 ? glm::vec3(1, 2, 3) : glm::vec3(4.0f))
                                                               : glm::vec3(0.25f);
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(out[i][c], expected[c], 1e-5f) << "pixel " << x << ", " << y << " channel " << c;
      EXPECT_EQ(estimated[i], wanted[i] && samples[i].hit ? 1 : 0) << "pixel " << x << ", " << y;
    }
  // Noise on one flat surface: alternating 0 and 2 on the valid pixels; the
  // full 7 x 7 window averages it to 1 within 2/49 at the centre, the two
  // passes within a few times that (each pass sees fewer values).
  for (std::size_t i = 0; i < n; ++i) {
    samples[i].hit = true;
    samples[i].depth = 1.0f;
    samples[i].normal_world = glm::vec3(0, 0, 1);
    valid[i] = 1;
    wanted[i] = 1;
    values[i] = glm::vec3(static_cast<float>((i + i / w) % 2) * 2.0f);
  }
  shading::filter_near_field_separable(guide_of(samples), w, h, values, valid, wanted, 3, row, out, estimated);
  const std::vector<glm::vec3> full = shading::filter_near_field(guide_of(samples), w, h, 1, values, 3);
  const std::size_t centre = static_cast<std::size_t>(5 * w + 6);
  EXPECT_NEAR(full[centre].r, 1.0f, 2.0f / 49.0f + 1e-5f);
  EXPECT_NEAR(out[centre].r, 1.0f, 0.1f);
  // Bad sizes are refused, not read past.
  std::vector<std::uint8_t> short_mask(n - 1, 1);
  EXPECT_THROW(shading::filter_near_field_separable(guide_of(samples), w, h, values, short_mask, wanted, 3, row, out, estimated),
               std::invalid_argument);
}

// The real-time path's near field (on its half-resolution grid, filtered
// there) against the quality path's (every pixel): a wall standing on a
// sunlit floor, probes holding no light, so the wall's GI is its contact
// light alone. The mean over the wall's lowest half metre agrees within
// 10 % (64 rays a sample on both; measured 4.5 % apart: the real-time grid
// samples every second pixel and its filter reaches twice as far, on a light
// that falls steeply with height), and the wall's top gets none.
namespace {
// A wall standing on a sunlit floor, probes holding no light: the wall's GI
// is its contact light alone (the real-time near field's tests below).
struct WallOnSunlitFloor {
  app::App app{app::AppOptions{.jobs = {.threads = 2}}};
  ecs::Entity wall{};
  probes::ProbeFieldSettings ps;
  std::unique_ptr<probes::ProbeField> field;
  std::unique_ptr<render::LightSet> lights;
  std::unique_ptr<render::CameraRays> rays;
  ecs::Entity camera{};
  static constexpr int kSize = 48;

  ecs::Entity slat{};  // with_slat only

  // with_slat: a slat 3 cm tall across the wall, 30 cm in front of it at
  // 32 cm above the floor (on pixel row 36 of the camera), facing the camera as the wall does.
  ecs::Entity block{};  // with_block only

  // with_block: a 40 cm cube on the floor 50 cm in front of the wall's left half.
  explicit WallOnSunlitFloor(bool with_slat = false, bool with_block = false) {
    scene::SceneAssets a;
    a.generation = scene::next_scene_generation();
    a.meshes = {std::make_shared<scene::MeshAsset>(scene::make_quad({10, 10}, 0)),
                std::make_shared<scene::MeshAsset>(scene::make_quad({2, 1}, 1)),
                std::make_shared<scene::MeshAsset>(scene::make_quad({1, 0.015f}, 1)),
                std::make_shared<scene::MeshAsset>(scene::make_box(glm::vec3(0.2f), false, 1))};
    a.materials = {lambert(glm::vec3(0.5f)), lambert(glm::vec3(0.8f))};
    app.world().insert_resource<scene::SceneAssets>(std::move(a));
    app.add_plugin<rt::RtPlugin>();
    ecs::World& w = app.world();
    const ecs::Entity floor = w.spawn();
    w.emplace<transform::Transform>(floor);
    w.emplace<scene::MeshInstance>(floor, scene::MeshInstance{0});
    wall = w.spawn();  // 4 x 2 m, standing on the floor at z = -1, facing +z
    transform::Transform wt = transform::Transform::from_translation({0, 1, -1});
    wt.rotation = glm::angleAxis(glm::half_pi<float>(), glm::vec3(1, 0, 0));
    w.emplace<transform::Transform>(wall, wt);
    w.emplace<scene::MeshInstance>(wall, scene::MeshInstance{1});
    if (with_slat) {
      slat = w.spawn();
      transform::Transform t = transform::Transform::from_translation({0, 0.32f, -0.7f});
      t.rotation = wt.rotation;
      w.emplace<transform::Transform>(slat, t);
      w.emplace<scene::MeshInstance>(slat, scene::MeshInstance{2});
    }
    if (with_block) {
      block = w.spawn();
      w.emplace<transform::Transform>(block, transform::Transform::from_translation({-1.0f, 0.2f, -0.5f}));
      w.emplace<scene::MeshInstance>(block, scene::MeshInstance{3});
    }
    const ecs::Entity sun = w.spawn();
    transform::Transform st;
    st.rotation = glm::quatLookAt(glm::vec3(0, -1, 0), glm::vec3(0, 0, 1));  // straight down: the wall is edge-on
    w.emplace<transform::Transform>(sun, st);
    w.emplace<scene::PunctualLight>(sun, scene::PunctualLight{.type = scene::PunctualLight::Type::Directional, .intensity = 2.0f});
    camera = w.spawn();
    transform::Transform cam = transform::Transform::from_translation({0, 1, 2});
    cam.rotation = glm::quatLookAt(glm::vec3(0, 0, -1), glm::vec3(0, 1, 0));
    w.emplace<transform::Transform>(camera, cam);
    w.emplace<scene::Camera>(camera, scene::Camera{.yfov_radians = 0.9f});
    app.update();
    lights = std::make_unique<render::LightSet>(w.resource<rt::RtScene>(), render::gather_punctual_lights(w), nullptr);
    look_from(cam);
    ps.grid = probes::ProbeGrid{{-2, 0.1f, -0.9f}, {2, 2.1f, 1.1f}, {5, 3, 3}};  // never updated: it holds no light
    ps.map = probes::MapLayout{8, 4};
    field = std::make_unique<probes::ProbeField>(ps);
  }
  // The camera rays from `pose` (the camera entity's transform).
  void look_from(const transform::Transform& pose) {
    ecs::World& w = app.world();
    w.get_mut<transform::Transform>(camera) = pose;
    app.update();
    rays = std::make_unique<render::CameraRays>(w.get<scene::Camera>(camera), w.get<transform::WorldTransform>(camera), kSize, kSize);
  }
  [[nodiscard]] const rt::RtScene& rt() { return app.world().resource<rt::RtScene>(); }
  [[nodiscard]] const scene::SceneAssets& assets() { return app.world().resource<scene::SceneAssets>(); }
  // One real-time GI frame the game's way (the GI reuse on), its G-buffer
  // traced into g, its histories in scratch.
  image::ImageRGB realtime_frame(const shading::NearFieldRays& near, shading::RealtimeGiScratch& scratch, shading::GBuffer& g) {
    shading::RealtimeGiSettings reuse;
    reuse.reuse_history = true;
    const probes::ProbeField* fields[] = {field.get()};
    image::ImageRGB gi;
    app.jobs().run([&] {
      shading::trace_gbuffer(rt(), assets(), *rays, kSize, kSize, g);
      gi = shading::shade_gi_realtime({.gbuffer = g,
                                       .scene = rt(),
                                       .assets = assets(),
                                       .fields = fields,
                                       .settings = reuse,
                                       .mirror_lights = lights.get(),
                                       .mirror = shading::MirrorRay{.max_roughness = -1},
                                       .near_field = near},
                                      {.scratch = &scratch});
    });
    return gi;
  }
};
}  // namespace

TEST(NearField, TheRealTimePathAgreesWithTheQualityPath) {
  WallOnSunlitFloor scene;
  const ecs::Entity wall = scene.wall;
  const probes::ProbeFieldSettings& ps = scene.ps;
  const auto& rt = scene.rt();
  const auto& assets = scene.assets();
  const render::LightSet& lights = *scene.lights;
  const int size = WallOnSunlitFloor::kSize;
  const render::CameraRays& rays = *scene.rays;
  const probes::ProbeField* fields[] = {scene.field.get()};
  app::App& app = scene.app;
  const shading::NearFieldRays near{.rays = 64, .reach_cells = 1.0f, .filter_radius = 2};
  const shading::LightAt no_light = [](const glm::vec3&, const glm::vec3&, float* out) { std::fill_n(out, 75, 0.0f); };

  shading::TransferRenderSettings s;
  s.spp = 1;
  s.has_transfer = [](ecs::Entity) { return false; };
  s.lights = &lights;
  s.near_field = near;
  s.probe_spacing_at = [&](const glm::vec3&) { return ps.grid.min_spacing(); };
  const model::TransferModel no_model;
  shading::TransferRenderResult quality;
  shading::GBuffer g;
  image::ImageRGB realtime, budgeted;
  // The game's way: the GI reuse (each frame decodes every other cell, the
  // two colours in turn; the rest keep the value, contact light included,
  // they were given), a cell budget that leaves a sparse, shifting lattice
  // of cells tracing (60 of 576: one row in 5), and each cell's estimates
  // averaged over frames, over 32 frames of a still view. (4 rays a cell:
  // with 1 the mean of this 48 x 48 image is within 2 % but its noise is 8 %
  // between neighbours.)
  shading::NearFieldRays game_near = near;
  game_near.rays = 4;
  game_near.cell_budget = 60;
  shading::RealtimeGiSettings reuse;
  reuse.reuse_history = true;
  shading::RealtimeGiScratch scratch;
  shading::RealtimeGiStats stats;
  app.jobs().run([&] {
    quality = shading::render_transfer(rt, assets, no_model, rays, size, size, no_light, nullptr,
                                       shading::TransferSource::Network, s);
    shading::trace_gbuffer(rt, assets, rays, size, size, g);
    realtime = shading::shade_gi_realtime({.gbuffer = g,
                                           .scene = rt,
                                           .assets = assets,
                                           .fields = fields,
                                           .mirror_lights = &lights,
                                           .mirror = shading::MirrorRay{.max_roughness = -1},
                                           .near_field = near});
    for (int frame = 0; frame < 32; ++frame)
      budgeted = shading::shade_gi_realtime({.gbuffer = g,
                                             .scene = rt,
                                             .assets = assets,
                                             .fields = fields,
                                             .settings = reuse,
                                             .mirror_lights = &lights,
                                             .mirror = shading::MirrorRay{.max_roughness = -1},
                                             .near_field = game_near},
                                            {.stats = &stats, .scratch = &scratch});
  });
  EXPECT_GT(stats.reused_cells, 0u) << "the last frame reused cells";
  // The wall's pixels: rows where the camera ray meets it, below its middle.
  double sum_q = 0, sum_r = 0, sum_b = 0, low = 0, high = 0, step_b = 0;
  int n = 0;
  for (int y = 0; y < size; ++y)
    for (int x = size / 4; x < 3 * size / 4; ++x) {
      const shading::GSample& smp = g.samples[static_cast<std::size_t>(y * size + x)];
      if (!smp.hit || !(smp.entity == wall)) continue;
      if (smp.position.y < 0.5f) {
        sum_q += quality.image.at(x, y).g;
        sum_r += realtime.at(x, y).g;
        sum_b += budgeted.at(x, y).g;
        step_b += std::abs(budgeted.at(x, y).g - budgeted.at(x + 1, y).g);  // the contact light is level along the wall
        ++n;
        if (smp.position.y < 0.25f) low += realtime.at(x, y).g;
      } else if (smp.position.y > 1.5f) {
        high += realtime.at(x, y).g;
      }
    }
  ASSERT_GT(n, 50) << "the camera must see the wall's lower half";
  std::printf("wall below 0.5 m, %d pixels: mean GI quality %.5f, real-time %.5f, budgeted with reuse %.5f\n", n, sum_q / n,
              sum_r / n, sum_b / n);
  EXPECT_GT(sum_q / n, 0.01) << "contact light from the sunlit floor";
  EXPECT_NEAR(sum_r / n, sum_q / n, 0.10 * sum_q / n);
  EXPECT_NEAR(sum_b / n, sum_q / n, 0.10 * sum_q / n);
  // No pattern between neighbouring cells: rays from each decode colour's own
  // cells gave each colour its own frozen noise, a checkerboard (the first
  // version: about a fifth of the level between neighbours).
  std::printf("budgeted: mean |difference| of horizontal neighbours %.5f (%.1f %% of the mean)\n", step_b / n, 100.0 * step_b / sum_b);
  EXPECT_LT(step_b / sum_b, 0.05);
  EXPECT_GT(low, 0.0);
  EXPECT_EQ(high, 0.0) << "above the reach (one 1 m cell) of the floor, nothing";
}

// A slat too thin for the GI grid to put a cell on it, and too far in front
// of the wall for the upsampling to take the wall's cells (10 % of the
// depth, beyond its 5 %), is decoded pixel by pixel. Its contact light from
// the sunlit floor is about the wall's at the same height (both face the
// camera, 30 cm apart, inside the near field's reach); it takes the wall's
// cells' estimate. Before, it got none: its GI was zero (the probes hold no
// light here), against the wall's 0.02. Tolerance 35 %: the slat stands in
// front of the floor's brightest band, the wall at its back.
TEST(NearField, APixelDecodedOnItsOwnTakesTheContactLightOfItsSurface) {
  WallOnSunlitFloor scene(true);
  const probes::ProbeField* fields[] = {scene.field.get()};
  const int size = WallOnSunlitFloor::kSize;
  shading::GBuffer g;
  image::ImageRGB gi;
  shading::RealtimeGiStats stats;
  scene.app.jobs().run([&] {
    shading::trace_gbuffer(scene.rt(), scene.assets(), *scene.rays, size, size, g);
    gi = shading::shade_gi_realtime({.gbuffer = g,
                                     .scene = scene.rt(),
                                     .assets = scene.assets(),
                                     .fields = fields,
                                     .mirror_lights = scene.lights.get(),
                                     .mirror = shading::MirrorRay{.max_roughness = -1},
                                     .near_field = shading::NearFieldRays{.rays = 64, .reach_cells = 1.0f, .filter_radius = 2}},
                                    {.stats = &stats});
  });
  double slat = 0, wall = 0;
  int n_slat = 0, n_wall = 0;
  for (int y = 0; y < size; ++y)
    for (int x = size / 4; x < 3 * size / 4; ++x) {
      const shading::GSample& smp = g.samples[static_cast<std::size_t>(y * size + x)];
      if (!smp.hit) continue;
      if (smp.entity == scene.slat) {
        slat += gi.at(x, y).g;
        ++n_slat;
      } else if (smp.entity == scene.wall && std::abs(smp.position.y - 0.32f) < 0.1f) {
        wall += gi.at(x, y).g;
        ++n_wall;
      }
    }
  std::printf("%zu pixels decoded on their own; slat %d pixels, mean GI %.5f; wall at its height %d pixels, %.5f\n",
              stats.edge_samples, n_slat, n_slat ? slat / n_slat : 0.0, n_wall, n_wall ? wall / n_wall : 0.0);
  ASSERT_GT(n_slat, 10) << "the camera must see the slat";
  ASSERT_GE(stats.edge_samples, static_cast<std::size_t>(n_slat)) << "the slat's pixels are decoded on their own";
  ASSERT_GT(wall / n_wall, 0.005) << "contact light from the sunlit floor";
  EXPECT_NEAR(slat / n_slat, wall / n_wall, 0.35 * wall / n_wall);
}

// Near a moved object the contact light's means restart from one frame's
// filtered estimate. From the sparse lattice's estimates alone (a tenth of
// the cells here) that estimate mottled the surfaces around the object with
// blotches a few cells wide for the frames the means took to settle (the
// shutter behind the rolling ball in the sample level's replay); every
// other cell there now traces. Measured on the wall behind a cube moved
// 30 cm along it: the frame after the move against the same view once its
// means settled again (47 frames later), mean |difference| as a fraction of
// the settled light: 47 % from the lattice alone, 24 % now (one ray a cell
// and a 48 x 48 view); bound 35 %.
TEST(NearField, AroundAMovedObjectTheRestartedContactLightIsNotBlotchy) {
  WallOnSunlitFloor scene(false, true);
  const int size = WallOnSunlitFloor::kSize;
  shading::NearFieldRays near{.rays = 1, .reach_cells = 1.0f, .filter_radius = 2};
  near.cell_budget = 60;
  near.cut_fade_frames = 0;  // the cube's surroundings are most of this small view: no cut's fade
  shading::RealtimeGiScratch scratch;
  shading::GBuffer g;
  image::ImageRGB gi;
  const auto frames = [&](int n) {
    for (int f = 0; f < n; ++f) gi = scene.realtime_frame(near, scratch, g);
  };
  frames(24);
  scene.app.world().get_mut<transform::Transform>(scene.block).translation.x += 0.3f;
  scene.app.update();
  frames(1);
  const image::ImageRGB after_move = gi;
  frames(47);  // the means settled again: what the first frame should show
  double level = 0, error = 0;
  int n = 0;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const shading::GSample& a = g.samples[static_cast<std::size_t>(y * size + x)];
      if (!a.hit || !(a.entity == scene.wall) || a.position.y > 0.8f || a.position.x > 0.2f) continue;  // the wall around the cube
      level += gi.at(x, y).g;
      error += std::abs(after_move.at(x, y).g - gi.at(x, y).g);
      ++n;
    }
  ASSERT_GT(n, 50) << "the camera must see the wall behind the cube";
  ASSERT_GT(level / n, 0.005) << "contact light from the sunlit floor";
  std::printf("wall around the moved cube, %d pixels: settled mean GI %.5f; the frame after the move differs by %.5f (%.1f %%)\n", n,
              level / n, error / n, 100.0 * error / level);
  EXPECT_LT(error / level, 0.35);
}

// After a cut (here the first frame: every cell's mean starts at once) the
// contact light fades in over NearFieldRays::cut_fade_frames frames of its
// mean: the first frame shows exactly an eighth of it, frame 8 all of it,
// the same image as without the fade (the means themselves are not
// faded). A step of the camera starts only some cells' means: nothing
// fades, the image is the one without the fade.
TEST(NearField, AfterACutTheContactLightFadesInAndAStepDoesNot) {
  WallOnSunlitFloor scene;
  struct Run {
    shading::RealtimeGiScratch scratch;
    std::vector<image::ImageRGB> frames;
  };
  const auto run = [&](int cut_fade, int frames, Run& r) {
    shading::NearFieldRays near{.rays = 4, .reach_cells = 1.0f, .filter_radius = 2};
    near.cut_fade_frames = cut_fade;
    shading::GBuffer g;
    for (int f = 0; f < frames; ++f) r.frames.push_back(scene.realtime_frame(near, r.scratch, g));
  };
  Run faded, plain;
  run(8, 9, faded);
  run(0, 9, plain);
  double first_faded = 0, first_plain = 0, last_difference = 0;
  for (std::size_t p = 0; p < plain.frames[0].pixels.size(); ++p) {
    first_faded += faded.frames[0].pixels[p].g;
    first_plain += plain.frames[0].pixels[p].g;
    last_difference = std::max(last_difference, static_cast<double>(std::abs(faded.frames[8].pixels[p].g - plain.frames[8].pixels[p].g)));
  }
  std::printf("first frame's GI summed: %.5f faded, %.5f without; frame 8's largest difference %.3g\n", first_faded, first_plain,
              last_difference);
  ASSERT_GT(first_plain, 1.0) << "contact light from the sunlit floor";
  EXPECT_NEAR(first_faded, first_plain / 8.0, 1e-4 * first_plain);
  EXPECT_EQ(last_difference, 0.0) << "after 8 frames the fade is over";
  // A 15 cm step: some cells see new points (the test fails if any new point
  // counted as a cut), far fewer than a quarter of them.
  transform::Transform step = transform::Transform::from_translation({0.15f, 1, 2});
  step.rotation = glm::quatLookAt(glm::vec3(0, 0, -1), glm::vec3(0, 1, 0));
  scene.look_from(step);
  run(8, 1, faded);
  run(0, 1, plain);
  double step_difference = 0;
  for (std::size_t p = 0; p < plain.frames.back().pixels.size(); ++p)
    step_difference = std::max(step_difference, static_cast<double>(std::abs(faded.frames.back().pixels[p].g - plain.frames.back().pixels[p].g)));
  EXPECT_EQ(step_difference, 0.0) << "a step of the camera is no cut";
}
