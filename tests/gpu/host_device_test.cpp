// A host engine's own Vulkan device (VulkanContext::adopt, TransGIPlugin's
// host_gpu): the plugin's kernels run on it, give the frame that a device of
// their own gives, and leave the device working for the host.
#include <gtest/gtest.h>

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <vulkan/vulkan_core.h>

#include "engine/image/metrics.h"
#include "eval/method_runs.h"
#include "gpu/vulkan_probe_kernels.h"
#include "gpu_fixture.h"

using namespace transgi;

namespace {

// What a host engine would have made: its instance, a device with a compute
// queue and shaderInt64 (the kernels need it), nothing of ours.
struct HostDevice {
  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice physical = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  VkQueue queue = VK_NULL_HANDLE;
  std::uint32_t family = 0;
  std::string name;
  HostDevice() = default;
  HostDevice(const HostDevice&) = delete;
  HostDevice& operator=(const HostDevice&) = delete;
  ~HostDevice() {
    if (device) vkDestroyDevice(device, nullptr);
    if (instance) vkDestroyInstance(instance, nullptr);
  }
};

// int64: whether the host enables shaderInt64 (false: a host that did not,
// though the device has it).
std::unique_ptr<HostDevice> make_host_device(std::string* why, bool int64 = true) {
  auto host = std::make_unique<HostDevice>();
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "host engine";
  app.apiVersion = VK_API_VERSION_1_2;
  VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  ici.pApplicationInfo = &app;
  if (vkCreateInstance(&ici, nullptr, &host->instance) != VK_SUCCESS) {
    *why = "vkCreateInstance failed";
    return nullptr;
  }
  std::uint32_t n = 0;
  vkEnumeratePhysicalDevices(host->instance, &n, nullptr);
  std::vector<VkPhysicalDevice> all(n);
  vkEnumeratePhysicalDevices(host->instance, &n, all.data());
  for (VkPhysicalDevice p : all) {
    VkPhysicalDeviceFeatures features;
    vkGetPhysicalDeviceFeatures(p, &features);
    std::uint32_t families = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(p, &families, nullptr);
    std::vector<VkQueueFamilyProperties> fam(families);
    vkGetPhysicalDeviceQueueFamilyProperties(p, &families, fam.data());
    for (std::uint32_t f = 0; f < families && !host->physical; ++f)
      if (features.shaderInt64 && (fam[f].queueFlags & VK_QUEUE_COMPUTE_BIT)) {
        host->physical = p;
        host->family = f;
      }
  }
  if (!host->physical) {
    *why = "no device with a compute queue and shaderInt64";
    return nullptr;
  }
  VkPhysicalDeviceProperties props;
  vkGetPhysicalDeviceProperties(host->physical, &props);
  host->name = props.deviceName;
  const float priority = 1.0f;
  VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  qci.queueFamilyIndex = host->family;
  qci.queueCount = 1;
  qci.pQueuePriorities = &priority;
  VkPhysicalDeviceFeatures enable{};
  enable.shaderInt64 = int64 ? VK_TRUE : VK_FALSE;
  VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  dci.queueCreateInfoCount = 1;
  dci.pQueueCreateInfos = &qci;
  dci.pEnabledFeatures = &enable;
  if (vkCreateDevice(host->physical, &dci, nullptr, &host->device) != VK_SUCCESS) {
    *why = "vkCreateDevice failed";
    return nullptr;
  }
  vkGetDeviceQueue(host->device, host->family, 0, &host->queue);
  return host;
}

// The handles a host passes to VulkanContext::adopt; int64: what it says
// it enabled.
engine::gpu::HostVulkanDevice handles_of(const HostDevice& host, bool int64) {
  engine::gpu::HostVulkanDevice handles;
  handles.instance = host.instance;
  handles.physical_device = host.physical;
  handles.device = host.device;
  handles.queue = host.queue;
  handles.queue_family = host.family;
  handles.enabled_shader_int64 = int64;
  return handles;
}

eval::MethodRun cornell_on(std::shared_ptr<engine::gpu::VulkanContext> host_gpu,
                           runtime::Backend backend = runtime::Backend::Vulkan) {
  eval::TransgiRunOptions t;
  t.frames = 8;
  t.progress = false;
  t.settings.backend = backend;
  t.settings.direct_spp = 0;
  t.settings.probes.map = probes::MapLayout{32, 16};
  t.settings.probes.fixed_pattern = true;  // the same rays on both runs
  t.placement.mode = runtime::ProbeVolumeMode::Scene;
  t.placement.scene_dims = glm::ivec3(4);
  t.host_gpu = std::move(host_gpu);
  eval::LoadedScene scene = eval::load_scene(std::string(TRANSGI_CONTENT_DIR) + "/test_scenes/cornell_box/scene.gltf", "", 2);
  return eval::run_transgi(scene, std::make_shared<const model::TransferModel>(), 32, 32, t);
}

}  // namespace

TEST(HostVulkanDevice, TheKernelsRunOnTheHostsDeviceAndLeaveItToTheHost) {
  GPU_TEST_CONTEXT_OR_SKIP(own);
  std::string why;
  const std::unique_ptr<HostDevice> host = make_host_device(&why);
  ASSERT_TRUE(host) << why;
  std::shared_ptr<engine::gpu::VulkanContext> ctx = engine::gpu::VulkanContext::adopt(handles_of(*host, true), {}, &why);
  ASSERT_TRUE(ctx) << why;
  EXPECT_EQ(ctx->device(), host->device);
  EXPECT_FALSE(ctx->info().ray_query) << "the host did not enable ray queries";

  const eval::MethodRun on_host = cornell_on(ctx);
  ASSERT_EQ(on_host.backend.rfind("vulkan", 0), 0u) << "the plugin fell back: " << on_host.backend;
  EXPECT_NE(on_host.backend.find(host->name), std::string::npos) << on_host.backend;
  EXPECT_GT(ctx->traffic().submissions, 0u) << "nothing was submitted through the host's device";
  const eval::MethodRun on_own = cornell_on(nullptr);
  const double mean = gpu_test::mean_rgb(on_own.gi);
  ASSERT_GT(mean, 1e-3) << "the Cornell box's GI should not be black";
  const double rmse = engine::image::rmse_clamped(on_host.gi, on_own.gi);
  std::printf("host's device against the plugin's own: GI RMSE %.3g, mean GI %.4f (%s)\n", rmse, mean, on_host.backend.c_str());
  EXPECT_LT(rmse, 1e-4 * mean);

  // The context goes; the host's device and queue still serve the host.
  ctx.reset();
  VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  VkFence fence = VK_NULL_HANDLE;
  EXPECT_EQ(vkCreateFence(host->device, &fci, nullptr, &fence), VK_SUCCESS);
  VkSubmitInfo empty{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  EXPECT_EQ(vkQueueSubmit(host->queue, 1, &empty, fence), VK_SUCCESS);
  EXPECT_EQ(vkWaitForFences(host->device, 1, &fence, VK_TRUE, UINT64_MAX), VK_SUCCESS);
  vkDestroyFence(host->device, fence, nullptr);
}

TEST(HostVulkanDevice, AnIncompleteOrComputelessDeviceIsRefusedWithAReason) {
  GPU_TEST_CONTEXT_OR_SKIP(own);
  std::string why;
  EXPECT_FALSE(engine::gpu::VulkanContext::adopt(engine::gpu::HostVulkanDevice{}, {}, &why));
  EXPECT_NE(why.find("instance, physical device, device and queue are all needed"), std::string::npos) << why;
  const std::unique_ptr<HostDevice> host = make_host_device(&why);
  ASSERT_TRUE(host) << why;
  engine::gpu::HostVulkanDevice handles{host->instance, host->physical, host->device, host->queue, 1000, true, false, false};
  EXPECT_FALSE(engine::gpu::VulkanContext::adopt(handles, {}, &why));
  EXPECT_NE(why.find("queue family 1000 has no compute"), std::string::npos) << why;
}

// A host that did not enable shaderInt64, which the probe rays' shading needs:
// the backend is refused when it is made, typed (missing capability), and
// the CPU backend runs the whole frame, which is the CPU backend's own, bit
// for bit: no stage of it ran on the device.
TEST(HostVulkanDevice, ADeviceWithoutInt64GetsTheCpuBackendWholeAndSaysWhy) {
  GPU_TEST_CONTEXT_OR_SKIP(own);
  std::string why;
  const std::unique_ptr<HostDevice> host = make_host_device(&why, false);
  ASSERT_TRUE(host) << why;
  std::shared_ptr<engine::gpu::VulkanContext> ctx = engine::gpu::VulkanContext::adopt(handles_of(*host, false), {}, &why);
  ASSERT_TRUE(ctx) << why;
  probes::BackendFallback reason = probes::BackendFallback::None;
  EXPECT_FALSE(gpu::make_probe_kernels(ctx, &reason, &why));
  EXPECT_EQ(reason, probes::BackendFallback::MissingCapability) << probes::to_string(reason);
  const eval::MethodRun refused = cornell_on(ctx), cpu = cornell_on(nullptr, runtime::Backend::Cpu);
  EXPECT_EQ(ctx->traffic().submissions, 0u) << "nothing should have run on the refused device";
  gpu_test::expect_cpu_fallback_frame(refused.backend, refused.gi, cpu.backend, cpu.gi, "missing capability", "shaderInt64");
}
