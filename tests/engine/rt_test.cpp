#include <gtest/gtest.h>

#include <limits>

#include "engine/app/app.h"
#include "engine/math/rng.h"
#include "engine/rt/rt_plugin.h"
#include "engine/scene/components.h"
#include "engine/scene/scene_assets.h"

using namespace engine;
using namespace engine::rt;
using engine::ecs::Entity;

namespace {

// A unit square in the XY plane at z = 0, facing +Z; material 0 opaque, 1 masked.
scene::SceneAssets quad_assets(bool masked) {
  scene::SceneAssets a;
  a.generation = scene::next_scene_generation();
  auto m = std::make_shared<scene::MeshAsset>();
  m->name = "quad";
  m->positions = {{-0.5f, -0.5f, 0}, {0.5f, -0.5f, 0}, {0.5f, 0.5f, 0}, {-0.5f, 0.5f, 0}};
  m->normals.assign(4, {0, 0, 1});
  m->uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  m->triangles = {{0, 1, 2}, {0, 2, 3}};
  m->triangle_material = {masked ? 1u : 0u, masked ? 1u : 0u};
  m->compute_bounds();
  a.meshes.push_back(m);
  a.materials.resize(2);
  a.materials[1].alpha_mode = material::AlphaMode::Mask;
  a.materials[1].base_color_texture = 0;
  // 2x1 texture: left half transparent, right half opaque.
  scene::Texture t;
  t.width = 2;
  t.height = 1;
  t.rgba = {255, 255, 255, 0, 255, 255, 255, 255};
  t.wrap_s = t.wrap_t = scene::Wrap::ClampToEdge;
  a.textures.push_back(t);
  return a;
}

struct RtFixture {
  app::App app{app::AppOptions{.jobs = {.threads = 2}}};
  explicit RtFixture(bool masked = false) {
    app.world().insert_resource<scene::SceneAssets>(quad_assets(masked));
    app.add_plugin<RtPlugin>();
  }
  Entity spawn_quad(glm::vec3 at) {
    const Entity e = app.world().spawn();
    app.world().emplace<transform::Transform>(e, transform::Transform::from_translation(at));
    app.world().emplace<scene::MeshInstance>(e, scene::MeshInstance{0});
    return e;
  }
  const RtScene& rt() { return app.world().resource<RtScene>(); }
  // A ray down -Z through (x, y) from z = 10.
  bool hits(float x, float y, Hit* out = nullptr) {
    Hit h;
    const bool hit = rt().intersect(Ray{{x, y, 10}, {0, 0, -1}}, h);
    if (out) *out = h;
    return hit;
  }
};

}  // namespace

TEST(RtScene, MovedEntityIsHitAtTheNewPlaceAndNotTheOld) {
  RtFixture f;
  const Entity e = f.spawn_quad({0, 0, 0});
  f.app.update();
  Hit h;
  ASSERT_TRUE(f.hits(0.1f, 0.2f, &h));
  EXPECT_EQ(h.entity, e);
  EXPECT_EQ(h.mesh, 0u);
  EXPECT_NEAR(h.t, 10.0f, 1e-5f);
  // Barycentrics reproduce the hit point on the hit triangle.
  const auto& m = *f.app.world().resource<scene::SceneAssets>().meshes[0];
  const glm::uvec3 tri = m.triangles[h.primitive];
  const glm::vec3 p = (1 - h.barycentric.x - h.barycentric.y) * m.positions[tri.x] +
                      h.barycentric.x * m.positions[tri.y] + h.barycentric.y * m.positions[tri.z];
  EXPECT_NEAR(p.x, 0.1f, 1e-5f);
  EXPECT_NEAR(p.y, 0.2f, 1e-5f);

  f.app.world().get_mut<transform::Transform>(e).translation = {5, 0, 2};
  f.app.update();
  EXPECT_FALSE(f.hits(0.1f, 0.2f)) << "the old place must be empty after the move";
  ASSERT_TRUE(f.hits(5.1f, 0.2f, &h)) << "the new place must be hit";
  EXPECT_EQ(h.entity, e);
  EXPECT_NEAR(h.t, 8.0f, 1e-5f);
  EXPECT_EQ(f.rt().stats().blas_builds, 1u) << "moving must not rebuild the mesh";
  EXPECT_EQ(f.rt().stats().instances_moved, 1u);
}

TEST(RtScene, RotationAndScaleAreApplied) {
  RtFixture f;
  const Entity e = f.spawn_quad({0, 0, 0});
  auto& t = f.app.world().get_mut<transform::Transform>(e);
  t.scale = 4.0f;  // now spans [-2, 2]
  f.app.update();
  EXPECT_TRUE(f.hits(1.9f, 0.0f));
  f.app.world().get_mut<transform::Transform>(e).rotation = glm::angleAxis(glm::radians(90.0f), glm::vec3(0, 1, 0));
  f.app.update();
  EXPECT_FALSE(f.hits(1.9f, 0.0f)) << "rotated edge-on about Y, the quad no longer covers x = 1.9";
}

TEST(RtScene, StaticFramesCommitNothing) {
  RtFixture f;
  f.spawn_quad({0, 0, 0});
  f.app.update();
  const std::size_t commits = f.rt().stats().top_level_commits;
  f.app.update();
  f.app.update();
  EXPECT_EQ(f.rt().stats().top_level_commits, commits);
}

TEST(RtScene, DespawnedEntityDisappears) {
  RtFixture f;
  const Entity e = f.spawn_quad({0, 0, 0});
  f.app.update();
  ASSERT_TRUE(f.hits(0, 0));
  f.app.world().despawn(e);
  f.app.update();
  EXPECT_FALSE(f.hits(0, 0));
  EXPECT_EQ(f.rt().stats().instances_removed, 1u);
}

TEST(RtScene, AlphaMaskIsTestedInTheFilter) {
  RtFixture f(/*masked=*/true);
  f.spawn_quad({0, 0, 0});
  f.app.update();
  EXPECT_FALSE(f.hits(-0.25f, 0.0f)) << "left half has alpha 0";
  EXPECT_TRUE(f.hits(0.25f, 0.0f)) << "right half has alpha 1";
  EXPECT_FALSE(f.rt().occluded(Ray{{-0.25f, 0, 10}, {0, 0, -1}}));
  EXPECT_TRUE(f.rt().occluded(Ray{{0.25f, 0, 10}, {0, 0, -1}}));
}

TEST(RtScene, NonFiniteRaysAreRejectedAndCounted) {
  RtFixture f;
  f.spawn_quad({0, 0, 0});
  f.app.update();
  Hit h;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  EXPECT_FALSE(f.rt().intersect(Ray{{nan, 0, 10}, {0, 0, -1}}, h));
  EXPECT_FALSE(f.rt().occluded(Ray{{0, 0, 10}, {0, std::numeric_limits<float>::infinity(), -1}}));
  EXPECT_FALSE(f.rt().intersect(Ray{{0, 0, 10}, {0, 0, 0}}, h));
  EXPECT_EQ(f.rt().rejected_rays(), 3u);
}

TEST(RtScene, OffsetOriginEscapesTheSurface) {
  RtFixture f;
  f.spawn_quad({0, 0, 1000.0f});  // far from the origin, where a fixed epsilon would fail
  f.app.update();
  const glm::vec3 p(0.1f, 0.1f, 1000.0f);
  const glm::vec3 o = offset_ray_origin(p, {0, 0, 1});
  Hit h;
  EXPECT_FALSE(f.rt().intersect(Ray{o, {0.3f, 0.1f, 1.0f}}, h)) << "a ray leaving the surface must not re-hit it";
  EXPECT_GT(o.z, p.z);
}

TEST(RtScene, PacketsAnswerAsSingleRays) {
  // The 16-wide queries (incoherent and coherent traversal) are fast paths;
  // the single-ray queries are their reference. Rays of every kind: hits on two quads (one masked half), misses,
  // short tmax, a NaN ray and a short last packet.
  RtFixture f(/*masked=*/true);
  const Entity a = f.spawn_quad({0, 0, 0});
  const Entity b = f.spawn_quad({0.3f, 0.1f, -1.0f});
  f.app.world().get_mut<scene::MeshInstance>(b).mesh = 0;
  f.app.update();
  math::Pcg32 rng(3, 9);
  std::vector<Ray> rays;
  for (int i = 0; i < 16 * 20 + 5; ++i) {
    Ray r{{rng.next_float() * 2 - 1, rng.next_float() * 2 - 1, 3}, {0.2f * (rng.next_float() - 0.5f), 0.2f * (rng.next_float() - 0.5f), -1}};
    if (i % 7 == 0) r.tmax = 3.5f;  // stops between the quads
    if (i == 37) r.origin.x = std::numeric_limits<float>::quiet_NaN();
    rays.push_back(r);
  }
  int hits = 0, blocked_count = 0;
  for (std::size_t p = 0; p < rays.size(); p += 16) {
    const int n = static_cast<int>(std::min<std::size_t>(16, rays.size() - p));
    Hit packet[16], coherent[16];
    bool found[16], found_coherent[16], blocked[16];
    f.rt().intersect16(rays.data() + p, n, packet, found);
    f.rt().intersect16_coherent(rays.data() + p, n, coherent, found_coherent);
    f.rt().occluded16(rays.data() + p, n, blocked);
    for (int i = 0; i < n; ++i) {
      Hit single;
      const bool want = f.rt().intersect(rays[p + i], single);
      ASSERT_EQ(found[i], want) << "ray " << p + i;
      ASSERT_EQ(found_coherent[i], want) << "ray " << p + i << ", coherent";
      EXPECT_EQ(blocked[i], f.rt().occluded(rays[p + i])) << "ray " << p + i;
      if (!want) continue;
      ++hits;
      blocked_count += blocked[i];
      EXPECT_EQ(packet[i].entity, single.entity) << "ray " << p + i;
      EXPECT_EQ(packet[i].primitive, single.primitive) << "ray " << p + i;
      EXPECT_NEAR(packet[i].t, single.t, 1e-5f * single.t) << "ray " << p + i;
      EXPECT_NEAR(packet[i].barycentric.x, single.barycentric.x, 1e-5f) << "ray " << p + i;
      EXPECT_EQ(coherent[i].entity, single.entity) << "ray " << p + i << ", coherent";
      EXPECT_EQ(coherent[i].primitive, single.primitive) << "ray " << p + i << ", coherent";
      EXPECT_NEAR(coherent[i].t, single.t, 1e-5f * single.t) << "ray " << p + i << ", coherent";
      EXPECT_NEAR(coherent[i].barycentric.x, single.barycentric.x, 1e-5f) << "ray " << p + i << ", coherent";
    }
  }
  EXPECT_GT(hits, 50) << "the rays must exercise hits";
  EXPECT_GT(static_cast<int>(rays.size()) - hits, 50) << "and misses";
  EXPECT_EQ(f.rt().rejected_rays(), 5u) << "the NaN ray, counted by each of the five queries";
  (void)a;
}

TEST(RtScene, ReportsWhereTheLastCommitChangedTheGeometry) {
  RtFixture f;
  const Entity a = f.spawn_quad({0, 0, 0});
  f.app.update();
  // Added: the unit quad at the origin, flat in z.
  ASSERT_EQ(f.rt().changed_at_last_commit().size(), 1u);
  EXPECT_EQ(f.rt().changed_at_last_commit()[0].min, glm::vec3(-0.5f, -0.5f, 0.0f));
  EXPECT_EQ(f.rt().changed_at_last_commit()[0].max, glm::vec3(0.5f, 0.5f, 0.0f));
  // Moved by (3, 0, 1): old and new bounds merged.
  f.app.world().get_mut<transform::Transform>(a).translation = {3, 0, 1};
  f.app.update();
  ASSERT_EQ(f.rt().changed_at_last_commit().size(), 1u);
  EXPECT_EQ(f.rt().changed_at_last_commit()[0].min, glm::vec3(-0.5f, -0.5f, 0.0f));
  EXPECT_EQ(f.rt().changed_at_last_commit()[0].max, glm::vec3(3.5f, 0.5f, 1.0f));
  EXPECT_EQ(f.rt().instance_of(a)->bounds.min, glm::vec3(2.5f, -0.5f, 1.0f));
  // A static frame commits nothing: the list still describes the last commit.
  const std::size_t commits = f.rt().stats().top_level_commits;
  f.app.update();
  EXPECT_EQ(f.rt().stats().top_level_commits, commits);
  // Removed: its last bounds.
  f.app.world().despawn(a);
  f.app.update();
  ASSERT_EQ(f.rt().changed_at_last_commit().size(), 1u);
  EXPECT_EQ(f.rt().changed_at_last_commit()[0].max, glm::vec3(3.5f, 0.5f, 1.0f));
  EXPECT_EQ(f.rt().changed_at_last_commit()[0].min, glm::vec3(2.5f, -0.5f, 1.0f));
}

TEST(RtScene, AQueryBeforeTheFirstCommitMissesAndLeavesNoError) {
  scene::SceneAssets assets = quad_assets(false);
  RtScene rt;
  rt.set_assets(&assets);
  Ray r;
  r.origin = {0, 0, 1};
  r.direction = {0, 0, -1};
  Hit h;
  EXPECT_FALSE(rt.intersect(r, h));
  EXPECT_FALSE(rt.occluded(r));
  rt.upsert_instance(Entity{0, 0}, 0, transform::Similarity{});  // threw "scene not committed" before the fix
  rt.commit();
  EXPECT_TRUE(rt.intersect(r, h));
  EXPECT_NEAR(h.t, 1.0f, 1e-6f);
}
