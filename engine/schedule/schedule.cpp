#include "engine/schedule/schedule.h"

#include <atomic>
#include <limits>
#include <memory>

#include <tbb/task_group.h>

#include "engine/jobs/job_system.h"

namespace engine::schedule {

void Schedule::add_system(Phase phase, System system) {
  auto& pd = phases_[index(phase)];
  Entry e;
  e.state.name = system.name;
  e.stats.name = system.name;
  e.stats.phase = phase;
  e.system = std::move(system);
  pd.systems.push_back(std::move(e));
  pd.graph_valid = false;
}

void Schedule::build_graph(PhaseData& pd) {
  const std::size_t n = pd.systems.size();
  pd.successors.assign(n, {});
  pd.predecessor_count.assign(n, 0);
  for (std::size_t j = 0; j < n; ++j)
    for (std::size_t i = 0; i < j; ++i)
      if (pd.systems[i].system.access.conflicts_with(pd.systems[j].system.access)) {
        pd.successors[i].push_back(j);
        ++pd.predecessor_count[j];
      }
  pd.graph_valid = true;
}

void Schedule::run_entry(World& world, Entry& e) {
  const auto start = std::chrono::steady_clock::now();
  e.state.this_run = world.claim_tick();
  e.system.run(world, e.state);
  e.state.last_run = e.state.this_run;
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  e.stats.last_ms = ms;
  e.stats.total_ms += ms;
  ++e.stats.runs;
}

void Schedule::run_parallel(World& world, PhaseData& pd) {
  const std::size_t n = pd.systems.size();
  auto remaining = std::make_unique<std::atomic<int>[]>(n);
  for (std::size_t i = 0; i < n; ++i) remaining[i].store(pd.predecessor_count[i], std::memory_order_relaxed);

  tbb::task_group group;
  // Each finished system releases its successors; a successor starts once
  // every conflicting predecessor has finished.
  std::function<void(std::size_t)> launch = [&](std::size_t i) {
    group.run([&, i] {
      run_entry(world, pd.systems[i]);
      for (std::size_t j : pd.successors[i])
        if (remaining[j].fetch_sub(1, std::memory_order_acq_rel) == 1) launch(j);
    });
  };
  for (std::size_t i = 0; i < n; ++i)
    if (pd.predecessor_count[i] == 0) launch(i);
  group.wait();
}

void Schedule::run_phase(World& world, Phase phase, jobs::JobSystem* jobs) {
  auto& pd = phases_[index(phase)];
  for (auto& e : pd.systems)
    if (!e.initialised) {
      e.system.init(world, e.state);
      e.initialised = true;
    }
  if (!pd.graph_valid) build_graph(pd);

  auto body = [&] {
    if (mode_ == ExecutionMode::Serial || pd.systems.size() <= 1) {
      for (auto& e : pd.systems) run_entry(world, e);
    } else {
      run_parallel(world, pd);
    }
  };
  if (jobs) {
    jobs->run(body);
  } else {
    body();
  }

  // Sync point: structural changes land in registration order.
  world.flush();
  for (auto& e : pd.systems) dropped_commands_ += e.state.commands.apply(world);
  trim_removals(world);
}

void Schedule::trim_removals(World& world) const {
  // A removal can be forgotten once every per-frame system has run after it.
  Tick oldest = std::numeric_limits<Tick>::max();
  bool any = false;
  for (Phase p : kFramePhases)
    for (const auto& e : phases_[index(p)].systems) {
      oldest = std::min(oldest, e.state.last_run);
      any = true;
    }
  if (any) world.trim_removals(oldest);
}

std::vector<SystemStats> Schedule::stats() const {
  std::vector<SystemStats> out;
  for (const auto& pd : phases_)
    for (const auto& e : pd.systems) out.push_back(e.stats);
  return out;
}

std::vector<std::pair<std::string, std::string>> Schedule::conflicts(Phase phase) const {
  std::vector<std::pair<std::string, std::string>> out;
  const auto& systems = phases_[index(phase)].systems;
  for (std::size_t j = 0; j < systems.size(); ++j)
    for (std::size_t i = 0; i < j; ++i)
      if (systems[i].system.access.conflicts_with(systems[j].system.access))
        out.emplace_back(systems[i].system.name, systems[j].system.name);
  return out;
}

}  // namespace engine::schedule
