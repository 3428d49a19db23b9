#include <gtest/gtest.h>

#include "engine/ecs/ecs.h"

using namespace engine::ecs;

TEST(Entity, StaleHandleIsDetectedAfterDespawn) {
  World w;
  const Entity a = w.spawn();
  w.emplace<int>(a, 7);
  ASSERT_TRUE(w.despawn(a));
  EXPECT_FALSE(w.alive(a));
  EXPECT_FALSE(w.despawn(a)) << "despawning twice must be refused";
  EXPECT_EQ(w.try_get<int>(a), nullptr);
  EXPECT_THROW(w.emplace<int>(a, 1), EcsError);
}

TEST(Entity, ReusedSlotGetsNewGenerationSoOldHandleStaysDead) {
  World w;
  const Entity a = w.spawn();
  w.emplace<int>(a, 1);
  w.despawn(a);
  const Entity b = w.spawn();
  ASSERT_EQ(b.index, a.index) << "the freed slot should be reused";
  EXPECT_EQ(b.generation, a.generation + 1);
  EXPECT_TRUE(w.alive(b));
  EXPECT_FALSE(w.alive(a));
  w.emplace<int>(b, 2);
  EXPECT_EQ(w.try_get<int>(a), nullptr) << "a stale handle must not see the new entity's component";
  EXPECT_EQ(w.get<int>(b), 2);
}

TEST(Entity, DespawnRemovesAllComponents) {
  World w;
  const Entity a = w.spawn();
  w.emplace<int>(a, 1);
  w.emplace<float>(a, 2.0f);
  w.despawn(a);
  EXPECT_EQ(w.storage<int>().size(), 0u);
  EXPECT_EQ(w.storage<float>().size(), 0u);
  EXPECT_EQ(w.entity_count(), 0u);
}

TEST(Entity, ReservedEntitiesBecomeAliveAtFlush) {
  World w;
  const Entity live = w.spawn();
  w.despawn(live);  // leaves one slot on the free list
  const Entity r1 = w.reserve_entity();
  const Entity r2 = w.reserve_entity();
  EXPECT_NE(r1, r2);
  EXPECT_FALSE(w.alive(r1));
  EXPECT_FALSE(w.alive(r2));
  w.flush();
  EXPECT_TRUE(w.alive(r1));
  EXPECT_TRUE(w.alive(r2));
  EXPECT_EQ(w.entity_count(), 2u);
  EXPECT_FALSE(w.alive(live));
  const Entity s = w.spawn();
  EXPECT_NE(s.index, r1.index);
  EXPECT_NE(s.index, r2.index);
}

TEST(Resources, InsertGetRemove) {
  World w;
  EXPECT_FALSE(w.has_resource<double>());
  EXPECT_THROW((void)w.resource<double>(), EcsError);
  w.insert_resource<double>(2.5);
  EXPECT_EQ(w.resource<double>(), 2.5);
  w.resource<double>() = 3.0;
  EXPECT_EQ(std::as_const(w).resource<double>(), 3.0);
  EXPECT_TRUE(w.remove_resource<double>());
  EXPECT_FALSE(w.has_resource<double>());
}
