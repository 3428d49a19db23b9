// ECS and scheduler overhead. Each engine measurement has a baseline in the
// same process, so ratios are meaningful on a noisy machine:
//   BM_ViewIterate_*      vs BM_Baseline_PlainVectorIterate (same data in a std::vector)
//   BM_Schedule50Empty_*  vs BM_Baseline_50FunctionCalls (50 std::function calls)
#include <benchmark/benchmark.h>

#include <algorithm>
#include <functional>
#include <vector>

#include "engine/jobs/job_system.h"
#include "engine/math/distribution.h"
#include "engine/math/rng.h"
#include "engine/schedule/schedule.h"

using namespace engine::schedule;

namespace {
struct Pos {
  float x, y, z;
};
struct Vel {
  float x, y, z;
};
constexpr std::size_t kEntities = 1'000'000;

void BM_Baseline_PlainVectorIterate(benchmark::State& state) {
  std::vector<Pos> p(kEntities, Pos{0, 0, 0});
  std::vector<Vel> v(kEntities, Vel{1, 2, 3});
  for (auto _ : state) {
    for (std::size_t i = 0; i < kEntities; ++i) {
      p[i].x += v[i].x;
      p[i].y += v[i].y;
      p[i].z += v[i].z;
    }
    benchmark::DoNotOptimize(p.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * kEntities));
}

World& world_1m() {
  static World* w = [] {
    auto* world = new World;
    for (std::size_t i = 0; i < kEntities; ++i) {
      const Entity e = world->spawn();
      world->emplace<Pos>(e, Pos{0, 0, 0});
      world->emplace<Vel>(e, Vel{1, 2, 3});
    }
    return world;
  }();
  return *w;
}

void BM_ViewIterate_WritePos_ReadVel(benchmark::State& state) {
  World& w = world_1m();
  for (auto _ : state) {
    View<Get<Pos, const Vel>>(w, 0, w.claim_tick()).each([](Pos& p, const Vel& v) {
      p.x += v.x;
      p.y += v.y;
      p.z += v.z;
    });
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * kEntities));
}

void BM_ViewIterate_ReadOnly(benchmark::State& state) {
  World& w = world_1m();
  for (auto _ : state) {
    float sum = 0;
    View<Get<const Pos, const Vel>>(w, 0, w.change_tick()).each([&](const Pos& p, const Vel& v) {
      sum += p.x * v.x;
    });
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * kEntities));
}

void BM_ViewIterate_ParallelWrite(benchmark::State& state) {
  World& w = world_1m();
  engine::jobs::JobSystem jobs({.threads = static_cast<int>(state.range(0))});
  for (auto _ : state) {
    jobs.run([&] {
      View<Get<Pos, const Vel>>(w, 0, w.claim_tick()).par_each([](Pos& p, const Vel& v) {
        p.x += v.x;
        p.y += v.y;
        p.z += v.z;
      }, 16384);
    });
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * kEntities));
}

constexpr int kSystems = 50;

void BM_Baseline_50FunctionCalls(benchmark::State& state) {
  std::vector<std::function<void(int)>> fns(kSystems, [](int x) { benchmark::DoNotOptimize(x); });
  for (auto _ : state)
    for (int i = 0; i < kSystems; ++i) fns[static_cast<std::size_t>(i)](i);
}

// 50 empty systems, each touching a different component type so that none
// conflict (the parallel worst case for dispatch), or all writing one type.
template <int I>
struct Tag {};
template <int... Is>
void add_independent(Schedule& s, std::integer_sequence<int, Is...>) {
  (s.add_system(Phase::Update, "sys" + std::to_string(Is), [](View<Get<Tag<Is>>>) {}), ...);
}

void BM_Schedule50Empty_Independent(benchmark::State& state) {
  World w;
  Schedule s;
  add_independent(s, std::make_integer_sequence<int, kSystems>{});
  engine::jobs::JobSystem jobs({.threads = static_cast<int>(state.range(0))});
  for (auto _ : state) s.run_phase(w, Phase::Update, &jobs);
  state.counters["per_system_ns"] =
      benchmark::Counter(static_cast<double>(state.iterations() * kSystems),
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void BM_Schedule50Empty_AllConflicting(benchmark::State& state) {
  World w;
  Schedule s;
  for (int i = 0; i < kSystems; ++i) s.add_system(Phase::Update, "sys" + std::to_string(i), [](View<Get<Pos>>) {});
  engine::jobs::JobSystem jobs({.threads = static_cast<int>(state.range(0))});
  for (auto _ : state) s.run_phase(w, Phase::Update, &jobs);
}

void BM_Schedule50Empty_Serial(benchmark::State& state) {
  World w;
  Schedule s;
  s.set_execution_mode(ExecutionMode::Serial);
  add_independent(s, std::make_integer_sequence<int, kSystems>{});
  for (auto _ : state) s.run_phase(w, Phase::Update);
}

}  // namespace

// Sampling an environment-sized distribution (2048 x 1024, the Living
// Room's sky) with random u: the guided search of Distribution1D against a
// binary search over each whole CDF (the baseline, as it was before the guide
// table), same tables, same u.
const engine::math::Distribution2D& sky_distribution() {
  static const engine::math::Distribution2D d = [] {
    std::vector<float> f(2048 * 1024);
    engine::math::Pcg32 rng(5, 6);
    for (float& v : f) v = rng.next_float() * rng.next_float();
    return engine::math::Distribution2D(f, 2048, 1024);
  }();
  return d;
}
std::size_t full_search(const engine::math::Distribution1D& d, float u) {
  const std::vector<double>& cdf = d.cdf();
  const auto it = std::upper_bound(cdf.begin(), cdf.end(), static_cast<double>(u));
  return std::min(d.size() - 1, static_cast<std::size_t>(std::max<std::ptrdiff_t>(0, (it - cdf.begin()) - 1)));
}
void BM_Baseline_SkySampleFullBinarySearch(benchmark::State& state) {
  const auto& d = sky_distribution();
  engine::math::Pcg32 rng(7, 8);
  for (auto _ : state) {
    const std::size_t row = full_search(d.marginal(), rng.next_float());
    benchmark::DoNotOptimize(full_search(d.rows()[row], rng.next_float()));
  }
}
void BM_SkySampleGuided(benchmark::State& state) {
  const auto& d = sky_distribution();
  engine::math::Pcg32 rng(7, 8);
  for (auto _ : state) benchmark::DoNotOptimize(d.sample({rng.next_float(), rng.next_float()}, nullptr));
}

BENCHMARK(BM_Baseline_PlainVectorIterate)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Baseline_SkySampleFullBinarySearch)->Unit(benchmark::kNanosecond);
BENCHMARK(BM_SkySampleGuided)->Unit(benchmark::kNanosecond);
BENCHMARK(BM_ViewIterate_WritePos_ReadVel)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ViewIterate_ReadOnly)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ViewIterate_ParallelWrite)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Baseline_50FunctionCalls)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Schedule50Empty_Serial)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Schedule50Empty_Independent)->Arg(1)->Arg(2)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Schedule50Empty_AllConflicting)->Arg(2)->Unit(benchmark::kMicrosecond);
BENCHMARK_MAIN();
