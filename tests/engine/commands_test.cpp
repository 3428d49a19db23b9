#include <gtest/gtest.h>

#include "engine/schedule/schedule.h"

using namespace engine::schedule;

namespace {
struct Age {
  int years = 0;
};
struct Offspring {};
struct Dead {};
}  // namespace

TEST(Commands, StructuralChangesDuringIterationAreDeferredToThePhaseEnd) {
  World w;
  for (int i = 0; i < 10; ++i) w.emplace<Age>(w.spawn(), Age{i});

  struct Observed {
    std::size_t during = 0;
  };
  w.insert_resource<Observed>();

  Schedule s;
  s.add_system(Phase::Update, "reproduce_and_die", [](View<Get<const Age>> v, Commands& cmd, ResMut<Observed> o) {
    std::size_t visited = 0;
    v.each([&](Entity e, const Age& a) {
      ++visited;
      if (a.years % 2 == 0) {
        const Entity child = cmd.spawn();  // handle usable before it exists
        cmd.insert(child, Age{100 + a.years}).insert(child, Offspring{});
      } else {
        cmd.despawn(e);
      }
    });
    o->during = visited;  // iteration saw exactly the original 10
  });
  s.run_phase(w, Phase::Update);

  EXPECT_EQ(w.resource<Observed>().during, 10u);
  EXPECT_EQ(w.entity_count(), 10u);  // 10 - 5 despawned + 5 spawned
  int offspring = 0, originals = 0;
  w.view<const Age>().each([&](Entity e, const Age& a) {
    if (w.has<Offspring>(e)) {
      ++offspring;
      EXPECT_GE(a.years, 100);
    } else {
      ++originals;
      EXPECT_EQ(a.years % 2, 0) << "odd-aged entities should be gone";
    }
  });
  EXPECT_EQ(offspring, 5);
  EXPECT_EQ(originals, 5);
}

TEST(Commands, AreAppliedInRegistrationOrderAcrossSystems) {
  World w;
  const Entity e = w.spawn();
  w.emplace<Age>(e, Age{0});
  Schedule s;
  // Both systems only read, so they may run in parallel, but their commands
  // must land in registration order: the later insert wins.
  s.add_system(Phase::Update, "first", [e](View<Get<const Age>>, Commands& c) { c.insert(e, Age{1}); });
  s.add_system(Phase::Update, "second", [e](View<Get<const Age>>, Commands& c) { c.insert(e, Age{2}); });
  for (int i = 0; i < 20; ++i) {
    s.run_phase(w, Phase::Update);
    ASSERT_EQ(w.get<Age>(e).years, 2) << "iteration " << i;
  }
}

TEST(Commands, OpsOnEntitiesDespawnedEarlierInTheSameFlushAreDroppedAndCounted) {
  World w;
  const Entity e = w.spawn();
  Schedule s;
  s.add_system(Phase::Update, "killer", [e](Commands& c) { c.despawn(e); });
  s.add_system(Phase::Update, "decorator", [e](Commands& c) { c.insert(e, Dead{}); });
  s.run_phase(w, Phase::Update);
  EXPECT_FALSE(w.alive(e));
  EXPECT_EQ(s.dropped_commands(), 1u);
}
