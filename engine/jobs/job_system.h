#pragma once
// The engine's worker pool: a TBB arena with a fixed thread count. Systems
// and parallel_for calls made from inside run() use exactly these threads.
// Every worker flushes denormals to zero (FTZ/DAZ): ray tracing and shading
// otherwise slow down by orders of magnitude on denormal inputs.
#include <memory>
#include <utility>

#include <tbb/task_arena.h>

namespace engine::jobs {

struct JobSystemOptions {
  // 0 = one thread per hardware thread. Higher = more parallelism, at the
  // cost of more memory per in-flight task and less repeatable timings.
  int threads = 0;
  // Set FTZ/DAZ on every worker (and the calling thread inside run()).
  bool flush_denormals = true;
};

class JobSystem {
 public:
  explicit JobSystem(JobSystemOptions options = {});
  ~JobSystem();
  JobSystem(const JobSystem&) = delete;
  JobSystem& operator=(const JobSystem&) = delete;

  [[nodiscard]] int thread_count() const { return threads_; }

  // Runs fn inside the arena, so nested TBB work uses this pool.
  template <class Fn>
  decltype(auto) run(Fn&& fn) {
    return arena_.execute([&]() -> decltype(auto) {
      const FloatModeScope scope(flush_denormals_);
      return fn();
    });
  }

 private:
  // The calling thread joins the arena too; give it the workers' float mode
  // for the duration of run() and restore its own afterwards.
  struct FloatModeScope {
    explicit FloatModeScope(bool enable);
    ~FloatModeScope();
    FloatModeScope(const FloatModeScope&) = delete;
    FloatModeScope& operator=(const FloatModeScope&) = delete;
    unsigned saved;
    bool active;
  };
  bool flush_denormals_;
  int threads_;
  tbb::task_arena arena_;
};

// Sets FTZ and DAZ in this thread's MXCSR.
void enable_flush_denormals_on_this_thread();
// True when both FTZ and DAZ are set on this thread.
[[nodiscard]] bool flush_denormals_enabled_on_this_thread();

}  // namespace engine::jobs
