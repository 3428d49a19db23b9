// The real-time G-buffer traced by the GPU ray tracer against Embree's
// packets: the Cornell box at 96 x 64 (rays through every pixel centre).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "engine/gpu/gpu_ray_tracer.h"
#include "engine/image/metrics.h"
#include "engine/render/light_plugin.h"
#include "engine/render/camera_rays.h"
#include "engine/scene/components.h"
#include "eval/method_runs.h"
#include "gpu_fixture.h"
#include "shading/realtime_direct.h"
#include "shading/realtime_gi.h"

using namespace transgi;
using namespace engine;

// Every pixel must see the same surface (entity and triangle) as with
// Embree, with depth to 1e-4 relative and normals to 1e-4. Ties are the
// exception: the box is symmetric about the camera, so rows of pixel centres
// fall exactly on the edges where two walls (or a quad's two triangles) meet,
// and each tracer, or the rasteriser's top-left rule, keeps a different one
// of two hits at the same distance. Those are counted apart; beyond them,
// 0.2 % of the pixels may differ (a sample grazing a silhouette).
TEST(GpuGBuffer, EqualsEmbreesPacketsOnTheCornellBox) {
  GPU_TEST_CONTEXT_OR_SKIP(ctx);
  eval::LoadedScene s = eval::load_scene(std::string(TRANSGI_CONTENT_DIR) + "/test_scenes/cornell_box/scene.gltf", "", 2);
  auto& w = s.app->world();
  const auto& rt = w.resource<rt::RtScene>();
  const auto& assets = w.resource<scene::SceneAssets>();
  const int width = 96, height = 64;
  const render::CameraRays rays(w.get<scene::Camera>(s.camera), w.get<transform::WorldTransform>(s.camera), width, height);
  // The camera's hits from the raster visibility pass where the device
  // rasterises (lavapipe does), then from the camera rays traced.
  for (const bool raster : {true, false}) {
    shading::GBuffer want, got;
    gpu::GpuRayTracer tracer(*ctx);
    tracer.set_raster_visibility(raster);
    if (raster && !tracer.camera_hit_tracer()) {
      std::printf("G-buffer: the device cannot rasterise; only the traced camera rays are compared\n");
      continue;
    }
    s.app->jobs().run([&] {
      shading::trace_gbuffer(rt, assets, rays, width, height, want);
      shading::trace_gbuffer(rt, assets, rays, width, height, got, nullptr, &tracer);
    });
    ASSERT_GT(tracer.take_device_ms(), 0.0) << "the GPU must have found the hits";
    std::size_t hits = 0, differ = 0, ties = 0, bad = 0;
    for (std::size_t i = 0; i < want.samples.size(); ++i) {
      const auto& a = want.samples[i];
      const auto& b = got.samples[i];
      hits += a.hit;
      if (a.hit != b.hit || a.entity != b.entity || a.triangle != b.triangle) {
        if (a.hit && b.hit && std::abs(a.depth - b.depth) <= 1e-5f * a.depth) ++ties;
        else ++differ;
        continue;
      }
      if (!a.hit) continue;
      if ((!(std::abs(a.depth - b.depth) <= 1e-4f * a.depth) || glm::length(a.normal_world - b.normal_world) > 1e-4f) && bad++ < 5)
        ADD_FAILURE() << "pixel " << i << ": expected depth " << a.depth << ", got " << b.depth;
    }
    std::printf("G-buffer (%s): %zu pixels, %zu hits, %zu ties at shared edges, %zu differ\n",
                raster ? "raster visibility" : "traced camera rays", want.samples.size(), hits, ties, differ);
    EXPECT_EQ(bad, 0u);
    EXPECT_LE(differ, want.samples.size() / 500);
    EXPECT_GT(hits, want.samples.size() / 2);
  }
}

namespace {

// The sample level with its light set: its sun is a punctual light.
struct SunlitLevel {
  eval::LoadedScene scene = eval::load_scene(std::string(TRANSGI_CONTENT_DIR) + "/levels/living_room/scene.gltf", "", 2);
  SunlitLevel() {
    scene.app->add_plugin<render::LightPlugin>();
    scene.app->update();
  }
  ecs::World& world() { return scene.app->world(); }
  const rt::RtScene& rt() { return world().resource<rt::RtScene>(); }
  const scene::SceneAssets& assets() { return world().resource<scene::SceneAssets>(); }
  const render::LightSet& lights() { return world().resource<render::SceneLights>().set; }
  render::CameraRays camera(int width, int height) {
    return {world().get<scene::Camera>(scene.camera), world().get<transform::WorldTransform>(scene.camera), width, height};
  }
};

}  // namespace

// The real-time deterministic direct light with its shadow rays in one batch
// through the GPU tracer, against Embree's packets tile by tile: the sample
// level's sun through its window at 160 x 90. The second pass must read each
// tile's answers where the first pass put its rays (a dangling answer buffer
// once doubled the sun here), so the images agree to 1e-4 RMSE and the same
// number of shadow rays is traced.
TEST(GpuGBuffer, BatchedShadowRaysGiveEmbreesDirectLight) {
  GPU_TEST_CONTEXT_OR_SKIP(ctx);
  SunlitLevel level;
  const auto& rt = level.rt();
  const auto& assets = level.assets();
  const auto& lights = level.lights();
  ASSERT_GT(lights.punctual_count(), 0u) << "the level's sun should be a punctual light";
  const int width = 160, height = 90;
  const render::CameraRays rays = level.camera(width, height);
  gpu::GpuRayTracer tracer(*ctx);
  shading::GBuffer g;
  shading::RealtimeDirectStats want_stats, got_stats;
  image::ImageRGB want, got;
  level.scene.app->jobs().run([&] {
    shading::trace_gbuffer(rt, assets, rays, width, height, g);
    want = shading::shade_direct_realtime(g, rt, lights, rays, &want_stats);
    got = shading::shade_direct_realtime(g, rt, lights, rays, &got_stats, &tracer);
  });
  double mean = 0;
  for (const auto& p : want.pixels) mean += p.g;
  mean /= static_cast<double>(want.pixels.size());
  const double rmse = image::rmse_clamped(got, want);
  std::printf("direct light: %zu shadow rays, mean %.4f, RMSE between Embree and the batched GPU rays %.3g\n",
              want_stats.shadow_rays, mean, rmse);
  EXPECT_EQ(got_stats.shadow_rays, want_stats.shadow_rays);
  EXPECT_GT(want_stats.shadow_rays, 1000u);
  EXPECT_LT(rmse, 1e-4) << "expected the batched shadow rays to give Embree's direct light";
}

// The same direct light with its shadow rays traced on the device right
// after the camera's queued view (CameraHitTracer::queue_camera_hits with
// view_shadow_request, issue 36: no submission of their own), against
// Embree's packets over the same G-buffer: the sample level's soft sun at
// 160 x 90, in a shifted phase of its pattern. The device rounds the surface
// point and its normal apart from the G-buffer's (a ray grazing an edge
// could answer the other way; none does here): the images agree to 1e-4
// RMSE, no ray the shader asks for is missing, and the shading submits
// nothing.
TEST(GpuGBuffer, ShadowRaysTracedWithTheQueuedViewGiveEmbreesDirectLight) {
  GPU_TEST_CONTEXT_OR_SKIP(ctx);
  if (!gpu::VisibilityPass::supported(*ctx)) GTEST_SKIP() << "the device's queue cannot rasterise";
  SunlitLevel level;
  const auto& rt = level.rt();
  const auto& assets = level.assets();
  const auto& lights = level.lights();
  ASSERT_GT(lights.punctual_count(), 0u) << "the level's sun should be a punctual light";
  const int width = 160, height = 90, phase = 5;
  const render::CameraRays rays = level.camera(width, height);
  gpu::GpuRayTracer tracer(*ctx);
  tracer.set_raster_visibility(true);
  render::CameraHitTracer* raster = tracer.camera_hit_tracer();
  ASSERT_NE(raster, nullptr);
  shading::GBuffer g;
  shading::RealtimeDirectStats want_stats, got_stats;
  image::ImageRGB want, got;
  std::uint64_t shading_submissions = 0;
  level.scene.app->jobs().run([&] {
    const render::ViewShadowRequest request = shading::view_shadow_request(lights, phase, rt.offset_scale());
    raster->queue_camera_hits(rt, rays, glm::vec2(0.5f), &request);
    shading::trace_gbuffer(rt, assets, rays, width, height, g, nullptr, &tracer);
    want = shading::shade_direct_realtime(g, rt, lights, rays, &want_stats, nullptr, phase);
    const std::uint64_t before = ctx->traffic().submissions;
    got = shading::shade_direct_realtime(g, rt, lights, rays, &got_stats, &tracer, phase);
    shading_submissions = ctx->traffic().submissions - before;
  });
  ASSERT_TRUE(got_stats.traced_with_view) << "the G-buffer did not take the queued view, or its shadow answers were not kept";
  double mean = 0;
  for (const auto& p : want.pixels) mean += p.g;
  mean /= static_cast<double>(want.pixels.size());
  const double rmse = image::rmse_clamped(got, want);
  std::printf("direct light: %zu shadow rays, mean %.4f, RMSE between Embree and the rays traced with the view %.3g, %zu answers "
              "missing\n", want_stats.shadow_rays, mean, rmse, got_stats.untraced_answers);
  EXPECT_EQ(got_stats.shadow_rays, want_stats.shadow_rays);
  EXPECT_GT(want_stats.shadow_rays, 1000u);
  EXPECT_EQ(got_stats.untraced_answers, 0u);
  EXPECT_EQ(shading_submissions, 0u) << "the shading traced rays of its own";
  EXPECT_LT(rmse, 1e-4) << "expected the view's shadow rays to give Embree's direct light";
}
