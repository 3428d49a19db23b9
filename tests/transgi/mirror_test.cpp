// The mirror path (issue 14, item 5): a flat perfect mirror facing a lit
// wall reflects the wall's radiance. Known answer: a Lambertian ceiling of
// albedo a lit by a directional light of E_perp lux arriving at 45 degrees
// has radiance a E_perp cos45 / pi everywhere the light reaches; a mirror
// (metal, base colour 1, roughness 0: Fresnel 1) under it, seen by the
// camera, shows exactly that as GI (the ceiling's direct light seen through
// one more bounce). The probes are given no light here, so the answer has no
// other term. Tolerance 1e-4 relative: a delta light's next-event estimate
// is exact, what is left is float rounding.
#include <gtest/gtest.h>

#include <optional>

#include <glm/gtc/quaternion.hpp>

#include "engine/app/app.h"
#include "engine/render/light_set.h"
#include "engine/render/surface.h"
#include "engine/rt/rt_plugin.h"
#include "engine/scene/components.h"
#include "engine/scene/procedural.h"
#include "lambert.h"
#include "probes/probe_field.h"
#include "shading/realtime_gi.h"
#include "shading/transfer_renderer.h"
#include "engine/material/brdf.h"
#include "engine/material/specular_albedo.h"
#include "engine/math/rng.h"

using namespace engine;
using namespace transgi;

TEST(MirrorPath, AFlatMirrorUnderALitCeilingShowsTheCeilingsRadiance) {
  const float albedo = 0.5f, lux = 3.0f;
  app::App app(app::AppOptions{.jobs = {.threads = 2}});
  scene::SceneAssets a;
  a.generation = scene::next_scene_generation();
  a.meshes = {std::make_shared<scene::MeshAsset>(scene::make_quad({0.5f, 0.5f}, 0)),
              std::make_shared<scene::MeshAsset>(scene::make_quad({10, 10}, 1))};
  material::Material mirror;
  mirror.base_color_factor = glm::vec4(1);
  mirror.metallic_factor = 1;
  mirror.roughness_factor = 0;
  a.materials = {mirror, lambert(glm::vec3(albedo))};
  app.world().insert_resource<scene::SceneAssets>(std::move(a));
  app.add_plugin<rt::RtPlugin>();
  ecs::World& w = app.world();
  const ecs::Entity m = w.spawn();
  w.emplace<transform::Transform>(m);
  w.emplace<scene::MeshInstance>(m, scene::MeshInstance{0});
  const ecs::Entity ceiling = w.spawn();
  transform::Transform ct = transform::Transform::from_translation({0, 2, 0});
  ct.rotation = glm::angleAxis(glm::pi<float>(), glm::vec3(1, 0, 0));  // facing down
  w.emplace<transform::Transform>(ceiling, ct);
  w.emplace<scene::MeshInstance>(ceiling, scene::MeshInstance{1});
  // The light travels up and to +x at 45 degrees: it reaches the ceiling's
  // underside; the mirror's shadow falls at x = 1.5..2.5, away from where the
  // mirror looks (around (0, 2, -6)).
  const ecs::Entity sun = w.spawn();
  transform::Transform st;
  st.rotation = glm::quatLookAt(glm::normalize(glm::vec3(1, 1, 0)), glm::vec3(0, 0, 1));
  w.emplace<transform::Transform>(sun, st);
  w.emplace<scene::PunctualLight>(sun, scene::PunctualLight{.type = scene::PunctualLight::Type::Directional, .intensity = lux});
  const ecs::Entity camera = w.spawn();
  transform::Transform cam = transform::Transform::from_translation({0, 1, 3});
  cam.rotation = glm::quatLookAt(glm::normalize(glm::vec3(0, -1, -3)), glm::vec3(0, 1, 0));
  w.emplace<transform::Transform>(camera, cam);
  w.emplace<scene::Camera>(camera, scene::Camera{.yfov_radians = 0.5f});
  app.update();

  const auto& rt = w.resource<rt::RtScene>();
  const render::LightSet lights(rt, render::gather_punctual_lights(w), nullptr);
  const render::CameraRays rays(w.get<scene::Camera>(camera), w.get<transform::WorldTransform>(camera), 32, 32);
  shading::TransferRenderSettings s;
  s.spp = 1;
  s.has_transfer = [](ecs::Entity) { return false; };
  s.lights = &lights;
  s.mirror.light_samples = 1;
  const shading::LightAt no_probe_light = [](const glm::vec3&, const glm::vec3&, float* out) { std::fill_n(out, 75, 0.0f); };
  const model::TransferModel no_model;
  shading::TransferRenderResult r;
  app.jobs().run([&] {
    r = shading::render_transfer(rt, w.resource<scene::SceneAssets>(), no_model, rays, 32, 32, no_probe_light, nullptr,
                                 shading::TransferSource::Network, s);
  });
  const float expected = albedo * lux * std::cos(glm::radians(45.0f)) / glm::pi<float>();
  std::printf("mirror pixel (16, 16): %.6f, expected a E cos45 / pi = %.6f; %zu mirror samples\n", r.image.at(16, 16).g, expected, r.mirror_samples);
  EXPECT_GT(r.mirror_samples, 16u);
  for (int y = 14; y < 18; ++y)
    for (int x = 14; x < 18; ++x)
      EXPECT_NEAR(r.image.at(x, y).g, expected, 1e-4f * expected) << "pixel (" << x << ", " << y << ")";

  // Off (the paper's setting), SH transfer or a diffuse fallback cannot show
  // a mirror: a metal has no diffuse albedo, so the pixel is black.
  s.mirror.max_roughness = -1;
  app.jobs().run([&] {
    r = shading::render_transfer(rt, w.resource<scene::SceneAssets>(), no_model, rays, 32, 32, no_probe_light, nullptr,
                                 shading::TransferSource::Network, s);
  });
  EXPECT_EQ(r.mirror_samples, 0u);
  EXPECT_EQ(r.image.at(16, 16).g, 0.0f);

  // The real-time path traces the same ray at full resolution: the same
  // answer. Its probes hold no light yet (a field never updated).
  probes::ProbeFieldSettings ps;
  ps.grid = probes::ProbeGrid{{-1, 0.5f, -1}, {1, 1.5f, 1}, {2, 2, 2}};
  ps.map = probes::MapLayout{8, 4};
  const probes::ProbeField field(ps);
  const probes::ProbeField* fields[] = {&field};
  shading::GBuffer g;
  engine::image::ImageRGB realtime;
  app.jobs().run([&] {
    shading::trace_gbuffer(rt, w.resource<scene::SceneAssets>(), rays, 32, 32, g);
    realtime = shading::shade_gi_realtime(
        {.gbuffer = g, .scene = rt, .assets = w.resource<scene::SceneAssets>(), .fields = fields, .mirror_lights = &lights});
  });
  for (int y = 14; y < 18; ++y)
    for (int x = 14; x < 18; ++x)
      EXPECT_NEAR(realtime.at(x, y).g, expected, 1e-4f * expected) << "real-time path, pixel (" << x << ", " << y << ")";

  // The mirror pass finds its pixels through the G-buffer's metal_roughness:
  // exactly the pixels is_mirror() picks from the full samples.
  const shading::MirrorRay mirror_ray;
  int mirrors = 0;
  ASSERT_EQ(g.metal_roughness.size(), g.samples.size());
  for (std::size_t p = 0; p < g.samples.size(); ++p) {
    const bool by_sample = g.samples[p].hit && shading::is_mirror(g.samples[p].brdf, mirror_ray);
    EXPECT_EQ(g.metal_roughness[p] <= mirror_ray.max_roughness, by_sample) << "pixel " << p;
    mirrors += by_sample;
  }
  EXPECT_GT(mirrors, 0) << "the scene must show its mirror";
}

// The glossy ray (MirrorRay::glossy_max_roughness): a gold-coloured metal
// of roughness 0.3 under the same lit ceiling. Every reflection ray meets the
// ceiling, whose radiance L = a E cos45 / pi is the same everywhere lit, so
// the mean of shade_glossy over its samples is the GGX lobe's directional
// albedo (engine/material/specular_albedo.h, per channel's F0) times L.
// Tolerance 3 %: the estimator weighs by G1(wi) (separable Smith) where the
// table integrates height-correlated Smith, and 4,096 samples leave about
// 1 % of noise.
TEST(MirrorPath, AGlossyMetalReflectsItsDirectionalAlbedoOfALitCeiling) {
  const float albedo = 0.5f, lux = 3.0f;
  app::App app(app::AppOptions{.jobs = {.threads = 2}});
  scene::SceneAssets a;
  a.generation = scene::next_scene_generation();
  a.meshes = {std::make_shared<scene::MeshAsset>(scene::make_quad({10, 10}, 0))};
  a.materials = {lambert(glm::vec3(albedo))};
  app.world().insert_resource<scene::SceneAssets>(std::move(a));
  app.add_plugin<rt::RtPlugin>();
  ecs::World& w = app.world();
  const ecs::Entity ceiling = w.spawn();
  transform::Transform ct = transform::Transform::from_translation({0, 2, 0});
  ct.rotation = glm::angleAxis(glm::pi<float>(), glm::vec3(1, 0, 0));  // facing down
  w.emplace<transform::Transform>(ceiling, ct);
  w.emplace<scene::MeshInstance>(ceiling, scene::MeshInstance{0});
  const ecs::Entity sun = w.spawn();
  transform::Transform st;
  st.rotation = glm::quatLookAt(glm::normalize(glm::vec3(1, 1, 0)), glm::vec3(0, 0, 1));
  w.emplace<transform::Transform>(sun, st);
  w.emplace<scene::PunctualLight>(sun, scene::PunctualLight{.type = scene::PunctualLight::Type::Directional, .intensity = lux});
  app.update();
  const auto& rt = w.resource<rt::RtScene>();
  const render::LightSet lights(rt, render::gather_punctual_lights(w), nullptr);

  shading::GSample s;
  s.hit = true;
  s.position = glm::vec3(0.0f);
  s.normal_world = s.geometric_normal = glm::vec3(0, 1, 0);
  const float theta = glm::radians(30.0f);
  s.wo_world = glm::vec3(0.0f, std::cos(theta), std::sin(theta));
  s.brdf.base_color = glm::vec3(0.95f, 0.65f, 0.3f);
  s.brdf.metallic = 1.0f;
  s.brdf.roughness = 0.3f;
  const shading::LightAt no_probe_light = [](const glm::vec3&, const glm::vec3&, float* out) { std::fill_n(out, 75, 0.0f); };
  shading::MirrorRay mirror;
  mirror.light_samples = 1;  // a delta light: one sample is exact
  math::Pcg32 rng(3, 9);
  glm::dvec3 sum(0.0);
  constexpr int kSamples = 4096;
  for (int i = 0; i < kSamples; ++i) {
    const glm::vec2 u{(static_cast<float>(i % 64) + rng.next_float()) / 64.0f, (static_cast<float>(i / 64) + rng.next_float()) / 64.0f};
    sum += glm::dvec3(shading::shade_glossy(rt, s, no_probe_light, &lights, mirror, u, rng).gi);
  }
  const glm::dvec3 mean = sum / static_cast<double>(kSamples);
  const double radiance = albedo * lux * std::cos(glm::radians(45.0)) / glm::pi<double>();
  const material::SpecularAlbedo e = material::ggx_albedo(std::cos(theta), s.brdf.roughness * s.brdf.roughness);
  for (int c = 0; c < 3; ++c) {
    const double expected = e.with_f0(s.brdf.base_color[c]) * radiance;
    std::printf("channel %d: glossy mean %.5f, directional albedo x ceiling radiance %.5f\n", c, mean[c], expected);
    EXPECT_NEAR(mean[c], expected, 0.03 * expected) << "channel " << c;
  }
}

// What a reflection ray brings back, by what it meets (reflected_light): the
// sky's radiance where it escapes and an emitter's emission, both as direct
// light; a diffuse surface's albedo / pi x the irradiance it is given, as
// GI. Exact answers (float rounding).
TEST(ReflectedLight, SplitsWhatTheRayMeetsIntoDirectAndGi) {
  app::App app(app::AppOptions{.jobs = {.threads = 1}});
  scene::SceneAssets a;
  a.generation = scene::next_scene_generation();
  a.meshes = {std::make_shared<scene::MeshAsset>(scene::make_quad({1, 1}, 0)),
              std::make_shared<scene::MeshAsset>(scene::make_quad({1, 1}, 1))};
  material::Material lamp = lambert(glm::vec3(0.0f));
  lamp.emissive_factor = glm::vec3(2.0f, 3.0f, 4.0f);
  a.materials = {lambert(glm::vec3(0.25f, 0.5f, 0.75f)), lamp};
  app.world().insert_resource<scene::SceneAssets>(std::move(a));
  app.add_plugin<rt::RtPlugin>();
  ecs::World& w = app.world();
  // A diffuse quad 1 m above the origin and a lamp 1 m above x = 5, both facing down.
  for (const auto& [mesh, x] : {std::pair{0u, 0.0f}, std::pair{1u, 5.0f}}) {
    const ecs::Entity e = w.spawn();
    transform::Transform t = transform::Transform::from_translation({x, 1, 0});
    t.rotation = glm::angleAxis(glm::pi<float>(), glm::vec3(1, 0, 0));
    w.emplace<transform::Transform>(e, t);
    w.emplace<scene::MeshInstance>(e, scene::MeshInstance{mesh});
  }
  app.update();
  const auto& rt = w.resource<rt::RtScene>();
  const scene::Environment sky = scene::uniform_environment(glm::vec3(0.5f, 0.6f, 0.7f));
  const shading::HitIrradiance irradiance = [](const render::Surface&) { return glm::vec3(2.0f); };
  const auto from = [](glm::vec3 p) {
    shading::GSample s;
    s.hit = true;
    s.position = p;
    s.normal_world = s.geometric_normal = glm::vec3(0, 1, 0);
    return s;
  };
  const glm::vec3 up(0, 1, 0);
  const shading::ReflectedLight to_sky = shading::reflected_light(rt, from({-5, 0, 0}), up, &sky, irradiance);
  EXPECT_EQ(to_sky.direct, glm::vec3(0.5f, 0.6f, 0.7f));
  EXPECT_EQ(to_sky.gi, glm::vec3(0.0f));
  const shading::ReflectedLight to_lamp = shading::reflected_light(rt, from({5, 0, 0}), up, &sky, irradiance);
  EXPECT_EQ(to_lamp.direct, glm::vec3(2.0f, 3.0f, 4.0f));
  EXPECT_EQ(to_lamp.gi, glm::vec3(0.0f));
  const shading::ReflectedLight to_wall = shading::reflected_light(rt, from({0, 0, 0}), up, &sky, irradiance);
  EXPECT_EQ(to_wall.direct, glm::vec3(0.0f));
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(to_wall.gi[c], 0.25f * static_cast<float>(c + 1) * 2.0f / glm::pi<float>(), 1e-6f);
  // Below the surface: nothing.
  const shading::ReflectedLight below = shading::reflected_light(rt, from({-5, 0, 0}), -up, &sky, irradiance);
  EXPECT_EQ(below.direct, glm::vec3(0.0f));
  EXPECT_EQ(below.gi, glm::vec3(0.0f));
}

// A reflection ray that meets a varnished surface (a diffuse base under a
// specular layer) takes back its whole directional albedo towards the ray's
// origin / pi x the irradiance it is given (reflected_gi), not its diffuse
// albedo alone: the specular layer reflects the room's light too. Known
// answer: engine::material::directional_albedo of the surface's parameters,
// at normal incidence and at 60 degrees, within float rounding; and more
// than the diffuse albedo's share, by the layer's albedo less what it takes
// from the base.
TEST(ReflectedLight, AVarnishedSurfaceReflectsItsWholeDirectionalAlbedo) {
  app::App app(app::AppOptions{.jobs = {.threads = 1}});
  scene::SceneAssets a;
  a.generation = scene::next_scene_generation();
  a.meshes = {std::make_shared<scene::MeshAsset>(scene::make_quad({4, 4}, 0))};
  material::Material varnish = lambert(glm::vec3(0.25f, 0.5f, 0.75f));
  varnish.specular_factor = 1.0f;
  varnish.roughness_factor = 0.3f;
  a.materials = {varnish};
  app.world().insert_resource<scene::SceneAssets>(std::move(a));
  app.add_plugin<rt::RtPlugin>();
  ecs::World& w = app.world();
  // The varnished quad 1 m above the origin, facing down.
  const ecs::Entity e = w.spawn();
  transform::Transform t = transform::Transform::from_translation({0, 1, 0});
  t.rotation = glm::angleAxis(glm::pi<float>(), glm::vec3(1, 0, 0));
  w.emplace<transform::Transform>(e, t);
  w.emplace<scene::MeshInstance>(e, scene::MeshInstance{0});
  app.update();
  const auto& rt = w.resource<rt::RtScene>();
  const shading::HitIrradiance irradiance = [](const render::Surface&) { return glm::vec3(2.0f); };
  shading::GSample from;
  from.hit = true;
  from.normal_world = from.geometric_normal = glm::vec3(0, 1, 0);
  for (const float degrees : {0.0f, 60.0f}) {
    const float a_rad = glm::radians(degrees);
    const glm::vec3 wi(std::sin(a_rad), std::cos(a_rad), 0.0f);
    const shading::ReflectedLight r = shading::reflected_light(rt, from, wi, nullptr, irradiance);
    rt::Hit hit;
    ASSERT_TRUE(rt.intersect(rt::Ray{from.position, wi}, hit));
    const render::Surface surface = render::make_surface(rt, hit, wi);
    const glm::vec3 albedo = material::directional_albedo(surface.brdf, std::cos(a_rad));
    const glm::vec3 diffuse = material::diffuse_albedo(surface.brdf);
    EXPECT_EQ(r.direct, glm::vec3(0.0f));
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(r.gi[c], albedo[c] * 2.0f / glm::pi<float>(), 1e-6f) << degrees << " degrees, channel " << c;
      EXPECT_GT(r.gi[c], diffuse[c] * 2.0f / glm::pi<float>() + 0.005f) << degrees << " degrees, channel " << c;
    }
  }
}

// A dielectric's reflection rays weigh, on average, its specular layer's
// directional albedo (sample_reflection; the dielectric reflection filter
// divides each ray's light by that albedo and so relies on it). Known answer:
// engine/material/specular_albedo.h's table at F0 = 0.04 x specular_color,
// times `specular`. Tolerance 3 %, as for the glossy metal above.
TEST(MirrorPath, ADielectricsReflectionWeightsAverageItsSpecularLayersAlbedo) {
  shading::GSample s;
  s.hit = true;
  s.normal_world = s.geometric_normal = glm::vec3(0, 1, 0);
  s.brdf.base_color = glm::vec3(0.3f, 0.2f, 0.1f);  // no part in the specular layer
  s.brdf.metallic = 0.0f;
  s.brdf.roughness = 0.4f;
  s.brdf.specular = 0.8f;
  s.brdf.specular_color = glm::vec3(1.0f, 0.5f, 2.0f);
  for (const float degrees : {0.0f, 45.0f, 75.0f}) {
    const float theta = glm::radians(degrees);
    s.wo_world = glm::vec3(0.0f, std::cos(theta), std::sin(theta));
    math::Pcg32 rng(5, 7);
    glm::dvec3 sum(0.0);
    constexpr int kSamples = 4096;
    for (int i = 0; i < kSamples; ++i) {
      const glm::vec2 u{(static_cast<float>(i % 64) + rng.next_float()) / 64.0f, (static_cast<float>(i / 64) + rng.next_float()) / 64.0f};
      glm::vec3 wi, weight;
      if (!shading::sample_reflection(s, false, u, wi, weight)) continue;
      EXPECT_NEAR(glm::dot(wi, wi), 1.0f, 1e-4f);
      EXPECT_GT(wi.y, 0.0f);
      sum += glm::dvec3(weight);
    }
    const glm::dvec3 mean = sum / static_cast<double>(kSamples);
    const material::SpecularAlbedo e = material::ggx_albedo(std::cos(theta), s.brdf.roughness * s.brdf.roughness);
    for (int c = 0; c < 3; ++c) {
      const double expected = s.brdf.specular * e.with_f0(std::min(material::kDielectricF0 * s.brdf.specular_color[c], 1.0f));
      EXPECT_NEAR(mean[c], expected, 0.03 * expected) << degrees << " degrees, channel " << c;
    }
  }
}

namespace {

// A varnished floor (base colour 0.4, 0.25, 0.1; roughness 0.35; a full
// specular layer) under `sky` alone, a camera 1 m above it looking down at
// 18 degrees, and probes that hold no light (a field never updated): the
// glossy dielectrics' reflections are all a real-time frame shows.
struct VarnishedFloor {
  static constexpr float kRoughness = 0.35f;
  app::App app{app::AppOptions{.jobs = {.threads = 2}}};
  ecs::Entity camera;
  std::optional<render::LightSet> lights;
  std::optional<probes::ProbeField> field;

  // mirror_wall: a white mirror (a metal, roughness 0) standing across the
  // floor 1.5 m behind its middle, facing the camera.
  explicit VarnishedFloor(scene::Environment sky, bool mirror_wall = false) {
    scene::SceneAssets a;
    a.generation = scene::next_scene_generation();
    a.meshes = {std::make_shared<scene::MeshAsset>(scene::make_quad({20, 20}, 0)),
                std::make_shared<scene::MeshAsset>(scene::make_quad({5, 2}, 1))};
    material::Material varnish = lambert(glm::vec3(0.4f, 0.25f, 0.1f));
    varnish.roughness_factor = kRoughness;
    varnish.specular_factor = 1.0f;
    material::Material mirror;
    mirror.base_color_factor = glm::vec4(1.0f);
    mirror.metallic_factor = 1.0f;
    mirror.roughness_factor = 0.0f;
    a.materials = {varnish, mirror};
    a.environment = std::move(sky);
    app.world().insert_resource<scene::SceneAssets>(std::move(a));
    app.add_plugin<rt::RtPlugin>();
    ecs::World& w = app.world();
    const ecs::Entity floor = w.spawn();
    w.emplace<transform::Transform>(floor);
    w.emplace<scene::MeshInstance>(floor, scene::MeshInstance{0});
    if (mirror_wall) {
      const ecs::Entity wall = w.spawn();
      transform::Transform t = transform::Transform::from_translation({0, 2, -1.5f});
      t.rotation = glm::angleAxis(glm::half_pi<float>(), glm::vec3(1, 0, 0));
      w.emplace<transform::Transform>(wall, t);
      w.emplace<scene::MeshInstance>(wall, scene::MeshInstance{1});
    }
    camera = w.spawn();
    transform::Transform cam = transform::Transform::from_translation({0, 1, 3});
    cam.rotation = glm::quatLookAt(glm::normalize(glm::vec3(0, -1, -3)), glm::vec3(0, 1, 0));
    w.emplace<transform::Transform>(camera, cam);
    w.emplace<scene::Camera>(camera, scene::Camera{.yfov_radians = 0.5f});
    app.update();
    lights.emplace(w.resource<rt::RtScene>(), render::gather_punctual_lights(w), &*w.resource<scene::SceneAssets>().environment);
    probes::ProbeFieldSettings ps;
    ps.grid = probes::ProbeGrid{{-1, 0.5f, -1}, {1, 1.5f, 1}, {2, 2, 2}};
    ps.map = probes::MapLayout{8, 4};
    field.emplace(ps);
  }

  // One real-time frame of size x size traced at `jitter` into g, with
  // `scratch` (null: no history); returns its GI, its direct light in direct.
  image::ImageRGB frame(int size, shading::GBuffer& g, image::ImageRGB& direct, const shading::MirrorRay& mirror = {},
                        glm::vec2 jitter = glm::vec2(0.0f), shading::RealtimeGiScratch* scratch = nullptr) {
    ecs::World& w = app.world();
    const auto& rt = w.resource<rt::RtScene>();
    const render::CameraRays rays(w.get<scene::Camera>(camera), w.get<transform::WorldTransform>(camera), size, size);
    const probes::ProbeField* fields[] = {&*field};
    direct = image::ImageRGB(size, size);
    image::ImageRGB gi;
    app.jobs().run([&] {
      shading::trace_gbuffer(rt, w.resource<scene::SceneAssets>(), rays, size, size, g, nullptr, nullptr, jitter);
      gi = shading::shade_gi_realtime({.gbuffer = g,
                                       .scene = rt,
                                       .assets = w.resource<scene::SceneAssets>(),
                                       .fields = fields,
                                       .mirror_lights = &*lights,
                                       .mirror = mirror},
                                      {.direct = &direct, .scratch = scratch});
    });
    return gi;
  }

  // The floor's specular albedo at a G-buffer sample's view angle.
  static float specular_albedo(const shading::GSample& s) {
    return material::ggx_albedo(glm::dot(s.normal_world, s.wo_world), kRoughness * kRoughness).with_f0(material::kDielectricF0);
  }
};

}  // namespace

// The real-time path's glossy dielectrics (MirrorRay::dielectric_max_
// roughness): a varnished floor alone under a uniform sky of radiance L.
// Every reflection ray escapes and finds L, so the floor's specular layer
// shows E(wo) L as direct light, E its directional albedo at the pixel's
// view angle (the filter's split-sum is exact under light that does not
// vary across the lobe), and nothing as GI (the probes hold no light).
// Tolerance 1e-4 relative: float rounding. Off, the floor's pixels take no
// reflection at all.
TEST(MirrorPath, AVarnishedFloorUnderAUniformSkyShowsItsSpecularAlbedoTimesTheSky) {
  const glm::vec3 sky(0.5f, 1.0f, 2.0f);
  VarnishedFloor scene(scene::uniform_environment(sky));
  shading::GBuffer g;
  image::ImageRGB direct;
  const image::ImageRGB gi = scene.frame(48, g, direct);
  int checked = 0;
  for (int y = 20; y < 48; y += 3)
    for (int x = 8; x < 40; x += 3) {
      const std::size_t p = static_cast<std::size_t>(y) * 48 + x;
      ASSERT_TRUE(g.samples[p].hit) << "pixel (" << x << ", " << y << ") must see the floor";
      const float expected_albedo = VarnishedFloor::specular_albedo(g.samples[p]);
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(direct.pixels[p][c], expected_albedo * sky[c], 1e-4f * expected_albedo * sky[c])
            << "pixel (" << x << ", " << y << "), channel " << c;
        EXPECT_EQ(gi.pixels[p][c], 0.0f);
      }
      ++checked;
    }
  EXPECT_GT(checked, 50);
  shading::MirrorRay off;
  off.dielectric_max_roughness = -1;
  scene.frame(48, g, direct, off);
  for (std::size_t p = 0; p < direct.pixels.size(); ++p) EXPECT_EQ(direct.pixels[p], glm::vec3(0.0f)) << "pixel " << p;
}

// A varnished floor before a white mirror (F0 = 1) under a uniform sky: a
// floor ray that meets the mirror sees the sky in it, one bounce further
// (the mirror's own reflection ray), so every floor pixel's reflection,
// direct (the sky seen at once) plus GI (the sky seen in the mirror), is
// still its specular albedo times the sky. Before, a metal met by a
// reflection ray was black and the floor in front of the mirror lost the
// share of its rays that met it. Tolerance 0.5 % (the mirror's Smith G1 at
// the smallest roughness) plus 1e-5.
TEST(MirrorPath, AVarnishedFloorSeesTheSkyInAMirrorBehindIt) {
  const glm::vec3 sky(0.5f, 1.0f, 2.0f);
  VarnishedFloor scene(scene::uniform_environment(sky), true);
  shading::GBuffer g;
  image::ImageRGB direct;
  const image::ImageRGB gi = scene.frame(48, g, direct);
  int checked = 0, with_mirror = 0;
  for (int y = 24; y < 48; y += 3)
    for (int x = 8; x < 40; x += 3) {
      const std::size_t p = static_cast<std::size_t>(y) * 48 + x;
      if (!g.samples[p].hit || g.samples[p].brdf.metallic >= 0.5f) continue;
      const float expected_albedo = VarnishedFloor::specular_albedo(g.samples[p]);
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(direct.pixels[p][c] + gi.pixels[p][c], expected_albedo * sky[c], 5e-3f * expected_albedo * sky[c] + 1e-5f)
            << "pixel (" << x << ", " << y << "), channel " << c;
      if (gi.pixels[p].b > 0.05f * expected_albedo * sky.b) ++with_mirror;
      ++checked;
    }
  EXPECT_GT(checked, 50);
  EXPECT_GT(with_mirror, 10) << "floor pixels whose reflection meets the mirror";
}

// The glossy dielectrics' reflection history: a still floor under a sky
// that varies with direction, seen at two jitter phases in turn. The second
// frame's reflection is the mean of what each phase alone gives (each
// frame's light over its specular albedo, the running mean over 2 frames,
// times this frame's albedo), pixel for pixel: the history follows the
// surface point to where the previous frame saw it. Tolerance 1e-4
// relative (float rounding) plus 1e-6 absolute. After forget_histories (a
// camera cut) a frame is its own phase's alone, exactly.
TEST(MirrorPath, AStillGlossyFloorsReflectionIsTheMeanOfItsFramesRays) {
  image::ImageRGB sky(16, 8);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 16; ++x) sky.at(x, y) = glm::vec3(0.2f + 0.3f * static_cast<float>(x % 5), 0.5f + 0.1f * static_cast<float>(y), 1.0f);
  VarnishedFloor scene(scene::Environment(sky, 1.0f, glm::mat4(1.0f)));
  // Less than half a pixel apart: each pixel finds itself in the other frame.
  const glm::vec2 phase_a{-0.125f, 0.125f}, phase_b{0.125f, -0.125f};
  // The direct image of one frame at `jitter`, with `scratch` (its history),
  // and each pixel's specular albedo.
  const auto frame = [&](glm::vec2 jitter, shading::RealtimeGiScratch& scratch, std::vector<float>& albedo) {
    shading::GBuffer g;
    image::ImageRGB direct;
    scene.frame(40, g, direct, shading::MirrorRay{}, jitter, &scratch);
    albedo.assign(g.samples.size(), 0.0f);
    for (std::size_t p = 0; p < g.samples.size(); ++p)
      if (g.samples[p].hit) albedo[p] = VarnishedFloor::specular_albedo(g.samples[p]);
    return direct;
  };
  shading::RealtimeGiScratch alone_a, alone_b, together;
  std::vector<float> albedo_a, albedo_b, albedo_2;
  const image::ImageRGB a_only = frame(phase_a, alone_a, albedo_a);
  const image::ImageRGB b_only = frame(phase_b, alone_b, albedo_b);
  frame(phase_a, together, albedo_2);
  const image::ImageRGB second = frame(phase_b, together, albedo_2);
  int checked = 0, differ = 0;
  for (int y = 22; y < 38; ++y)
    for (int x = 6; x < 34; ++x) {
      const std::size_t p = static_cast<std::size_t>(y) * 40 + x;
      ASSERT_GT(albedo_a[p], 0.0f) << "pixel (" << x << ", " << y << ") must see the floor";
      for (int c = 0; c < 3; ++c) {
        const float mean = albedo_b[p] * 0.5f * (a_only.pixels[p][c] / albedo_a[p] + b_only.pixels[p][c] / albedo_b[p]);
        EXPECT_NEAR(second.pixels[p][c], mean, 1e-4f * mean + 1e-6f) << "pixel (" << x << ", " << y << "), channel " << c;
        differ += std::abs(a_only.pixels[p][c] - b_only.pixels[p][c]) > 1e-3f * mean;
      }
      ++checked;
    }
  EXPECT_GT(checked, 400);
  EXPECT_GT(differ, checked) << "the two phases' rays must see different sky, or the test shows nothing";
  // A camera cut forgets it: the next frame is its phase's alone.
  together.forget_histories();
  const image::ImageRGB after_cut = frame(phase_a, together, albedo_2);
  for (std::size_t p = 0; p < a_only.pixels.size(); ++p) EXPECT_EQ(after_cut.pixels[p], a_only.pixels[p]) << "pixel " << p;
}
