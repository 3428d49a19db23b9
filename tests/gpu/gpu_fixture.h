#pragma once
// One Vulkan context for every GPU test in the process (creating a lavapipe
// device costs ~50 ms), with the validation layer on where it is installed.
// Where no device can be created the tests skip with the reason, as the
// issue asks: CI installs lavapipe, a developer's machine may not have it.
#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "engine/gpu/vulkan_context.h"
#include "engine/image/image.h"

namespace gpu_test {

// One context per combination of the options tests vary, made on first use.
// Each is a static initialised by the creating call, so its destructor is
// registered after the driver and layers it loaded, and runs before theirs
// at exit (a static made before the create call is destroyed after the
// validation layer's globals, and crashed in vkDeviceWaitIdle).
template <bool StageDeviceOnly, bool RayQuery>
engine::gpu::VulkanContext* context_slot(std::string* why) {
  static std::string why_not;
  static std::unique_ptr<engine::gpu::VulkanContext> ctx = [] {
    engine::gpu::GpuOptions options;
    options.validation = true;
    options.stage_device_only = StageDeviceOnly;
    options.ray_query = RayQuery;
    return engine::gpu::VulkanContext::create(options, &why_not);
  }();
  *why = why_not;
  return ctx.get();
}

// ray_query: trace with VK_KHR_ray_query where the device has it (the
// default); false: the compute-shader BVH traversal, whatever the device.
inline engine::gpu::VulkanContext* context_with(bool stage_device_only, bool ray_query, std::string* why) {
  if (stage_device_only) return ray_query ? context_slot<true, true>(why) : context_slot<true, false>(why);
  return ray_query ? context_slot<false, true>(why) : context_slot<false, false>(why);
}

inline engine::gpu::VulkanContext* context(std::string* why) { return context_with(false, true, why); }

// A second context whose DeviceOnly buffers always go through staging
// copies (GpuOptions::stage_device_only), as on a discrete GPU.
inline engine::gpu::VulkanContext* staging_context(std::string* why) { return context_with(true, true, why); }

// The two ways the device traces (and binds its scene for a raster pass),
// for tests that run once each way.
enum class Traversal { ComputeBvh, RayQuery };

inline std::string traversal_name(const testing::TestParamInfo<Traversal>& info) {
  return info.param == Traversal::RayQuery ? "RayQuery" : "ComputeBvh";
}

// The context that traces the parameter's way, or null with the reason.
inline engine::gpu::VulkanContext* traversal_context(Traversal t, bool staging, std::string* why) {
  engine::gpu::VulkanContext* ctx = context_with(staging, t == Traversal::RayQuery, why);
  if (!ctx) {
    *why = "no Vulkan device: " + *why;
    return nullptr;
  }
  if (t == Traversal::RayQuery && !ctx->info().ray_query) {
    *why = ctx->info().name + " (" + ctx->info().driver +
           ") has no VK_KHR_ray_query; Mesa 25's lavapipe (bookworm-backports, scripts/setup-deps.sh) has it";
    return nullptr;
  }
  return ctx;
}

}  // namespace gpu_test

namespace gpu_test {

// The mean of (r + g + b) / 3 over an image's pixels: the scale the GPU
// tests' tolerances are stated against.
inline double mean_rgb(const engine::image::ImageRGB& img) {
  double mean = 0;
  for (const auto& p : img.pixels) mean += (p.r + p.g + p.b) / 3.0;
  return mean / static_cast<double>(img.pixels.size());
}

// A run whose device was refused (reason: probes::to_string's words) against
// the CPU backend's run of the same frames: the first says it fell back
// whole, for that reason, its detail naming `detail`, and its GI is the
// CPU's bit for bit.
inline void expect_cpu_fallback_frame(const std::string& capped_backend, const engine::image::ImageRGB& capped_gi,
                                      const std::string& cpu_backend, const engine::image::ImageRGB& cpu_gi,
                                      const std::string& reason = "scene too large",
                                      const std::string& detail = "largest storage buffer") {
  EXPECT_EQ(capped_backend.rfind("cpu; the CPU backend runs the frame (" + reason + "): ", 0), 0u) << capped_backend;
  EXPECT_NE(capped_backend.find(detail), std::string::npos) << capped_backend;
  EXPECT_EQ(cpu_backend, "cpu");
  ASSERT_GT(mean_rgb(cpu_gi), 1e-4) << "the GI should not be black";
  ASSERT_EQ(capped_gi.pixels.size(), cpu_gi.pixels.size());
  std::size_t differ = 0;
  for (std::size_t i = 0; i < cpu_gi.pixels.size(); ++i) differ += capped_gi.pixels[i] != cpu_gi.pixels[i] ? 1 : 0;
  EXPECT_EQ(differ, 0u) << "expected the CPU backend's frame exactly";
}

}  // namespace gpu_test

#define GPU_TEST_CONTEXT_OR_SKIP(name)                                   \
  std::string gpu_why_;                                                  \
  engine::gpu::VulkanContext* name = gpu_test::context(&gpu_why_);       \
  if (!name) GTEST_SKIP() << "no Vulkan device: " << gpu_why_
