#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <limits>
#include <vector>

#include "engine/jobs/job_system.h"
#include "engine/jobs/parallel_for.h"

using namespace engine::jobs;

TEST(ParallelFor, CoversTheRangeExactlyOnce) {
  JobSystem jobs({.threads = 2});
  std::vector<std::atomic<int>> hits(10007);
  jobs.run([&] { parallel_for_each_index<std::size_t>(0, hits.size(), 64, [&](std::size_t i) { ++hits[i]; }); });
  for (std::size_t i = 0; i < hits.size(); ++i) ASSERT_EQ(hits[i].load(), 1) << "index " << i;
}

TEST(ParallelFor, ChunkBoundariesDoNotDependOnThreadCount) {
  // Each chunk records its end and sum at its begin index. (Halving 100,000
  // gives chunks of 97 or 98, not 100: keying by b / 100, as this test once
  // did, let two chunks race for one slot and failed now and then.)
  auto chunks = [](int threads) {
    JobSystem jobs({.threads = threads});
    std::vector<std::pair<std::size_t, double>> at(100000, {0, 0.0});
    jobs.run([&] {
      parallel_for<std::size_t>(0, 100000, 100, [&](std::size_t b, std::size_t e) {
        double s = 0;
        for (std::size_t i = b; i < e; ++i) s += std::sin(static_cast<double>(i));
        at[b] = {e, s};
      });
    });
    return at;
  };
  const auto one = chunks(1), two = chunks(2);
  std::size_t count = 0;
  for (std::size_t b = 0; b < one.size(); ++b) {
    ASSERT_EQ(one[b], two[b]) << "chunk at " << b << ": 1 thread ends at " << one[b].first << ", 2 threads at " << two[b].first;
    count += one[b].first != 0;
  }
  EXPECT_GT(count, 500u) << "chunks must be at most the grain long";
}

TEST(JobSystem, WorkersFlushDenormals) {
  JobSystem jobs({.threads = 2});
  std::atomic<int> without{0};
  jobs.run([&] {
    parallel_for_each_index<int>(0, 256, 1, [&](int) {
      if (!flush_denormals_enabled_on_this_thread()) ++without;
    });
  });
  EXPECT_EQ(without.load(), 0);
  // And the effect is real: a denormal input reads as zero.
  volatile float tiny = std::numeric_limits<float>::denorm_min();
  float got = -1.0f;
  jobs.run([&] { got = tiny + tiny; });  // 2 * denorm_min without DAZ
  EXPECT_EQ(got, 0.0f);
}
