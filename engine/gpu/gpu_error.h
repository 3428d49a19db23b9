#pragma once
// Every failing Vulkan call and every shader that does not compile becomes a
// GpuError whose message names the call (or the shader file and line) and
// where in our source it was made, so a report from a user's driver says
// which step broke without a debugger.
#include <stdexcept>
#include <string>

#include <vulkan/vulkan_core.h>

namespace engine::gpu {

class GpuError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// "VK_ERROR_OUT_OF_DEVICE_MEMORY", or the number for codes newer than ours.
std::string vk_result_name(VkResult result);

[[noreturn]] void throw_vk_error(VkResult result, const char* call, const char* file, int line);

}  // namespace engine::gpu

// Checks a VkResult; anything but VK_SUCCESS throws GpuError naming the call.
#define ENGINE_VK_CHECK(call)                                                               \
  do {                                                                                      \
    const VkResult engine_vk_result_ = (call);                                              \
    if (engine_vk_result_ != VK_SUCCESS) ::engine::gpu::throw_vk_error(engine_vk_result_, #call, __FILE__, __LINE__); \
  } while (false)
