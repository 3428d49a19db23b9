#include <gtest/gtest.h>

#include <vector>

#include "engine/schedule/schedule.h"

using namespace engine::schedule;

namespace {
struct Health {
  int hp = 0;
};

// What a watcher system saw on each of its runs.
struct Seen {
  std::vector<std::vector<std::uint32_t>> added, changed, removed;
};

void watcher(View<Get<const Health>> v, Removed<Health> removed, ResMut<Seen> seen) {
  std::vector<std::uint32_t> a, c, r;
  v.each([&](Entity e, const Health&) {
    if (v.is_added<Health>(e)) a.push_back(e.index);
    if (v.is_changed<Health>(e)) c.push_back(e.index);
  });
  for (Entity e : removed) r.push_back(e.index);
  seen->added.push_back(a);
  seen->changed.push_back(c);
  seen->removed.push_back(r);
}

using Idx = std::vector<std::uint32_t>;
}  // namespace

TEST(ChangeDetection, AddedChangedRemovedAreRelativeToTheWatchersLastRun) {
  World w;
  w.insert_resource<Seen>();
  Schedule s;
  s.add_system(Phase::Update, "watcher", watcher);

  const Entity a = w.spawn();
  const Entity b = w.spawn();
  w.emplace<Health>(a, Health{10});
  s.run_phase(w, Phase::Update);  // run 0: a added

  w.emplace<Health>(b, Health{5});
  s.run_phase(w, Phase::Update);  // run 1: b added; a untouched

  (void)w.get<Health>(a);  // read access is not a change
  s.run_phase(w, Phase::Update);  // run 2: nothing

  w.get_mut<Health>(a).hp = 9;  // any mutable access is a change
  s.run_phase(w, Phase::Update);  // run 3: a changed

  w.patch<Health>(b, [](Health& h) { h.hp = 1; });
  w.remove<Health>(a);
  s.run_phase(w, Phase::Update);  // run 4: b changed, a removed

  s.run_phase(w, Phase::Update);  // run 5: removal is reported once only

  const auto& seen = w.resource<Seen>();
  ASSERT_EQ(seen.added.size(), 6u);
  EXPECT_EQ(seen.added[0], Idx{a.index});
  EXPECT_EQ(seen.changed[0], Idx{a.index}) << "an added component also counts as changed";
  EXPECT_EQ(seen.added[1], Idx{b.index});
  EXPECT_EQ(seen.changed[1], Idx{b.index});
  EXPECT_EQ(seen.added[2], Idx{});
  EXPECT_EQ(seen.changed[2], Idx{});
  EXPECT_EQ(seen.changed[3], Idx{a.index});
  EXPECT_EQ(seen.added[3], Idx{});
  EXPECT_EQ(seen.changed[4], Idx{b.index});
  EXPECT_EQ(seen.removed[4], Idx{a.index});
  EXPECT_EQ(seen.removed[5], Idx{});
  EXPECT_EQ(seen.changed[5], Idx{});
}

TEST(ChangeDetection, EachSystemHasItsOwnLastRun) {
  // Writer runs every frame; the slow watcher only sees changes made since *its* last run.
  World w;
  w.insert_resource<Seen>();
  const Entity e = w.spawn();
  w.emplace<Health>(e, Health{0});

  Schedule writer_schedule, watcher_schedule;
  writer_schedule.add_system(Phase::Update, "writer",
                             [](View<Get<Health>> v) { v.each([](Health& h) { ++h.hp; }); });
  watcher_schedule.add_system(Phase::Update, "watcher", watcher);

  watcher_schedule.run_phase(w, Phase::Update);  // sees the add
  watcher_schedule.run_phase(w, Phase::Update);  // nothing new
  writer_schedule.run_phase(w, Phase::Update);
  writer_schedule.run_phase(w, Phase::Update);
  watcher_schedule.run_phase(w, Phase::Update);  // sees one change, however many writes
  const auto& seen = w.resource<Seen>();
  EXPECT_EQ(seen.changed[0], Idx{e.index});
  EXPECT_EQ(seen.changed[1], Idx{});
  EXPECT_EQ(seen.changed[2], Idx{e.index});
  EXPECT_EQ(w.get<Health>(e).hp, 2);
}

TEST(ChangeDetection, MutableViewMarksChangedConstViewDoesNot) {
  World w;
  const Entity e = w.spawn();
  w.emplace<Health>(e);
  const Tick before = w.claim_tick();
  w.claim_tick();
  View<Get<const Health>>(w, before, w.claim_tick()).each([](const Health&) {});
  EXPECT_FALSE((View<Get<const Health>>(w, before, w.change_tick()).is_changed<Health>(e)))
      << "const access must not stamp a change";
  View<Get<Health>>(w, before, w.claim_tick()).each([](Health&) {});
  EXPECT_TRUE((View<Get<const Health>>(w, before, w.change_tick()).is_changed<Health>(e)));
}
