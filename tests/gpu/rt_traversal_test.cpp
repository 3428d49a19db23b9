// shaders/rt_traversal.glsl against Embree (RtScene) on the same scene:
// 10,000 random rays and 2,000 rays that start on surfaces, as the renderer
// spawns them (offset_ray_origin). Every GpuRtTraversal test runs twice:
// through the compute-shader BVH and through VK_KHR_ray_query (skipped, with
// the reason, where the device has no ray queries: Debian 12's lavapipe 22.3;
// setup-deps installs Mesa 25 from bookworm-backports, whose lavapipe has them).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include <glm/gtc/quaternion.hpp>

#include "engine/gpu/gpu_error.h"
#include "engine/gpu/gpu_rt_scene.h"
#include "engine/math/rng.h"
#include "engine/rt/bvh_builder.h"
#include "engine/scene/procedural.h"
#include "gpu_fixture.h"
#include "rt_world.h"

using namespace engine;
using gpu_test::build_world;
using gpu_test::RtWorld;
using gpu_test::Traversal;
using gpu_test::traversal_context;
using gpu_test::traversal_name;

namespace {

glm::vec3 point_in_room(math::Pcg32& rng) {
  return glm::vec3(9.6f * rng.next_float() - 4.8f, 5.6f * rng.next_float() - 2.8f, 7.6f * rng.next_float() - 3.8f);
}

glm::vec3 random_direction(math::Pcg32& rng) {
  const float z = 2.0f * rng.next_float() - 1.0f, phi = 6.2831853f * rng.next_float();
  const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
  return {r * std::cos(phi), r * std::sin(phi), z};
}

class GpuRtTraversal : public testing::TestWithParam<Traversal> {};

}  // namespace

#define TRAVERSAL_CONTEXT_OR_SKIP(name, staging)                                            \
  std::string traversal_why_;                                                               \
  engine::gpu::VulkanContext* name = traversal_context(GetParam(), staging, &traversal_why_); \
  if (!name) GTEST_SKIP() << traversal_why_;                                                \
  ASSERT_EQ(name->info().ray_query, GetParam() == Traversal::RayQuery)

TEST(BvhBuilder, EveryItemLandsInExactlyOneLeafInsideItsAncestorsBoxes) {
  math::Pcg32 rng(4, 4);
  std::vector<rt::BvhBox> boxes(1000);
  for (auto& b : boxes) {
    const glm::vec3 c(rng.next_float() * 10, rng.next_float() * 10, rng.next_float());
    b = {c - 0.05f, c + glm::vec3(0.05f, 0.2f * rng.next_float(), 0.05f)};
  }
  boxes[10] = {glm::vec3(NAN), glm::vec3(NAN)};
  const rt::Bvh bvh = rt::build_bvh(boxes, 4);
  std::vector<int> seen(boxes.size(), 0);
  std::vector<std::pair<std::uint32_t, rt::BvhBox>> stack = {{0u, bvh.nodes[0].bounds}};
  while (!stack.empty()) {
    const auto [at, parent] = stack.back();
    stack.pop_back();
    const rt::BvhNode& n = bvh.nodes[at];
    EXPECT_TRUE(glm::all(glm::greaterThanEqual(n.bounds.min, parent.min)) && glm::all(glm::lessThanEqual(n.bounds.max, parent.max)))
        << "node " << at << " sticks out of its parent";
    if (n.count == 0) {
      stack.push_back({n.first, n.bounds});
      stack.push_back({n.first + 1, n.bounds});
      continue;
    }
    EXPECT_LE(n.count, 4u);
    for (std::uint32_t k = 0; k < n.count; ++k) {
      const std::uint32_t item = bvh.order[n.first + k];
      ++seen[item];
      EXPECT_TRUE(glm::all(glm::greaterThanEqual(boxes[item].min, n.bounds.min)) && glm::all(glm::lessThanEqual(boxes[item].max, n.bounds.max)));
    }
  }
  for (std::size_t i = 0; i < boxes.size(); ++i) EXPECT_EQ(seen[i], i == 10 ? 0 : 1) << "item " << i;
  EXPECT_EQ(bvh.order.back(), 10u) << "the non-finite item is listed last, outside every leaf";
}

// Hits must agree with Embree: the same instance and primitive, t to 1e-4
// relative (plus the coordinates' rounding, below), barycentrics to 1e-3. Moeller-Trumbore and Embree's test round
// differently, so a ray through a shared edge or a vertex may pick the
// other triangle, and a ray grazing a silhouette may hit in one and miss in
// the other: at most 0.2 % of the rays may disagree (measured: see output).
TEST_P(GpuRtTraversal, FindsTheSameClosestHitsAsEmbree) {
  TRAVERSAL_CONTEXT_OR_SKIP(ctx, false);
  RtWorld w;
  build_world(w);
  math::Pcg32 rng(12, 5);
  std::vector<rt::Ray> rays;
  for (int i = 0; i < 10000; ++i) {
    rt::Ray r;
    r.origin = point_in_room(rng);
    r.direction = random_direction(rng) * (0.5f + rng.next_float());  // not unit: t is in its units
    if (i % 10 == 0) r.tmax = 2.0f * rng.next_float();                  // short rays end before some hits
    rays.push_back(r);
  }
  // Rays leaving a surface: a random point of a random instance's random
  // triangle, offset along the geometric normal to the side it leaves by.
  for (int i = 0; i < 2000; ++i) {
    const std::uint32_t inst = 1 + rng.next_u32() % 12;
    const scene::MeshAsset& m = *w.assets.meshes[w.mesh_of[inst]];
    const glm::uvec3 tri = m.triangles[rng.next_u32() % m.triangles.size()];
    float a = rng.next_float(), b = rng.next_float();
    if (a + b > 1) a = 1 - a, b = 1 - b;
    const glm::vec3 p0 = w.xf[inst].apply_point(m.positions[tri.x]), p1 = w.xf[inst].apply_point(m.positions[tri.y]),
                    p2 = w.xf[inst].apply_point(m.positions[tri.z]);
    const glm::vec3 p = p0 + a * (p1 - p0) + b * (p2 - p0);
    glm::vec3 n = glm::normalize(glm::cross(p1 - p0, p2 - p0));
    glm::vec3 d = random_direction(rng);
    if (glm::dot(d, n) < 0) n = -n;
    rt::Ray r;
    r.origin = rt::offset_ray_origin(p, n, w.rt.offset_scale());
    r.direction = d;
    rays.push_back(r);
  }
  std::vector<rt::Hit> want(rays.size()), got(rays.size());
  std::vector<bool> want_found(rays.size());
  std::vector<std::uint8_t> got_found(rays.size());
  for (std::size_t i = 0; i < rays.size(); ++i) {
    rt::Hit h;
    want_found[i] = w.rt.intersect(rays[i], h);
    want[i] = h;
  }
  gpu::GpuRtScene gpu_rt(*ctx);
  gpu_rt.sync(w.rt);
  EXPECT_EQ(gpu_rt.stats().ray_query, GetParam() == Traversal::RayQuery);
  double ms = 0;
  gpu_rt.intersect(rays, got, got_found, &ms);

  std::size_t hits = 0, disagree = 0, bad = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    hits += want_found[i];
    if (want_found[i] != (got_found[i] != 0) || (want_found[i] && (want[i].instance != got[i].instance || want[i].primitive != got[i].primitive))) {
      ++disagree;
      continue;
    }
    if (!want_found[i]) continue;
    // 1e-4 of t, plus an absolute part: both intersectors get t from edge
    // vectors rounded at the scale of the coordinates (a few metres here,
    // 2^-22 of which is 1e-6), so for a hit a millimetre from a ray's origin
    // on a surface the absolute rounding dominates (measured 7e-7).
    const float tol_t = 1e-4f * want[i].t + 1e-5f * std::max(1.0f, glm::length(rays[i].origin));
    if ((!(std::abs(want[i].t - got[i].t) <= tol_t) || !(glm::all(glm::lessThanEqual(glm::abs(want[i].barycentric - got[i].barycentric), glm::vec2(1e-3f))))) &&
        bad++ < 5)
      ADD_FAILURE() << "ray " << i << ": expected t " << want[i].t << " uv (" << want[i].barycentric.x << ", "
                    << want[i].barycentric.y << "), got t " << got[i].t << " uv (" << got[i].barycentric.x << ", "
                    << got[i].barycentric.y << ")";
  }
  std::printf("rt (%s): %zu rays, %zu hits, %zu disagree (%.3f %%); BLAS %zu nodes over %zu triangles, TLAS %zu nodes over %zu instances; %.1f ms on %s\n",
              ctx->info().ray_query ? "ray query" : "compute BVH", rays.size(), hits, disagree, 100.0 * static_cast<double>(disagree) / static_cast<double>(rays.size()),
              gpu_rt.stats().blas_nodes, gpu_rt.stats().triangles, gpu_rt.stats().tlas_nodes, gpu_rt.stats().instances, ms,
              ctx->info().name.c_str());
  EXPECT_EQ(bad, 0u);
  EXPECT_LE(disagree, rays.size() / 500);
  EXPECT_GT(hits, rays.size() * 8 / 10) << "most rays should hit in a closed room";
  EXPECT_EQ(ctx->validation_errors(), 0);
}

// Shadow rays stop at their first hit: the same answers as Embree's
// occluded() on 10,000 rays of random lengths, a third of them ending just
// before or after a surface.
TEST_P(GpuRtTraversal, AnyHitShadowRaysGiveEmbreesOccludedAnswers) {
  TRAVERSAL_CONTEXT_OR_SKIP(ctx, false);
  RtWorld w;
  build_world(w);
  math::Pcg32 rng(21, 2);
  std::vector<rt::Ray> rays;
  for (int i = 0; i < 10000; ++i) {
    rt::Ray r;
    r.origin = point_in_room(rng);
    r.direction = random_direction(rng);
    rt::Hit h;
    const bool hit = w.rt.intersect(r, h);
    // Ends 1 % short of or past the closest hit (or anywhere when it escapes).
    r.tmax = hit && i % 3 == 0 ? h.t * (i % 2 ? 0.99f : 1.01f) : 8.0f * rng.next_float();
    rays.push_back(r);
  }
  gpu::GpuRtScene gpu_rt(*ctx);
  gpu_rt.sync(w.rt);
  std::vector<std::uint8_t> blocked(rays.size());
  gpu_rt.occluded(rays, blocked);
  std::size_t n_blocked = 0, disagree = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const bool want = w.rt.occluded(rays[i]);
    n_blocked += want;
    if (want != (blocked[i] != 0) && disagree++ < 5) ADD_FAILURE() << "ray " << i << ": Embree says " << want;
  }
  std::printf("occluded (%s): %zu rays, %zu blocked, %zu disagree\n", ctx->info().ray_query ? "ray query" : "compute BVH",
              rays.size(), n_blocked, disagree);
  EXPECT_LE(disagree, rays.size() / 500);
  EXPECT_GT(n_blocked, rays.size() / 4);
  EXPECT_LT(n_blocked, rays.size() * 3 / 4);
  EXPECT_EQ(ctx->validation_errors(), 0);
}

// A later batch (occluded_later) gives occluded()'s answers, and rides with
// the device's next submission: a moved instance's TLAS rebuild, the batch
// and the next query cost one submission in all (issue 36: the frame's
// submissions), and the query sees the move.
TEST_P(GpuRtTraversal, ALaterShadowBatchAndATlasRebuildRideWithTheNextSubmission) {
  TRAVERSAL_CONTEXT_OR_SKIP(ctx, false);
  RtWorld w;
  build_world(w);
  math::Pcg32 rng(23, 5);
  std::vector<rt::Ray> rays;
  for (int i = 0; i < 4000; ++i) rays.push_back(rt::Ray{point_in_room(rng), random_direction(rng), 0.0f, 8.0f * rng.next_float()});
  gpu::GpuRtScene gpu_rt(*ctx);
  gpu_rt.sync(w.rt);
  std::vector<std::uint8_t> now(rays.size()), later(rays.size());
  gpu_rt.occluded(rays, now);
  // The sphere to the back wall, then the batch queued after the move.
  transform::Similarity s;
  s.translation = glm::vec3(0.0f, 0.0f, -3.5f);
  w.rt.upsert_instance(ecs::Entity{1, 0}, 1, s);
  w.rt.commit();
  const std::uint64_t before = ctx->traffic().submissions;
  gpu_rt.sync(w.rt);
  gpu_rt.occluded_later(rays);
  EXPECT_EQ(ctx->traffic().submissions, before) << "a TLAS rebuild and a later batch submit nothing by themselves";
  // Another stage's submission (the probe rays' in a frame) carries both.
  ctx->submit_and_wait([](VkCommandBuffer) {});
  EXPECT_EQ(ctx->traffic().submissions - before, 1u);
  gpu_rt.take_occluded(later);
  EXPECT_EQ(ctx->traffic().submissions - before, 1u) << "the answers came with that submission";
  const std::vector<rt::Ray> probe = {rt::Ray{glm::vec3(0.0f), glm::vec3(0.0f, 0.0f, -1.0f)}};
  std::vector<rt::Hit> h(1);
  std::vector<std::uint8_t> found(1, 0);
  gpu_rt.intersect(probe, h, found);
  // Answers against the moved scene, from Embree.
  std::size_t disagree = 0, n_blocked = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const bool want = w.rt.occluded(rays[i]);
    n_blocked += want;
    if (want != (later[i] != 0) && disagree++ < 5) ADD_FAILURE() << "ray " << i << ": Embree says " << want;
  }
  EXPECT_LE(disagree, rays.size() / 500);
  EXPECT_GT(n_blocked, rays.size() / 10);
  rt::Hit want;
  ASSERT_TRUE(w.rt.intersect(probe[0], want));
  ASSERT_TRUE(found[0]);
  EXPECT_EQ(h[0].instance, want.instance) << "the query traced the rebuilt TLAS";
  EXPECT_NEAR(h[0].t, want.t, 1e-4f * want.t);
  EXPECT_EQ(ctx->traffic().submissions - before, 2u);

  // Queued, then an immediate query: the batch rides with the query's
  // submission (it has a kernel of its own); so does a batch of closest-hit
  // distances queued beside it; queued with no submission after it:
  // take_occluded submits it. The answers are occluded()'s and intersect()'s
  // either way, 4 bytes a ray back.
  std::vector<std::uint8_t> again(rays.size()), alone(rays.size());
  gpu_rt.occluded(rays, now);
  std::vector<rt::Hit> nearest(rays.size());
  std::vector<std::uint8_t> hit(rays.size());
  std::vector<float> distance(rays.size());
  gpu_rt.intersect(rays, nearest, hit);
  std::uint64_t at = ctx->traffic().submissions;
  const std::uint64_t back = ctx->traffic().device_to_host_bytes;
  gpu_rt.occluded_later(rays);
  gpu_rt.distances_later(rays);
  gpu_rt.intersect(probe, h, found);
  EXPECT_EQ(ctx->traffic().submissions - at, 1u) << "both batches rode with the query";
  gpu_rt.take_occluded(again);
  gpu_rt.take_distances(distance);
  EXPECT_EQ(ctx->traffic().submissions - at, 1u);
  EXPECT_LE(ctx->traffic().device_to_host_bytes - back, 2 * 4 * rays.size() + sizeof(engine::gpu::HitGpu))
      << "a queued batch brings back more than a distance a ray";
  EXPECT_EQ(again, now);
  for (std::size_t i = 0; i < rays.size(); ++i) {
    if (hit[i]) EXPECT_EQ(distance[i], nearest[i].t) << "ray " << i;
    else EXPECT_TRUE(std::isinf(distance[i])) << "ray " << i;
  }
  at = ctx->traffic().submissions;
  gpu_rt.occluded_later(rays);
  gpu_rt.take_occluded(alone);
  EXPECT_EQ(ctx->traffic().submissions - at, 1u);
  EXPECT_EQ(alone, now);
  EXPECT_THROW(gpu_rt.take_occluded(again), engine::gpu::GpuError) << "nothing queued";
  EXPECT_EQ(ctx->validation_errors(), 0);
}

// Moving an instance needs only a sync (no BLAS rebuild), and the hits follow.
namespace {

void expect_a_moved_instance_found_where_it_moved(engine::gpu::VulkanContext* ctx) {
  RtWorld w;
  build_world(w);
  gpu::GpuRtScene gpu_rt(*ctx);
  gpu_rt.sync(w.rt);
  transform::Similarity s;
  s.translation = glm::vec3(0.0f, 0.0f, -3.5f);
  w.rt.upsert_instance(ecs::Entity{1, 0}, 1, s);  // the sphere, to the back wall
  w.rt.commit();
  gpu_rt.sync(w.rt);
  EXPECT_EQ(gpu_rt.stats().blas_builds, w.assets.meshes.size()) << "a move must not rebuild a BLAS";
  EXPECT_EQ(gpu_rt.stats().instances, 13u);
  const std::vector<rt::Ray> rays = {rt::Ray{glm::vec3(0.0f, 0.0f, 0.0f), glm::vec3(0.0f, 0.0f, -1.0f)}};
  std::vector<rt::Hit> h(1);
  std::vector<std::uint8_t> found(1, 0);
  gpu_rt.intersect(rays, h, found);
  rt::Hit want;
  ASSERT_TRUE(w.rt.intersect(rays[0], want));
  ASSERT_TRUE(found[0]);
  EXPECT_EQ(h[0].instance, want.instance);
  EXPECT_EQ(h[0].entity, want.entity) << "a GPU hit names its entity as Embree's does";
  EXPECT_NEAR(h[0].t, want.t, 1e-4f * want.t) << "the sphere's front at z = -3.5 + 0.7";
}

}  // namespace

TEST_P(GpuRtTraversal, AMovedInstanceIsFoundWhereItMovedAfterASync) {
  TRAVERSAL_CONTEXT_OR_SKIP(ctx, false);
  expect_a_moved_instance_found_where_it_moved(ctx);
}

// The scene in device memory written through staging copies, as on a
// discrete GPU: the TLAS re-upload after the move must land too.
TEST_P(GpuRtTraversal, AMovedInstanceIsFoundThroughStagedDeviceBuffers) {
  TRAVERSAL_CONTEXT_OR_SKIP(ctx, true);
  expect_a_moved_instance_found_where_it_moved(ctx);
  EXPECT_EQ(ctx->validation_errors(), 0);
}

// Alpha-masked content (foliage, blinds, fences): a quad whose 8 x 8 texture
// cuts out a checker of holes, its UVs running to 3 so the texture repeats,
// and a second one mirrored, in front of a wall. Every ray must hit what
// Embree's alpha filter lets it hit.
TEST_P(GpuRtTraversal, AlphaMaskedTrianglesAreCutOutAsEmbreesFilterDoes) {
  TRAVERSAL_CONTEXT_OR_SKIP(ctx, false);
  scene::SceneAssets assets;
  assets.generation = scene::next_scene_generation();
  const scene::MeshAsset wall = gpu_test::wall_quad(), screen = gpu_test::screen_quad(1);
  scene::MeshAsset mirrored = screen;
  for (auto& m : mirrored.triangle_material) m = 2;
  assets.meshes = {std::make_shared<scene::MeshAsset>(wall), std::make_shared<scene::MeshAsset>(screen),
                   std::make_shared<scene::MeshAsset>(mirrored)};
  assets.materials.resize(3);
  for (int i : {1, 2}) {
    assets.materials[static_cast<std::size_t>(i)].alpha_mode = material::AlphaMode::Mask;
    assets.materials[static_cast<std::size_t>(i)].alpha_cutoff = 0.5f;
    assets.materials[static_cast<std::size_t>(i)].base_color_texture = i - 1;
  }
  for (int i = 0; i < 2; ++i) {
    scene::Texture t;
    t.width = t.height = 8;
    t.rgba.assign(8 * 8 * 4, 255);
    for (int y = 0; y < 8; ++y)
      for (int x = 0; x < 8; ++x) t.rgba[static_cast<std::size_t>(y * 8 + x) * 4 + 3] = (x + y) % 2 ? 0 : (x % 3 ? 255 : 120);
    t.wrap_s = i == 0 ? scene::Wrap::Repeat : scene::Wrap::MirroredRepeat;
    t.wrap_t = i == 0 ? scene::Wrap::Repeat : scene::Wrap::ClampToEdge;
    assets.textures.push_back(t);
  }
  rt::RtScene rt;
  rt.set_assets(&assets);
  transform::Similarity at_wall, at_screen, at_mirrored;
  // make_quad lies in the XZ plane: turned to face +Z, towards the rays.
  const glm::quat upright = glm::angleAxis(1.5707963f, glm::vec3(1.0f, 0.0f, 0.0f));
  at_wall.translation = glm::vec3(0.0f, 0.0f, -2.0f);
  at_wall.rotation = upright;
  at_screen.translation = glm::vec3(-1.0f, 0.0f, 0.0f);
  at_screen.rotation = upright;
  at_mirrored.translation = glm::vec3(1.5f, 0.5f, 0.5f);
  at_mirrored.rotation = glm::angleAxis(0.4f, glm::vec3(0.0f, 1.0f, 0.0f)) * upright;
  rt.upsert_instance(ecs::Entity{0, 0}, 0, at_wall);
  rt.upsert_instance(ecs::Entity{1, 0}, 1, at_screen);
  rt.upsert_instance(ecs::Entity{2, 0}, 2, at_mirrored);
  rt.commit();

  math::Pcg32 rng(6, 6);
  std::vector<rt::Ray> rays;
  for (int i = 0; i < 8000; ++i) {
    const glm::vec3 target(6.0f * rng.next_float() - 3.0f, 4.0f * rng.next_float() - 2.0f, 0.0f);
    const glm::vec3 origin(2.0f * rng.next_float() - 1.0f, 2.0f * rng.next_float() - 1.0f, 5.0f);
    rays.push_back(rt::Ray{origin, glm::normalize(target - origin)});
  }
  gpu::GpuRtScene gpu_rt(*ctx);
  gpu_rt.sync(rt);
  std::vector<rt::Hit> got(rays.size());
  std::vector<std::uint8_t> found(rays.size());
  gpu_rt.intersect(rays, got, found);
  // How far (in texels) a hit on a screen lies from the nearest texel edge
  // of its 8 x 8 texture: only there may the two tracers' barycentrics round
  // to different texels.
  auto texel_edge_distance = [&](const rt::Hit& h) {
    const scene::MeshAsset& m = *assets.meshes[h.mesh];
    const glm::uvec3 tri = m.triangles[h.primitive];
    const glm::vec2 uv = (1.0f - h.barycentric.x - h.barycentric.y) * m.uvs[tri.x] + h.barycentric.x * m.uvs[tri.y] +
                         h.barycentric.y * m.uvs[tri.z];
    const glm::vec2 f = uv * 8.0f;
    return std::min(std::abs(f.x - std::round(f.x)), std::abs(f.y - std::round(f.y)));
  };
  std::size_t through = 0, on_screens = 0, disagree = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    rt::Hit want;
    const bool hit = rt.intersect(rays[i], want);
    if (hit && want.instance == 0) ++through;  // reached the wall: a hole, or missed the screens
    if (hit && want.instance != 0) ++on_screens;
    if (hit != (found[i] != 0) || (hit && (want.instance != got[i].instance || want.primitive != got[i].primitive))) {
      ++disagree;
      const rt::Hit& on_screen = hit && want.instance != 0 ? want : got[i];
      const float edge = on_screen.instance != 0 ? texel_edge_distance(on_screen) : 1.0f;
      std::printf("alpha: ray %zu: Embree %s, GPU %s; %.2g texels from a texel edge\n", i,
                  hit ? ("hit instance " + std::to_string(want.instance)).c_str() : "missed",
                  found[i] ? ("hit instance " + std::to_string(got[i].instance)).c_str() : "missed", static_cast<double>(edge));
      EXPECT_LT(edge, 1e-3f) << "ray " << i << " disagrees away from a texel edge";
    }
  }
  std::printf("alpha (%s): %zu rays, %zu on the screens, %zu to the wall, %zu disagree\n",
              ctx->info().ray_query ? "ray query" : "compute BVH", rays.size(), on_screens, through, disagree);
  EXPECT_LE(disagree, rays.size() / 500) << "rays at a texel's edge may round either way";
  EXPECT_GT(on_screens, 1000u);
  EXPECT_GT(through, 1000u);
  EXPECT_EQ(ctx->validation_errors(), 0);
}

// Content no importer should let through, and a driver's builder would take
// as undefined: a mesh without triangles (its instances are inactive), a
// triangle with an infinite and one with a NaN corner (skipped, as Embree
// skips them), and rays with a NaN origin, a zero direction or an empty
// interval (no hit). Every other ray answers as Embree does.
TEST_P(GpuRtTraversal, DegenerateMeshesAndRaysAreSkippedAsEmbreeSkipsThem) {
  TRAVERSAL_CONTEXT_OR_SKIP(ctx, false);
  scene::SceneAssets assets;
  assets.generation = scene::next_scene_generation();
  scene::MeshAsset empty;
  empty.name = "empty";
  scene::MeshAsset wall = scene::make_quad({4.0f, 4.0f}, 0);
  const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
  // Two extra triangles in front of the wall, each with a corner off the map.
  const auto base = static_cast<std::uint32_t>(wall.positions.size());
  wall.positions.insert(wall.positions.end(), {glm::vec3(-1.0f, 1.0f, -1.0f), glm::vec3(1.0f, 1.0f, -1.0f), glm::vec3(0.0f, 1.0f, inf),
                                               glm::vec3(-1.0f, 1.0f, 1.0f), glm::vec3(1.0f, 1.0f, 1.0f), glm::vec3(nan, 1.0f, 0.0f)});
  wall.normals.resize(wall.positions.size(), glm::vec3(0.0f, 1.0f, 0.0f));
  wall.uvs.resize(wall.positions.size(), glm::vec2(0.0f));
  wall.triangles.push_back({base, base + 1, base + 2});
  wall.triangles.push_back({base + 3, base + 4, base + 5});
  wall.triangle_material.resize(wall.triangles.size(), 0);
  wall.compute_bounds();
  assets.meshes = {std::make_shared<scene::MeshAsset>(empty), std::make_shared<scene::MeshAsset>(wall)};
  assets.materials.resize(1);
  rt::RtScene rt;
  rt.set_assets(&assets);
  rt.upsert_instance(ecs::Entity{0, 0}, 0, transform::Similarity{});
  rt.upsert_instance(ecs::Entity{1, 0}, 1, transform::Similarity{});
  rt.commit();

  math::Pcg32 rng(3, 3);
  std::vector<rt::Ray> rays;
  for (int i = 0; i < 2000; ++i) {
    // Down onto the quad (make_quad lies in the XZ plane at y = 0), through
    // where the two broken triangles would be.
    rays.push_back(rt::Ray{glm::vec3(4.0f * rng.next_float() - 2.0f, 3.0f, 4.0f * rng.next_float() - 2.0f), glm::vec3(0.0f, -1.0f, 0.0f)});
  }
  rays.push_back(rt::Ray{glm::vec3(nan, 3.0f, 0.0f), glm::vec3(0.0f, -1.0f, 0.0f)});
  rays.push_back(rt::Ray{glm::vec3(0.0f, 3.0f, 0.0f), glm::vec3(0.0f)});
  rays.push_back(rt::Ray{glm::vec3(0.0f, 3.0f, 0.0f), glm::vec3(0.0f, -1.0f, 0.0f), 2.0f, 1.0f});
  const std::size_t broken = 3;
  gpu::GpuRtScene gpu_rt(*ctx);
  gpu_rt.sync(rt);
  std::vector<rt::Hit> got(rays.size());
  std::vector<std::uint8_t> found(rays.size());
  gpu_rt.intersect(rays, got, found);
  std::size_t disagree = 0, on_wall = 0;
  for (std::size_t i = 0; i + broken < rays.size(); ++i) {
    rt::Hit want;
    const bool hit = rt.intersect(rays[i], want);
    on_wall += hit;
    if (hit != (found[i] != 0) || (hit && (want.primitive != got[i].primitive || std::abs(want.t - got[i].t) > 1e-4f * want.t))) {
      if (disagree++ < 5)
        ADD_FAILURE() << "ray " << i << ": Embree " << (hit ? "hit primitive " + std::to_string(want.primitive) + " at t " + std::to_string(want.t) : std::string("missed"))
                      << ", GPU " << (found[i] ? "hit primitive " + std::to_string(got[i].primitive) + " at t " + std::to_string(got[i].t) : std::string("missed"));
    }
    EXPECT_LT(got[i].primitive, 2u) << "ray " << i << " hit a triangle with a corner off the map";
  }
  for (std::size_t i = rays.size() - broken; i < rays.size(); ++i) EXPECT_EQ(found[i], 0) << "broken ray " << i << " hit";
  EXPECT_GT(on_wall, 1000u);
  EXPECT_EQ(disagree, 0u);
  EXPECT_EQ(ctx->validation_errors(), 0);
}

INSTANTIATE_TEST_SUITE_P(Traversals, GpuRtTraversal, testing::Values(Traversal::ComputeBvh, Traversal::RayQuery),
                         traversal_name);
