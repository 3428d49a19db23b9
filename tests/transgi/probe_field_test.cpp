// The probe frame loop against a known answer: probes above a large
// Lambertian floor (albedo a) under a uniform sky of radiance 1. Every ray
// down hits the floor, whose radiance is a (direct light only: an open plane
// gets no indirect light); every ray up escapes and records zero. So each
// probe's radiance is a below the horizon and 0 above, whose SH is
// L00 = a sqrt(pi) and L(1,-1) (the y coefficient) = -a 0.4886 pi.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "engine/app/app.h"
#include "engine/rt/rt_plugin.h"
#include "engine/scene/procedural.h"
#include "engine/render/surface.h"
#include "probes/probe_field.h"
#include "probes/probe_rays.h"
#include "floor_under_sky.h"

using namespace transgi::probes;
using namespace engine;

namespace {

ProbeFieldSettings floor_probes() {
  ProbeFieldSettings settings = floor_probe_settings();
  settings.window = false;  // compare the raw projection with the analytic one
  return settings;
}

render::LightSet sky_lights(FloorUnderSky& s) {
  return render::LightSet(s.app.world().resource<rt::RtScene>(), {}, &*s.app.world().resource<scene::SceneAssets>().environment);
}

// L00 = a sqrt(pi) and L(1,-1) = -a 0.4886 pi at every probe, to `relative`.
void expect_floor_sh(const ProbeField& field, float a, double relative) {
  const double pi = 3.14159265358979323846;
  for (int p = 0; p < field.settings().grid.count(); ++p) {
    const float* L = field.light_sh(p);
    EXPECT_NEAR(L[0], a * std::sqrt(pi), relative * a * std::sqrt(pi)) << "probe " << p << " L00";
    EXPECT_NEAR(L[1], -a * 0.488603 * pi, relative * a * 0.488603 * pi) << "probe " << p << " L(1,-1)";
  }
}

}  // namespace

TEST(ProbeField, ProbesAboveALitFloorConvergeToTheAnalyticSh) {
  const float a = 0.5f;
  FloorUnderSky s(a);
  const render::LightSet lights = sky_lights(s);
  const ProbeFieldSettings settings = floor_probes();
  ProbeField field(settings);
  s.app.jobs().run([&] {
    // 200 frames: with hysteresis 0.95 the history spans ~20-40 frames, and
    // 40 frames left 4 % of Monte Carlo noise in L(1,-1).
    for (int f = 0; f < 200; ++f) field.update(s.app.world().resource<rt::RtScene>(), lights);
  });
  expect_floor_sh(field, a, 0.04);
  for (int p = 0; p < settings.grid.count(); ++p) EXPECT_NEAR(field.light_sh(p)[25], field.light_sh(p)[0], 1e-5) << "grey: channels agree";
  // The floor's irradiance from the probes (upper hemisphere sees only the
  // sky, which the probes do not hold) is near zero.
  EXPECT_LT(field.irradiance({0, 0.01f, 0}, {0, 1, 0}).g, 0.1f);
}

// ---- switching a light off (issue 5, test 3) ----------------------------------------
//
// A floor lit by two point lights; after the probes settle, light A goes off.
// Count the frames until every probe's L00 is within 5 % of its settled value
// with light B alone. A fixed hysteresis of 0.97 (RTXGI's) needs about
// log(0.05)/log(0.97) ~ 98 frames per texel in theory (more here: texels that
// are sampled rarely decay more slowly); the probes' change detection, which
// blends fast and drops stale texels once a change is far beyond the noise,
// must be much faster.

namespace {
// A square floor of half width `half` and material m, at the origin, the
// world's only mesh.
void add_floor(app::App& app, const material::Material& m, float half) {
  scene::SceneAssets a;
  a.generation = scene::next_scene_generation();
  a.meshes = {std::make_shared<scene::MeshAsset>(scene::make_quad({half, half}))};
  a.materials = {m};
  app.world().insert_resource<scene::SceneAssets>(std::move(a));
  app.add_plugin<rt::RtPlugin>();
  const ecs::Entity floor = app.world().spawn();
  app.world().emplace<transform::Transform>(floor);
  app.world().emplace<scene::MeshInstance>(floor, scene::MeshInstance{0});
}

struct TwoLights {
  app::App app{app::AppOptions{.jobs = {.threads = 2}}};
  ecs::Entity light_a, light_b;
  TwoLights() {
    material::Material m;
    m.base_color_factor = glm::vec4(0.6f, 0.6f, 0.6f, 1);
    m.metallic_factor = 0;
    m.specular_factor = 0;
    add_floor(app, m, 4);
    light_a = spawn_light({-1.5f, 2.0f, 0.0f}, 20.0f);
    light_b = spawn_light({1.5f, 2.0f, 0.0f}, 10.0f);
    app.update();
  }
  ecs::Entity spawn_light(glm::vec3 at, float intensity) {
    const ecs::Entity e = app.world().spawn();
    app.world().emplace<transform::Transform>(e, transform::Transform::from_translation(at));
    app.world().emplace<scene::PunctualLight>(e, scene::PunctualLight{.intensity = intensity});
    return e;
  }
  render::LightSet lights() {
    app.update();
    return render::LightSet(app.world().resource<rt::RtScene>(), render::gather_punctual_lights(app.world()), nullptr);
  }
};

ProbeFieldSettings switch_settings(float hysteresis, bool adaptive) {
  ProbeFieldSettings s;
  s.grid = ProbeGrid{{-1.5f, 0.5f, -1.5f}, {1.5f, 1.5f, 1.5f}, {3, 2, 3}};
  s.map = MapLayout{32, 16};
  s.rays_per_probe = 400;
  s.accumulation.hysteresis = hysteresis;
  if (!adaptive) {
    s.accumulation.change_threshold = 1e9f;
    s.skip.skip_converged = false;  // RTXGI's fixed blend keeps updating every probe
  }
  return s;
}

// Frames after the switch until every probe's L00 is within 5 % of `settled`.
int frames_to_settle(TwoLights& scene, ProbeField& field, const std::vector<float>& settled) {
  scene.app.world().get_mut<scene::PunctualLight>(scene.light_a).enabled = false;
  const auto lights = scene.lights();
  field.notify_scene_changed({.light_changed = true});  // what the ECS system does when a light changes
  for (int frame = 1; frame <= 400; ++frame) {
    scene.app.jobs().run([&] { field.update(scene.app.world().resource<rt::RtScene>(), lights); });
    bool all = true;
    for (int p = 0; p < field.settings().grid.count(); ++p)
      all = all && std::abs(field.light_sh(p)[0] - settled[static_cast<std::size_t>(p)]) <= 0.05f * settled[static_cast<std::size_t>(p)];
    if (all) return frame;
  }
  return 401;
}
}  // namespace

TEST(ProbeField, SwitchingALightOffSettlesInFewFrames) {
  // Settled value with light B only.
  TwoLights only_b;
  only_b.app.world().get_mut<scene::PunctualLight>(only_b.light_a).enabled = false;
  const auto lights_b = only_b.lights();
  ProbeField reference(switch_settings(0.95f, true));
  only_b.app.jobs().run([&] {
    for (int f = 0; f < 150; ++f) reference.update(only_b.app.world().resource<rt::RtScene>(), lights_b);
  });
  std::vector<float> settled;
  for (int p = 0; p < reference.settings().grid.count(); ++p) settled.push_back(reference.light_sh(p)[0]);

  auto run = [&](float hysteresis, bool adaptive) {
    TwoLights scene;
    const auto both = scene.lights();
    ProbeField field(switch_settings(hysteresis, adaptive));
    scene.app.jobs().run([&] {
      for (int f = 0; f < 150; ++f) field.update(scene.app.world().resource<rt::RtScene>(), both);
    });
    return frames_to_settle(scene, field, settled);
  };
  const int adaptive = run(0.95f, true);
  const int fixed_097 = run(0.97f, false);
  std::printf("frames to within 5 %% after switching a light off: adaptive %d, fixed hysteresis 0.97 %d\n", adaptive, fixed_097);
  // Measured: adaptive 27 frames, fixed 0.97 344 frames (every probe within
  // 5 %, so rarely resampled texels set the pace of the fixed blend).
  EXPECT_LE(adaptive, 40) << "the probes' change detection should react within tens of frames";
  EXPECT_GE(fixed_097, 3 * adaptive) << "and clearly faster than RTXGI's fixed 0.97 hysteresis";
}

// The oracle probes of the error decomposition (issue 14, item 2) hold the
// same analytic answer, path-traced in one go instead of accumulated.
TEST(ProbeField, OracleProbesAboveALitFloorHoldTheAnalyticSh) {
  const float a = 0.5f;
  FloorUnderSky s(a);
  const render::LightSet lights = sky_lights(s);
  ProbeField field(floor_probes());
  s.app.jobs().run([&] {
    field.update(s.app.world().resource<rt::RtScene>(), lights);  // classifies the probes
    field.replace_with_oracle(s.app.world().resource<rt::RtScene>(), lights, 16, 9);
  });
  expect_floor_sh(field, a, 0.02);
}

// ---- the bounce a probe ray's hit reflects --------------------------------------------
//
// A floor lit evenly by radiance L = E / pi from its whole hemisphere (the
// feedback's irradiance E, no lights) reflects towards any wo exactly its
// BRDF's directional albedo times L (tests/engine/brdf_test.cpp checks that
// albedo against the BRDF's integral). With the diffuse albedo alone, as
// before, a gold floor reflected nothing of the room's light and a
// varnished one too little; the near field (HitLobes::Diffuse) keeps the
// diffuse lobe.
TEST(ProbeRays, AHitReflectsTheFeedbackByItsWholeDirectionalAlbedo) {
  const float irradiance = 2.0f, cos_o = 0.5f;
  const glm::vec3 dir = glm::normalize(glm::vec3(std::sqrt(1.0f - cos_o * cos_o), -cos_o, 0.0f));
  material::Material gold, varnish;
  gold.base_color_factor = glm::vec4(1.0f, 0.78f, 0.34f, 1);
  gold.metallic_factor = 1;
  gold.roughness_factor = 0.4f;
  varnish.base_color_factor = glm::vec4(0.30f, 0.15f, 0.08f, 1);
  varnish.metallic_factor = 0;
  varnish.roughness_factor = 0.3f;
  for (const material::Material& m : {gold, varnish}) {
    app::App app(app::AppOptions{.jobs = {.threads = 1}});
    add_floor(app, m, 100);
    app.update();
    const auto& rt = app.world().resource<rt::RtScene>();
    const render::LightSet none(rt, {}, nullptr);
    const auto feedback = [&](const glm::vec3&, const glm::vec3&, const glm::vec3&) { return glm::vec3(irradiance); };
    math::Pcg32 rng(1, 2);
    const ProbeRayHit all = trace_probe_ray(rt, none, {0, 1, 0}, dir, rng, feedback);
    rt::Hit hit;
    ASSERT_TRUE(rt.intersect(rt::Ray{{0, 1, 0}, dir}, hit));
    const PendingProbeRay diffuse_only = begin_probe_ray(rt, none, dir, &hit, rng, HitLobes::Diffuse);
    const ProbeRayHit diffuse = finish_probe_ray(diffuse_only, false, feedback);
    const render::Surface s = render::make_surface(rt, hit, dir);
    const glm::vec3 expected = material::directional_albedo(s.brdf, cos_o) * irradiance / 3.14159265f;
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(all.radiance[k], expected[k], 1e-5f * expected[k] + 1e-7f) << "metallic " << m.metallic_factor << " channel " << k;
      EXPECT_NEAR(diffuse.radiance[k], material::diffuse_albedo(s.brdf)[k] * irradiance / 3.14159265f, 1e-6f);
    }
    EXPECT_GT(all.radiance.b, diffuse.radiance.b + 0.01f) << "the specular layer reflects the room's light too";
  }
}

// A mirror floor under an even sky of radiance 1 reflects, towards any wo,
// its directional albedo (the sky is the same in every direction). A probe
// ray's hit estimates that from one light sample: with the mirror's own lobe
// the sample almost never meets the mirror direction and, when it does, is
// worth tens of thousands (the fireplace glow of docs/image-quality.md); the
// blurred lobe, scaled to the mirror's own albedo, keeps the mean and every
// sample small.
TEST(ProbeRays, AMirrorsLightSampleIsBoundedAndKeepsItsMeanUnderAnEvenSky) {
  material::Material mirror;
  mirror.base_color_factor = glm::vec4(0.95f, 0.9f, 0.8f, 1);
  mirror.metallic_factor = 1;
  mirror.roughness_factor = 0;
  app::App app(app::AppOptions{.jobs = {.threads = 1}});
  add_floor(app, mirror, 100);
  app.world().resource<scene::SceneAssets>().environment = scene::uniform_environment(glm::vec3(1.0f));
  app.update();
  const auto& rt = app.world().resource<rt::RtScene>();
  const render::LightSet sky(rt, {}, &*app.world().resource<scene::SceneAssets>().environment);
  const float cos_o = 0.6f;
  const glm::vec3 dir = glm::normalize(glm::vec3(std::sqrt(1.0f - cos_o * cos_o), -cos_o, 0.0f));
  rt::Hit hit;
  ASSERT_TRUE(rt.intersect(rt::Ray{{0, 1, 0}, dir}, hit));
  const glm::vec3 expected = material::directional_albedo(render::make_surface(rt, hit, dir).brdf, cos_o);
  math::Pcg32 rng(7, 3);
  const int n = 400000;
  glm::dvec3 sum(0.0);
  float largest = 0;
  for (int i = 0; i < n; ++i) {
    const PendingProbeRay p = begin_probe_ray(rt, sky, dir, &hit, rng);
    sum += glm::dvec3(p.unoccluded);
    largest = std::max({largest, p.unoccluded.r, p.unoccluded.g, p.unoccluded.b});
  }
  // The estimate's standard deviation is about 1 % of the mean here.
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(sum[k] / n, expected[k], 0.10 * expected[k]) << "channel " << k;
  // The floored lobe's peak f cos_i, F D / (4 cos_o) with D = 1 / (pi
  // alpha^2) at alpha = 0.25, times 4 pi (the sky's radiance over its
  // sampling pdf): about 25; the mirror's own peak would be some 10^6.
  EXPECT_LT(largest, 100.0f);
}
