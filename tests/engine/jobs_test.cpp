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
  auto chunk_sums = [](int threads) {
    JobSystem jobs({.threads = threads});
    std::vector<double> sums(1000, 0.0);
    jobs.run([&] {
      parallel_for<std::size_t>(0, 100000, 100, [&](std::size_t b, std::size_t e) {
        double s = 0;
        for (std::size_t i = b; i < e; ++i) s += std::sin(static_cast<double>(i));
        sums[b / 100] = s;  // with grain 100 and a power-of-ten range each chunk is 100 long
      });
    });
    return sums;
  };
  EXPECT_EQ(chunk_sums(1), chunk_sums(2));
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
