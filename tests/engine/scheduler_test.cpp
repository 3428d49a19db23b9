// Proves, with atomic counters and no sleeps, that the scheduler keeps
// conflicting systems apart and lets independent systems overlap.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>

#include <tbb/global_control.h>

#include "engine/jobs/job_system.h"
#include "engine/schedule/schedule.h"

using namespace engine::schedule;

namespace {
struct A {
  int v = 0;
};
struct B {
  int v = 0;
};

// Shared probe: how many probed systems are inside their body right now, and
// the most that ever were at once.
struct Overlap {
  std::atomic<int> inside{0};
  std::atomic<int> max_inside{0};

  void enter() {
    const int now = inside.fetch_add(1) + 1;
    int seen = max_inside.load();
    while (now > seen && !max_inside.compare_exchange_weak(seen, now)) {
    }
  }
  void leave() { inside.fetch_sub(1); }
  // Spins until `count` systems are inside at once, or gives up after a
  // generous bound; gives up immediately if the partner can never arrive.
  // How long a probed system waits for a partner. The overlap test returns as
  // soon as the partner arrives; the conflict test always waits the full
  // time, giving a broken scheduler ample chance to start the other system.
  std::chrono::milliseconds patience{5000};

  bool rendezvous(int count) {
    const auto deadline = std::chrono::steady_clock::now() + patience;
    while (inside.load() < count) {
      if (std::chrono::steady_clock::now() > deadline) return false;
    }
    return true;
  }
};

Overlap* g_probe = nullptr;

// Two systems that write the same component: they conflict.
void write_a_1(View<Get<A>> v) {
  g_probe->enter();
  g_probe->rendezvous(2);  // would wait for a partner that must never come
  v.each([](A& a) { a.v = a.v * 10 + 1; });
  g_probe->leave();
}
void write_a_2(View<Get<A>> v) {
  g_probe->enter();
  g_probe->rendezvous(2);
  v.each([](A& a) { a.v = a.v * 10 + 2; });
  g_probe->leave();
}
// Independent systems: one writes A, one writes B.
void touch_a(View<Get<A>> v) {
  g_probe->enter();
  g_probe->rendezvous(2);
  v.each([](A& a) { ++a.v; });
  g_probe->leave();
}
void touch_b(View<Get<B>> v) {
  g_probe->enter();
  g_probe->rendezvous(2);
  v.each([](B& b) { ++b.v; });
  g_probe->leave();
}
}  // namespace

TEST(Access, DeducedFromConstness) {
  const System s = make_system("s", [](View<Get<const A, B>>, Res<int>, ResMut<double>) {});
  ASSERT_EQ(s.access.component_reads.size(), 1u);
  ASSERT_EQ(s.access.component_writes.size(), 1u);
  EXPECT_EQ(s.access.component_reads[0], engine::ecs::type_id<A>());
  EXPECT_EQ(s.access.component_writes[0], engine::ecs::type_id<B>());
  EXPECT_EQ(s.access.resource_reads[0], engine::ecs::type_id<int>());
  EXPECT_EQ(s.access.resource_writes[0], engine::ecs::type_id<double>());

  const System reader = make_system("r", [](View<Get<const B>>) {});
  const System other_reader = make_system("r2", [](View<Get<const A>>, Res<double>) {});
  EXPECT_TRUE(s.access.conflicts_with(reader.access)) << "write B vs read B";
  EXPECT_TRUE(s.access.conflicts_with(other_reader.access)) << "write double vs read double";
  EXPECT_FALSE(reader.access.conflicts_with(other_reader.access));
  const System exclusive = make_system("x", [](World&) {});
  EXPECT_TRUE(exclusive.access.conflicts_with(reader.access));
}

TEST(Scheduler, ConflictingSystemsNeverOverlapAndKeepRegistrationOrder) {
  tbb::global_control allow_two(tbb::global_control::max_allowed_parallelism, 2);
  engine::jobs::JobSystem jobs({.threads = 2});
  Overlap probe;
  probe.patience = std::chrono::milliseconds(300);
  g_probe = &probe;
  World w;
  const Entity e = w.spawn();
  w.emplace<A>(e);
  Schedule s;
  s.add_system(Phase::Update, "write_a_1", write_a_1);
  s.add_system(Phase::Update, "write_a_2", write_a_2);
  ASSERT_EQ(s.conflicts(Phase::Update).size(), 1u);
  // A few frames are enough: each one makes the first system spin for its
  // partner, which must not be started while it runs.
  for (int frame = 0; frame < 3; ++frame) {
    w.get_mut<A>(e).v = 0;
    s.run_phase(w, Phase::Update, &jobs);
    EXPECT_EQ(w.get<A>(e).v, 12) << "write_a_1 must run before write_a_2";
  }
  EXPECT_EQ(probe.max_inside.load(), 1) << "conflicting systems ran at the same time";
  g_probe = nullptr;
}

TEST(Scheduler, IndependentSystemsCanOverlap) {
  tbb::global_control allow_two(tbb::global_control::max_allowed_parallelism, 2);
  engine::jobs::JobSystem jobs({.threads = 2});
  Overlap probe;
  g_probe = &probe;
  World w;
  const Entity e = w.spawn();
  w.emplace<A>(e);
  w.emplace<B>(e);
  Schedule s;
  s.add_system(Phase::Update, "touch_a", touch_a);
  s.add_system(Phase::Update, "touch_b", touch_b);
  ASSERT_TRUE(s.conflicts(Phase::Update).empty());
  s.run_phase(w, Phase::Update, &jobs);
  EXPECT_EQ(probe.max_inside.load(), 2) << "independent systems never ran at the same time on 2 threads";
  EXPECT_EQ(w.get<A>(e).v, 1);
  EXPECT_EQ(w.get<B>(e).v, 1);
  g_probe = nullptr;
}

TEST(Scheduler, SerialModeNeverOverlaps) {
  Overlap probe;
  g_probe = &probe;
  World w;
  w.emplace<A>(w.spawn());
  w.emplace<B>(w.spawn());
  Schedule s;
  s.set_execution_mode(ExecutionMode::Serial);
  s.add_system(Phase::Update, "noop_a", [](View<Get<const A>>) {
    g_probe->enter();
    g_probe->leave();
  });
  s.add_system(Phase::Update, "noop_b", [](View<Get<const B>>) {
    g_probe->enter();
    g_probe->leave();
  });
  s.run_phase(w, Phase::Update);
  EXPECT_EQ(probe.max_inside.load(), 1);
  g_probe = nullptr;
}

TEST(Scheduler, MissingResourceNamesSystemAndType) {
  World w;
  Schedule s;
  s.add_system(Phase::Update, "needs_double", [](Res<double>) {});
  try {
    s.run_phase(w, Phase::Update);
    FAIL() << "expected ScheduleError";
  } catch (const ScheduleError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("needs_double"), std::string::npos) << msg;
    EXPECT_NE(msg.find("double"), std::string::npos) << msg;
  }
}

TEST(Scheduler, LocalStateIsPerSystem) {
  World w;
  w.insert_resource<std::vector<int>>();
  Schedule s;
  auto counter = [](Local<int> n, ResMut<std::vector<int>> out) { out->push_back(++*n); };
  s.add_system(Phase::Update, "c1", counter);
  s.add_system(Phase::Update, "c2", counter);
  s.run_phase(w, Phase::Update);
  s.run_phase(w, Phase::Update);
  EXPECT_EQ(w.resource<std::vector<int>>(), (std::vector<int>{1, 1, 2, 2}));
}
