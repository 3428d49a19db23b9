#pragma once
// One Vulkan context for every GPU test in the process (creating a lavapipe
// device costs ~50 ms), with the validation layer on where it is installed.
// Where no device can be created the tests skip with the reason, as the
// issue asks: CI installs lavapipe, a developer's machine may not have it.
#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "engine/gpu/vulkan_context.h"

namespace gpu_test {

inline engine::gpu::VulkanContext* context(std::string* why) {
  static std::string why_not;
  static std::unique_ptr<engine::gpu::VulkanContext> ctx = [] {
    engine::gpu::GpuOptions options;
    options.validation = true;
    return engine::gpu::VulkanContext::create(options, &why_not);
  }();
  *why = why_not;
  return ctx.get();
}

// A second context whose DeviceOnly buffers always go through staging
// copies (GpuOptions::stage_device_only), as on a discrete GPU.
inline engine::gpu::VulkanContext* staging_context(std::string* why) {
  static std::string why_not;
  static std::unique_ptr<engine::gpu::VulkanContext> ctx = [] {
    engine::gpu::GpuOptions options;
    options.validation = true;
    options.stage_device_only = true;
    return engine::gpu::VulkanContext::create(options, &why_not);
  }();
  *why = why_not;
  return ctx.get();
}

}  // namespace gpu_test

#define GPU_TEST_CONTEXT_OR_SKIP(name)                                   \
  std::string gpu_why_;                                                  \
  engine::gpu::VulkanContext* name = gpu_test::context(&gpu_why_);       \
  if (!name) GTEST_SKIP() << "no Vulkan device: " << gpu_why_
