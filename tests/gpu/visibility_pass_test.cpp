// The raster visibility pass (engine/gpu/visibility_pass) against the GPU
// ray tracer (GpuRtScene::intersect, itself tested against Embree) on the
// same camera rays: every pixel must see the same instance and triangle at
// the same distance and barycentrics. A rasteriser and a ray test decide a
// pixel that falls on an edge between triangles by different rules (the
// top-left rule against a watertight intersection in floating point), so a
// few pixels on shared edges may go to the other triangle (at most 0.5 %
// of the pixels, and those only where the two hits lie at the same
// distance), and a ray grazing a silhouette may round the other way than
// the raster's sample (at most 0.1 %, and only where a neighbouring pixel
// of the raster's sees what the ray saw). Every test runs with the BVH traversal and with ray queries,
// whose scenes bind the raster's buffers differently.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <glm/gtc/quaternion.hpp>

#include "engine/gpu/gpu_rt_scene.h"
#include "engine/gpu/visibility_pass.h"
#include "engine/render/camera_rays.h"
#include "engine/render/view_shadows.h"
#include "engine/scene/procedural.h"
#include "gpu_fixture.h"
#include "rt_world.h"

using namespace engine;

namespace {

using gpu_test::Traversal;

class VisibilityPassTest : public testing::TestWithParam<Traversal> {};

struct Agreement {
  std::size_t pixels = 0, hits = 0, edge_ties = 0, silhouettes = 0, differ = 0, bad_depth = 0, bad_barycentrics = 0;
};

constexpr std::uint32_t kNothing = 0xffffffffu;

// Whether a 4-neighbour of pixel i in the raster's image sees `instance`
// (kNothing: the sky): pixel i then lies on that surface's silhouette,
// where a ray grazing an edge and a rasteriser's sample may round apart.
bool beside(const std::vector<rt::Hit>& hits, const std::vector<std::uint8_t>& found, std::size_t i, std::uint32_t instance,
            int width) {
  const int x = static_cast<int>(i) % width, y = static_cast<int>(i) / width;
  const int height = static_cast<int>(hits.size()) / width;
  for (const glm::ivec2 d : {glm::ivec2(1, 0), glm::ivec2(-1, 0), glm::ivec2(0, 1), glm::ivec2(0, -1)}) {
    const int nx = x + d.x, ny = y + d.y;
    if (nx < 0 || ny < 0 || nx >= width || ny >= height) continue;
    const auto j = static_cast<std::size_t>(ny * width + nx);
    if ((found[j] ? hits[j].instance : kNothing) == instance) return true;
  }
  return false;
}

// The raster's hits against the tracer's for the camera rays through film
// (x, y) + sample; prints the counts under `what`.
Agreement compare(const char* what, gpu::VisibilityPass& pass, gpu::GpuRtScene& gpu_rt, const render::CameraRays& camera,
                  glm::vec2 sample, float near_plane) {
  const int w = camera.width(), h = camera.height();
  const std::size_t n = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  std::vector<rt::Ray> rays(n);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) rays[static_cast<std::size_t>(y * w + x)] = camera.generate(glm::vec2(x, y) + sample);
  std::vector<rt::Hit> want(n), got(n);
  std::vector<std::uint8_t> want_found(n), got_found(n);
  gpu_rt.intersect(rays, want, want_found);
  pass.render(gpu_rt, camera, sample, near_plane, got, got_found);
  Agreement a;
  a.pixels = n;
  for (std::size_t i = 0; i < n; ++i) {
    a.hits += want_found[i];
    const rt::Hit &p = want[i], &q = got[i];
    if (want_found[i] != got_found[i] || (want_found[i] && (p.instance != q.instance || p.primitive != q.primitive))) {
      if (want_found[i] && got_found[i] && std::abs(p.t - q.t) <= 1e-3f * p.t) ++a.edge_ties;
      else if (beside(got, got_found, i, want_found[i] ? p.instance : kNothing, w)) ++a.silhouettes;
      else ++a.differ;
      continue;
    }
    if (!want_found[i]) continue;
    if (!(std::abs(p.t - q.t) <= 1e-4f * p.t)) ++a.bad_depth;
    if (glm::length(p.barycentric - q.barycentric) > 1e-3f) ++a.bad_barycentrics;
    EXPECT_EQ(q.entity, p.entity) << "pixel " << i;
    EXPECT_EQ(q.mesh, p.mesh) << "pixel " << i;
  }
  std::printf("visibility (%s): %zu pixels, %zu hits, %zu ties on shared edges, %zu on silhouettes, %zu differ, %zu "
              "depths and %zu barycentrics off\n", what, a.pixels, a.hits, a.edge_ties, a.silhouettes, a.differ, a.bad_depth,
              a.bad_barycentrics);
  return a;
}

void expect_agreement(const Agreement& a) {
  EXPECT_EQ(a.differ, 0u) << "a pixel away from any edge saw another surface";
  EXPECT_LE(a.edge_ties, a.pixels / 200);
  EXPECT_LE(a.silhouettes, a.pixels / 1000);
  EXPECT_EQ(a.bad_depth, 0u);
  EXPECT_EQ(a.bad_barycentrics, 0u);
  EXPECT_GT(a.hits, a.pixels / 2);
}

// The traversal's context, or null with the reason (also where the queue
// cannot rasterise).
gpu::VulkanContext* context_for(Traversal t, std::string* why) {
  gpu::VulkanContext* ctx = gpu_test::traversal_context(t, false, why);
  if (!ctx || !gpu::VisibilityPass::supported(*ctx, why)) return nullptr;
  return ctx;
}

// A camera inside build_world's room, looking across it.
render::CameraRays room_camera(int width, int height) {
  scene::Camera lens;
  lens.yfov_radians = 1.1f;
  transform::Similarity at;
  at.translation = glm::vec3(-3.5f, 1.0f, 3.0f);
  at.rotation = glm::angleAxis(-0.7f, glm::vec3(0, 1, 0)) * glm::angleAxis(-0.2f, glm::vec3(1, 0, 0));
  return render::CameraRays(lens, at, width, height);
}

}  // namespace

#define VISIBILITY_CONTEXT_OR_SKIP(name)                                 \
  std::string visibility_why_;                                           \
  gpu::VulkanContext* name = context_for(GetParam(), &visibility_why_); \
  if (!name) GTEST_SKIP() << visibility_why_

// A closed room of rotated, scaled, overlapping meshes, seen from inside at
// two sub-pixel offsets, then after one instance moved and the scene synced.
TEST_P(VisibilityPassTest, SeesWhatTheCameraRaysHitInARoomOfObjects) {
  VISIBILITY_CONTEXT_OR_SKIP(ctx);
  gpu_test::RtWorld world;
  gpu_test::build_world(world);
  gpu::GpuRtScene gpu_rt(*ctx);
  gpu_rt.sync(world.rt);
  const render::CameraRays camera = room_camera(160, 90);
  const transform::Similarity at = camera.to_world();
  gpu::VisibilityPass pass(*ctx);
  expect_agreement(compare("room, pixel centres", pass, gpu_rt, camera, {0.5f, 0.5f}, 0.01f));
  expect_agreement(compare("room, offset (0.2, 0.7)", pass, gpu_rt, camera, {0.2f, 0.7f}, 0.01f));
  // The nearest sphere or torus moved in front of the camera.
  transform::Similarity moved = world.xf[1];
  moved.translation = at.translation + at.rotation * glm::vec3(0.3f, 0.0f, -2.0f);
  world.rt.upsert_instance(ecs::Entity{1, 0}, world.mesh_of[1], moved);
  world.rt.commit();
  gpu_rt.sync(world.rt);
  const Agreement after = compare("room, an instance moved", pass, gpu_rt, camera, {0.5f, 0.5f}, 0.01f);
  expect_agreement(after);
  EXPECT_EQ(ctx->validation_errors(), 0);
}

// Cut-out screens (glTF MASK, checkered alpha textures) in front of a
// wall: a fragment the ray would pass through is discarded. Pixels whose
// hit lies at a texel's edge may round to either texel, as between the two
// tracers (rt_traversal_test.cpp).
TEST_P(VisibilityPassTest, CutOutsPassWhereTheRaysPass) {
  VISIBILITY_CONTEXT_OR_SKIP(ctx);
  scene::SceneAssets assets;
  assets.generation = scene::next_scene_generation();
  const scene::MeshAsset wall = gpu_test::wall_quad(), screen = gpu_test::screen_quad(1);
  assets.meshes = {std::make_shared<scene::MeshAsset>(wall), std::make_shared<scene::MeshAsset>(screen)};
  assets.materials.resize(2);
  assets.materials[1].alpha_mode = material::AlphaMode::Mask;
  assets.materials[1].alpha_cutoff = 0.5f;
  assets.materials[1].base_color_texture = 0;
  scene::Texture t;
  t.width = t.height = 8;
  t.rgba.assign(8 * 8 * 4, 255);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) t.rgba[static_cast<std::size_t>(y * 8 + x) * 4 + 3] = (x + y) % 2 ? 0 : 255;
  assets.textures.push_back(t);
  rt::RtScene rt;
  rt.set_assets(&assets);
  const glm::quat upright = glm::angleAxis(1.5707963f, glm::vec3(1.0f, 0.0f, 0.0f));
  transform::Similarity at_wall, at_screen;
  at_wall.translation = glm::vec3(0.0f, 0.0f, -2.0f);
  at_wall.rotation = upright;
  at_screen.rotation = glm::angleAxis(0.3f, glm::vec3(0.0f, 1.0f, 0.0f)) * upright;
  rt.upsert_instance(ecs::Entity{0, 0}, 0, at_wall);
  rt.upsert_instance(ecs::Entity{1, 0}, 1, at_screen);
  rt.commit();
  gpu::GpuRtScene gpu_rt(*ctx);
  gpu_rt.sync(rt);
  scene::Camera lens;
  lens.yfov_radians = 0.9f;
  transform::Similarity eye;
  eye.translation = glm::vec3(0.0f, 0.0f, 3.0f);
  const render::CameraRays camera(lens, eye, 128, 96);
  gpu::VisibilityPass pass(*ctx);
  const Agreement a = compare("cut-outs", pass, gpu_rt, camera, {0.5f, 0.5f}, 0.01f);
  // A texel-edge disagreement is a screen hit against a wall hit beside
  // a pixel of either: it counts as a silhouette.
  EXPECT_EQ(a.differ, 0u);
  EXPECT_LE(a.silhouettes, a.pixels / 500);
  EXPECT_LE(a.edge_ties, a.pixels / 200);
  EXPECT_EQ(a.bad_depth, 0u);
  EXPECT_GT(a.hits, a.pixels / 2);
  EXPECT_EQ(ctx->validation_errors(), 0);
}

// Nothing nearer the camera than the near plane is drawn (the ray tracer
// has no near plane): with the camera half a unit from the wall and the
// near plane beyond it, every pixel sees nothing.
TEST_P(VisibilityPassTest, NothingNearerThanTheNearPlaneIsDrawn) {
  VISIBILITY_CONTEXT_OR_SKIP(ctx);
  scene::SceneAssets assets;
  assets.generation = scene::next_scene_generation();
  assets.meshes = {std::make_shared<scene::MeshAsset>(gpu_test::wall_quad())};
  assets.materials.resize(1);
  rt::RtScene rt;
  rt.set_assets(&assets);
  transform::Similarity at_wall;
  at_wall.rotation = glm::angleAxis(1.5707963f, glm::vec3(1.0f, 0.0f, 0.0f));
  rt.upsert_instance(ecs::Entity{0, 0}, 0, at_wall);
  rt.commit();
  gpu::GpuRtScene gpu_rt(*ctx);
  gpu_rt.sync(rt);
  transform::Similarity eye;
  eye.translation = glm::vec3(0.0f, 0.0f, 0.5f);
  const render::CameraRays camera(scene::Camera{}, eye, 32, 32);
  gpu::VisibilityPass pass(*ctx);
  std::vector<rt::Hit> hits(32 * 32);
  std::vector<std::uint8_t> found(32 * 32);
  pass.render(gpu_rt, camera, {0.5f, 0.5f}, 0.4f, hits, found);
  EXPECT_EQ(std::count(found.begin(), found.end(), 1), 32 * 32) << "the wall is beyond a near plane at 0.4";
  pass.render(gpu_rt, camera, {0.5f, 0.5f}, 0.6f, hits, found);
  EXPECT_EQ(std::count(found.begin(), found.end(), 1), 0) << "the wall is nearer than a near plane at 0.6";
}

// A queued view (issue 36: drawn with the frame's first submission) gives
// render()'s hits for the same view without a submission of its own when
// another stage submitted; a request for another view or sample drops it
// and is answered by render(), as is one after the scene changed.
TEST_P(VisibilityPassTest, AQueuedViewIsTakenOnlyForTheSameViewAndGivesRendersHits) {
  VISIBILITY_CONTEXT_OR_SKIP(ctx);
  gpu_test::RtWorld world;
  gpu_test::build_world(world);
  gpu::GpuRtScene gpu_rt(*ctx);
  gpu_rt.sync(world.rt);
  const render::CameraRays camera = room_camera(96, 64);
  const std::size_t n = 96 * 64;
  gpu::VisibilityPass pass(*ctx);
  std::vector<rt::Hit> want(n), got(n);
  std::vector<std::uint8_t> want_found(n), got_found(n);
  pass.render(gpu_rt, camera, {0.3f, 0.6f}, 0.01f, want, want_found);
  ASSERT_GT(std::count(want_found.begin(), want_found.end(), 1), static_cast<long>(n / 2));

  pass.queue(gpu_rt, camera, {0.3f, 0.6f}, 0.01f);
  const std::uint64_t before = ctx->traffic().submissions;
  ctx->submit_and_wait([](VkCommandBuffer) {});  // another stage's submission
  double ms = -1;
  ASSERT_TRUE(pass.take_queued(gpu_rt, camera, {0.3f, 0.6f}, 0.01f, got, got_found, &ms));
  EXPECT_EQ(ctx->traffic().submissions - before, 1u) << "the queued view rode with the other stage's submission";
  EXPECT_GE(ms, 0.0);
  std::size_t differ = 0;
  for (std::size_t i = 0; i < n; ++i)
    differ += want_found[i] != got_found[i] ||
              (want_found[i] && (want[i].instance != got[i].instance || want[i].primitive != got[i].primitive ||
                                 want[i].t != got[i].t || want[i].entity != got[i].entity));
  EXPECT_EQ(differ, 0u);

  // Queued for one sample, asked for another: not taken, and dropped.
  pass.queue(gpu_rt, camera, {0.3f, 0.6f}, 0.01f);
  EXPECT_FALSE(pass.take_queued(gpu_rt, camera, {0.5f, 0.5f}, 0.01f, got, got_found));
  EXPECT_FALSE(ctx->has_deferred(&pass)) << "a view not taken is dropped";
  // Queued and taken with no submission in between: submitted then.
  pass.queue(gpu_rt, camera, {0.3f, 0.6f}, 0.01f);
  const std::uint64_t alone = ctx->traffic().submissions;
  ASSERT_TRUE(pass.take_queued(gpu_rt, camera, {0.3f, 0.6f}, 0.01f, got, got_found));
  EXPECT_EQ(ctx->traffic().submissions - alone, 1u);
  EXPECT_EQ(got_found, want_found);
  // Another scene: not taken.
  pass.queue(gpu_rt, camera, {0.3f, 0.6f}, 0.01f);
  gpu::GpuRtScene other(*ctx);
  other.sync(world.rt);
  EXPECT_FALSE(pass.take_queued(other, camera, {0.3f, 0.6f}, 0.01f, got, got_found));
  EXPECT_EQ(ctx->validation_errors(), 0);
}

// The view's shadow rays (render/view_shadows.h) traced on the device right
// after the queued view, in its commands, against the CPU oracle
// (trace_view_shadows, Embree) over the device's own hits: a soft sun's
// 8 x 8 pattern with the nearest blocker's distance, a hard directional
// light and a point light inside the room. The two trace from the same
// surface points but round p, the normal and the traversal apart, so a ray
// that grazes an edge or a surface may answer the other way, and one that
// grazes a curved blocker meets it a few millimetres apart: at most 0.1 %
// of the answers each; nearest distances within 1e-3 relative elsewhere. The
// answers are handed out once, and only for the request they were queued for.
TEST_P(VisibilityPassTest, TheViewsShadowRaysRideWithItAndEqualTheCpuOracles) {
  VISIBILITY_CONTEXT_OR_SKIP(ctx);
  gpu_test::RtWorld world;
  gpu_test::build_world(world);
  gpu::GpuRtScene gpu_rt(*ctx);
  gpu_rt.sync(world.rt);
  const int w = 160, h = 90;
  const render::CameraRays camera = room_camera(w, h);
  const std::size_t n = static_cast<std::size_t>(w) * h;
  const glm::vec2 sample{0.4f, 0.55f};
  render::ViewShadowRequest request;
  request.pattern_shift = {2, 6};
  request.offset_scale = world.rt.offset_scale();
  render::ViewShadowLight sun;
  sun.directional = true;
  sun.nearest = true;
  const glm::vec3 towards = glm::normalize(glm::vec3(0.3f, 1.0f, 0.2f));
  for (int c = 0; c < render::kViewShadowPatternCells; ++c)
    sun.directions[static_cast<std::size_t>(c)] =
        glm::normalize(towards + 0.05f * glm::vec3(std::cos(0.7f * c), 0.0f, std::sin(0.7f * c)) * (static_cast<float>(c) / 64.0f));
  render::ViewShadowLight hard = sun;
  hard.nearest = false;
  hard.directions.fill(glm::normalize(glm::vec3(-0.5f, 0.8f, -0.3f)));
  render::ViewShadowLight point;
  point.position = glm::vec3(0.5f, 2.6f, -0.5f);
  request.lights = {sun, hard, point};

  gpu::VisibilityPass pass(*ctx);
  pass.queue(gpu_rt, camera, sample, 0.01f, &request);
  const std::uint64_t before = ctx->traffic().submissions;
  ctx->submit_and_wait([](VkCommandBuffer) {});  // another stage's submission
  std::vector<rt::Hit> hits(n);
  std::vector<std::uint8_t> found(n);
  ASSERT_TRUE(pass.take_queued(gpu_rt, camera, sample, 0.01f, hits, found));
  EXPECT_EQ(ctx->traffic().submissions - before, 1u) << "the shadow rays rode with the other stage's submission";
  render::ViewShadowRequest other = request;
  other.pattern_shift = {4, 6};
  std::vector<float> got;
  EXPECT_FALSE(pass.take_shadows(other, got)) << "answers handed out for another pattern";
  // take_shadows consumed them: queue again for the real check.
  pass.queue(gpu_rt, camera, sample, 0.01f, &request);
  ASSERT_TRUE(pass.take_queued(gpu_rt, camera, sample, 0.01f, hits, found));
  ASSERT_TRUE(pass.take_shadows(request, got));
  EXPECT_FALSE(pass.take_shadows(request, got)) << "each view's answers are taken once";
  ASSERT_EQ(got.size(), 3 * n);
  std::vector<float> want(3 * n);
  render::trace_view_shadows(world.rt, camera, sample, hits, found, request, want);

  std::size_t traced = 0, blocked = 0, lit = 0, differ = 0, far = 0;
  for (std::size_t k = 0; k < want.size(); ++k) {
    const float a = want[k], b = got[k];
    if (std::isnan(a) != std::isnan(b)) {
      ++differ;
      continue;
    }
    if (std::isnan(a)) continue;
    ++traced;
    (std::isinf(a) ? lit : blocked) += 1;
    if (std::isinf(a) != std::isinf(b)) {
      ++differ;
      continue;
    }
    if (!std::isinf(a) && std::abs(a - b) > 1e-3f * std::max(1.0f, a)) ++far;
  }
  std::printf("view shadows: %zu answers, %zu traced (%zu blocked, %zu lit), %zu differ in kind, %zu distances off\n", want.size(),
              traced, blocked, lit, differ, far);
  EXPECT_GT(traced, want.size() / 3) << "too few rays to tell";
  EXPECT_GT(blocked, traced / 20);
  EXPECT_GT(lit, traced / 20);
  EXPECT_LE(differ, want.size() / 1000);
  EXPECT_LE(far, want.size() / 1000);
  // A view drawn anew (not the queued one) has no answers to hand out.
  pass.render(gpu_rt, camera, sample, 0.01f, hits, found);
  EXPECT_FALSE(pass.take_shadows(request, got));
  EXPECT_EQ(ctx->validation_errors(), 0);
}

INSTANTIATE_TEST_SUITE_P(Traversals, VisibilityPassTest, testing::Values(Traversal::ComputeBvh, Traversal::RayQuery),
                         gpu_test::traversal_name);
