#include <gtest/gtest.h>

#include <glm/gtc/constants.hpp>

#include "engine/app/app.h"
#include "engine/transform/transform_plugin.h"

using namespace engine;
using namespace engine::transform;
using engine::ecs::Entity;

namespace {

constexpr float kTol = 1e-5f;

void expect_near(glm::vec3 expected, glm::vec3 got, const char* what) {
  EXPECT_NEAR(expected.x, got.x, kTol) << what;
  EXPECT_NEAR(expected.y, got.y, kTol) << what;
  EXPECT_NEAR(expected.z, got.z, kTol) << what;
}

// Counts, per frame, which entities a PrepareRender-phase observer saw as
// changed; that is what render-side mirrors (e.g. the Embree scene) rely on.
struct ChangedLog {
  std::vector<std::vector<std::uint32_t>> frames;
};

struct Fixture {
  app::App app{app::AppOptions{.jobs = {.threads = 2}}};
  Fixture() {
    app.add_plugin<TransformPlugin>();
    app.world().insert_resource<ChangedLog>();
    app.add_system(schedule::Phase::PrepareRender, "observe",
                   [](schedule::View<schedule::Get<const WorldTransform>> v, schedule::ResMut<ChangedLog> log) {
                     std::vector<std::uint32_t> changed;
                     v.each([&](Entity e, const WorldTransform&) {
                       if (v.is_changed<WorldTransform>(e)) changed.push_back(e.index);
                     });
                     std::sort(changed.begin(), changed.end());
                     log->frames.push_back(changed);
                   });
  }
  ecs::World& w() { return app.world(); }
  const std::vector<std::uint32_t>& last_changed() { return w().resource<ChangedLog>().frames.back(); }
};

}  // namespace

TEST(Similarity, ComposeMatchesMatrixProductAndInverseUndoes) {
  Similarity a;
  a.translation = {1, 2, 3};
  a.rotation = glm::angleAxis(0.7f, glm::normalize(glm::vec3(1, 2, 0.5f)));
  a.scale = 2.0f;
  Similarity b;
  b.translation = {-0.5f, 4, 1};
  b.rotation = glm::angleAxis(-1.1f, glm::vec3(0, 0, 1));
  b.scale = 0.25f;
  const glm::vec3 p(0.3f, -0.2f, 0.9f);
  const glm::vec4 via_matrix = a.matrix() * b.matrix() * glm::vec4(p, 1.0f);
  expect_near(glm::vec3(via_matrix), (a * b).apply_point(p), "composition");
  expect_near(p, (a.inverse() * a).apply_point(p), "inverse");
}

TEST(TransformPropagation, ChildFollowsParentThroughTheHierarchy) {
  Fixture f;
  const Entity root = f.w().spawn();
  const Entity child = f.w().spawn();
  const Entity grandchild = f.w().spawn();
  Transform rt = Transform::from_translation({10, 0, 0});
  rt.rotation = glm::angleAxis(glm::half_pi<float>(), glm::vec3(0, 1, 0));  // +x -> -z
  rt.scale = 2.0f;
  f.w().emplace<Transform>(root, rt);
  f.w().emplace<Transform>(child, Transform::from_translation({1, 0, 0}));
  f.w().emplace<Parent>(child, Parent{root});
  f.w().emplace<Transform>(grandchild, Transform::from_translation({0, 1, 0}));
  f.w().emplace<Parent>(grandchild, Parent{child});
  f.app.update();

  expect_near({10, 0, 0}, f.w().get<WorldTransform>(root).translation, "root");
  expect_near({10, 0, -2}, f.w().get<WorldTransform>(child).translation, "child: rotated, scaled offset");
  expect_near({10, 2, -2}, f.w().get<WorldTransform>(grandchild).translation, "grandchild");
  EXPECT_FLOAT_EQ(f.w().get<WorldTransform>(grandchild).scale, 2.0f);
  EXPECT_EQ(f.last_changed().size(), 3u) << "all three are new";

  // Moving the root moves both descendants.
  f.w().get_mut<Transform>(root).translation = {0, 0, 0};
  f.app.update();
  expect_near({0, 2, -2}, f.w().get<WorldTransform>(grandchild).translation, "grandchild after root moved");
  EXPECT_EQ(f.last_changed(), (std::vector<std::uint32_t>{root.index, child.index, grandchild.index}));
}

TEST(TransformPropagation, ChangeFlagsFireOnlyWhereTheWorldTransformChanged) {
  Fixture f;
  const Entity root = f.w().spawn();
  const Entity a = f.w().spawn();
  const Entity b = f.w().spawn();
  const Entity unrelated = f.w().spawn();
  f.w().emplace<Transform>(root);
  f.w().emplace<Transform>(a, Transform::from_translation({1, 0, 0}));
  f.w().emplace<Parent>(a, Parent{root});
  f.w().emplace<Transform>(b, Transform::from_translation({0, 1, 0}));
  f.w().emplace<Parent>(b, Parent{a});
  f.w().emplace<Transform>(unrelated, Transform::from_translation({5, 5, 5}));
  f.app.update();

  f.app.update();
  EXPECT_TRUE(f.last_changed().empty()) << "nothing moved, nothing may be flagged";

  // Moving the middle entity flags it and its child, not the root or others.
  f.w().get_mut<Transform>(a).translation = {2, 0, 0};
  f.app.update();
  EXPECT_EQ(f.last_changed(), (std::vector<std::uint32_t>{a.index, b.index}));

  // Touching a Transform mutably without changing its value flags nothing.
  (void)f.w().get_mut<Transform>(root);
  f.app.update();
  EXPECT_TRUE(f.last_changed().empty());
  EXPECT_EQ(f.w().resource<TransformStats>().visited, 1u) << "only the touched root was recomputed";
}

TEST(TransformPropagation, ReparentingAndUnparenting) {
  Fixture f;
  const Entity p1 = f.w().spawn();
  const Entity p2 = f.w().spawn();
  const Entity c = f.w().spawn();
  f.w().emplace<Transform>(p1, Transform::from_translation({1, 0, 0}));
  f.w().emplace<Transform>(p2, Transform::from_translation({0, 0, 7}));
  f.w().emplace<Transform>(c, Transform::from_translation({0, 1, 0}));
  f.w().emplace<Parent>(c, Parent{p1});
  f.app.update();
  expect_near({1, 1, 0}, f.w().get<WorldTransform>(c).translation, "under p1");

  f.w().get_mut<Parent>(c).entity = p2;
  f.app.update();
  expect_near({0, 1, 7}, f.w().get<WorldTransform>(c).translation, "under p2");

  f.w().remove<Parent>(c);
  f.app.update();
  expect_near({0, 1, 0}, f.w().get<WorldTransform>(c).translation, "unparented");

  // A despawned parent turns its child into a root.
  f.w().emplace<Parent>(c, Parent{p1});
  f.app.update();
  f.w().despawn(p1);
  f.app.update();
  expect_near({0, 1, 0}, f.w().get<WorldTransform>(c).translation, "parent despawned");
}

TEST(TransformPropagation, ParentCycleIsReportedNotLooped) {
  Fixture f;
  const Entity a = f.w().spawn();
  const Entity b = f.w().spawn();
  f.w().emplace<Transform>(a);
  f.w().emplace<Transform>(b);
  f.w().emplace<Parent>(a, Parent{b});
  f.w().emplace<Parent>(b, Parent{a});
  f.app.update();
  EXPECT_EQ(f.w().resource<TransformStats>().unreachable, 2u);
}

// engine::app::Time::paused: systems still run, but see no time pass.
TEST(AppTime, APausedFrameRunsItsSystemsWithNoTimePassing) {
  app::App app;
  std::vector<double> seen;
  app.add_system(schedule::Phase::Update, "test::record_dt",
                 [&seen](ecs::World& w) { seen.push_back(w.resource<app::Time>().delta_seconds); });
  app.update();
  auto& time = app.world().resource<app::Time>();
  const double step = time.delta_seconds, before = time.elapsed_seconds;
  time.paused = true;
  app.update();
  app.update();
  EXPECT_EQ(time.elapsed_seconds, before) << "paused: the clock stands";
  EXPECT_EQ(time.delta_seconds, step) << "the step comes back after each paused frame";
  time.paused = false;
  app.update();
  ASSERT_EQ(seen.size(), 4u);
  EXPECT_EQ(seen[0], step);
  EXPECT_EQ(seen[1], 0.0);
  EXPECT_EQ(seen[2], 0.0);
  EXPECT_EQ(seen[3], step);
  EXPECT_EQ(time.elapsed_seconds, before + step);
  EXPECT_EQ(time.frame, 4u) << "frames still count";
}
