#include <gtest/gtest.h>

#include <algorithm>
#include <set>

#include "engine/ecs/ecs.h"

using namespace engine::ecs;

namespace {
struct Position {
  float x = 0;
};
struct Velocity {
  float v = 0;
};
struct Frozen {};
}  // namespace

TEST(View, IteratesEntitiesWithAllComponentsAndNoneExcluded) {
  World w;
  std::set<std::uint32_t> expected;
  for (int i = 0; i < 100; ++i) {
    const Entity e = w.spawn();
    w.emplace<Position>(e, Position{static_cast<float>(i)});
    if (i % 2 == 0) w.emplace<Velocity>(e, Velocity{1.0f});
    if (i % 3 == 0) w.emplace<Frozen>(e);
    if (i % 2 == 0 && i % 3 != 0) expected.insert(e.index);
  }
  std::set<std::uint32_t> got;
  auto view = w.view<Position, const Velocity>(Exclude<Frozen>{});
  view.each([&](Entity e, Position& p, const Velocity& v) {
    p.x += v.v;
    got.insert(e.index);
  });
  EXPECT_EQ(got, expected);
  EXPECT_EQ(got.size(), 33u);  // even and not a multiple of 3 below 100
}

TEST(View, ExcludeOnMissingStorageExcludesNothing) {
  World w;
  const Entity e = w.spawn();
  w.emplace<Position>(e);
  int n = 0;
  w.view<const Position>(Exclude<Frozen>{}).each([&](const Position&) { ++n; });
  EXPECT_EQ(n, 1);
}

TEST(View, MissingIncludedStorageYieldsNothing) {
  World w;
  const Entity e = w.spawn();
  w.emplace<Position>(e);
  int n = 0;
  w.view<const Position, const Velocity>().each([&](const Position&, const Velocity&) { ++n; });
  EXPECT_EQ(n, 0);
}

TEST(View, ParallelEachVisitsEveryEntityOnce) {
  World w;
  constexpr int kCount = 50000;
  for (int i = 0; i < kCount; ++i) w.emplace<Position>(w.spawn(), Position{1.0f});
  w.view<Position>().par_each([](Position& p) { p.x += 1.0f; }, 512);
  float sum = 0;
  w.view<const Position>().each([&](const Position& p) { sum += p.x; });
  EXPECT_EQ(sum, 2.0f * kCount);
}

TEST(View, SwapAndPopKeepsSparseSetConsistent) {
  World w;
  std::vector<Entity> es;
  for (int i = 0; i < 10; ++i) {
    es.push_back(w.spawn());
    w.emplace<Position>(es.back(), Position{static_cast<float>(i)});
  }
  for (int i : {0, 5, 9, 3}) w.remove<Position>(es[i]);
  for (int i = 0; i < 10; ++i) {
    const bool removed = i == 0 || i == 5 || i == 9 || i == 3;
    ASSERT_EQ(w.has<Position>(es[i]), !removed) << "entity " << i;
    if (!removed) {
      EXPECT_EQ(w.get<Position>(es[i]).x, static_cast<float>(i));
    }
  }
}
