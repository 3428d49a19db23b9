#pragma once
// A Vulkan context of a test's own (shared, as a backend holds it) and the
// probe kernels on it, for the tests that drive VulkanProbeKernels whole.
#include <memory>
#include <string>

#include "engine/gpu/vulkan_context.h"
#include "gpu/vulkan_probe_kernels.h"

namespace gpu_test {

struct OwnProbeKernels {
  std::shared_ptr<engine::gpu::VulkanContext> ctx;
  std::shared_ptr<transgi::gpu::VulkanProbeKernels> kernels;  // null: `why` says why
  std::string why;
};

inline OwnProbeKernels own_probe_kernels(engine::gpu::GpuOptions options = {}) {
  OwnProbeKernels k;
  k.ctx = std::shared_ptr<engine::gpu::VulkanContext>(engine::gpu::VulkanContext::create(options, &k.why));
  if (k.ctx) k.kernels = transgi::gpu::make_probe_kernels(k.ctx, nullptr, &k.why);
  return k;
}

}  // namespace gpu_test

// In a test body: `own` (a gpu_test::OwnProbeKernels) made with the given
// options, or the test fails (no context) or skips (no kernels), saying why.
#define OWN_PROBE_KERNELS_OR_SKIP(own, ...)                                      \
  const gpu_test::OwnProbeKernels own = gpu_test::own_probe_kernels(__VA_ARGS__); \
  ASSERT_TRUE(own.ctx) << own.why;                                               \
  if (!own.kernels) GTEST_SKIP() << own.why
