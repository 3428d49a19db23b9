#include "engine/jobs/job_system.h"

#include <algorithm>
#include <thread>

#include <xmmintrin.h>

namespace engine::jobs {

namespace {
constexpr unsigned kFtzBit = 0x8000;  // MXCSR flush-to-zero
constexpr unsigned kDazBit = 0x0040;  // MXCSR denormals-are-zero
}  // namespace

void enable_flush_denormals_on_this_thread() { _mm_setcsr(_mm_getcsr() | kFtzBit | kDazBit); }

bool flush_denormals_enabled_on_this_thread() {
  return (_mm_getcsr() & (kFtzBit | kDazBit)) == (kFtzBit | kDazBit);
}

JobSystem::JobSystem(JobSystemOptions options)
    : flush_denormals_(options.flush_denormals),
      threads_(options.threads > 0 ? options.threads
                                   : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()))),
      arena_(threads_) {
  // oneTBB captures the FP control state of the thread that initialises an
  // arena and applies it to every task run in it, whichever thread runs it.
  const FloatModeScope scope(flush_denormals_);
  arena_.initialize();
}

JobSystem::~JobSystem() = default;

JobSystem::FloatModeScope::FloatModeScope(bool enable) : saved(_mm_getcsr()), active(enable) {
  if (active) enable_flush_denormals_on_this_thread();
}
JobSystem::FloatModeScope::~FloatModeScope() {
  if (active) _mm_setcsr(saved);
}

}  // namespace engine::jobs
