#pragma once
// Runs systems phase by phase. Inside a phase, system j waits for every
// earlier-registered system i whose access conflicts with j's, so conflicting
// systems run in registration order and never at once; the rest run in
// parallel on the job system's threads. At the end of each phase every
// system's Commands are applied in registration order.
#include <array>
#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include "engine/schedule/phase.h"
#include "engine/schedule/system.h"

namespace engine::jobs {
class JobSystem;
}

namespace engine::schedule {

struct SystemStats {
  std::string name;
  Phase phase;
  double last_ms = 0.0;
  double total_ms = 0.0;
  std::uint64_t runs = 0;
};

enum class ExecutionMode {
  Parallel,  // non-conflicting systems overlap
  Serial,    // registration order, one at a time (debugging, profiling)
};

class Schedule {
 public:
  // Registers a system in a phase; its storages are created on first run.
  void add_system(Phase phase, System system);
  template <class Fn>
  void add_system(Phase phase, std::string name, Fn fn) {
    add_system(phase, make_system(std::move(name), std::move(fn)));
  }

  // Runs one phase. jobs may be null: the calling thread's TBB arena is used.
  void run_phase(World& world, Phase phase, jobs::JobSystem* jobs = nullptr);

  void set_execution_mode(ExecutionMode m) { mode_ = m; }
  [[nodiscard]] ExecutionMode execution_mode() const { return mode_; }

  [[nodiscard]] std::size_t system_count(Phase phase) const { return phases_[index(phase)].systems.size(); }
  [[nodiscard]] std::vector<SystemStats> stats() const;
  // Pairs (i, j) of systems in `phase` that the scheduler keeps apart.
  [[nodiscard]] std::vector<std::pair<std::string, std::string>> conflicts(Phase phase) const;
  // Commands dropped because their target entity was gone when applied.
  [[nodiscard]] std::uint64_t dropped_commands() const { return dropped_commands_; }

 private:
  struct Entry {
    System system;
    SystemState state;
    SystemStats stats;
    bool initialised = false;
  };
  struct PhaseData {
    std::vector<Entry> systems;
    std::vector<std::vector<std::size_t>> successors;  // conflict edges i -> j, i < j
    std::vector<int> predecessor_count;
    bool graph_valid = false;
  };

  static std::size_t index(Phase p) { return static_cast<std::size_t>(p); }
  static void build_graph(PhaseData& pd);
  static void run_entry(World& world, Entry& e);
  void run_parallel(World& world, PhaseData& pd);
  void trim_removals(World& world) const;

  std::array<PhaseData, kPhaseCount> phases_;
  ExecutionMode mode_ = ExecutionMode::Parallel;
  std::uint64_t dropped_commands_ = 0;
};

}  // namespace engine::schedule
