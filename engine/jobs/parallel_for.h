#pragma once
// Data-parallel loops for use inside systems. Chunk boundaries depend only on
// the range and the grain (simple_partitioner halves until a chunk is at most
// `grain` long), never on the thread count, so per-chunk reductions combined
// in chunk order give the same result on 1 or N threads.
#include <cstddef>
#include <type_traits>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

namespace engine::jobs {

// body(begin, end) is called for disjoint sub-ranges covering [first, last).
template <class Index, class Body>
void parallel_for(Index first, Index last, Index grain, Body&& body) {
  static_assert(std::is_integral_v<Index>);
  if (last <= first) return;
  if (grain < 1) grain = 1;
  tbb::parallel_for(
      tbb::blocked_range<Index>(first, last, grain),
      [&body](const tbb::blocked_range<Index>& r) { body(r.begin(), r.end()); }, tbb::simple_partitioner{});
}

// Threads that may run the calling context's parallel loops (the job
// system's arena inside JobSystem::run).
inline int current_thread_count() { return tbb::this_task_arena::max_concurrency(); }

// Per-index convenience form: fn(i) for every i in [first, last).
template <class Index, class Fn>
void parallel_for_each_index(Index first, Index last, Index grain, Fn&& fn) {
  parallel_for(first, last, grain, [&fn](Index b, Index e) {
    for (Index i = b; i < e; ++i) fn(i);
  });
}

}  // namespace engine::jobs
