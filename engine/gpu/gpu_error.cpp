#include "engine/gpu/gpu_error.h"

#include <filesystem>

namespace engine::gpu {

std::string vk_result_name(VkResult result) {
  switch (result) {
#define ENGINE_VK_NAME(x) \
  case x:                 \
    return #x;
    ENGINE_VK_NAME(VK_SUCCESS)
    ENGINE_VK_NAME(VK_NOT_READY)
    ENGINE_VK_NAME(VK_TIMEOUT)
    ENGINE_VK_NAME(VK_INCOMPLETE)
    ENGINE_VK_NAME(VK_ERROR_OUT_OF_HOST_MEMORY)
    ENGINE_VK_NAME(VK_ERROR_OUT_OF_DEVICE_MEMORY)
    ENGINE_VK_NAME(VK_ERROR_INITIALIZATION_FAILED)
    ENGINE_VK_NAME(VK_ERROR_DEVICE_LOST)
    ENGINE_VK_NAME(VK_ERROR_MEMORY_MAP_FAILED)
    ENGINE_VK_NAME(VK_ERROR_LAYER_NOT_PRESENT)
    ENGINE_VK_NAME(VK_ERROR_EXTENSION_NOT_PRESENT)
    ENGINE_VK_NAME(VK_ERROR_FEATURE_NOT_PRESENT)
    ENGINE_VK_NAME(VK_ERROR_INCOMPATIBLE_DRIVER)
    ENGINE_VK_NAME(VK_ERROR_TOO_MANY_OBJECTS)
    ENGINE_VK_NAME(VK_ERROR_FORMAT_NOT_SUPPORTED)
    ENGINE_VK_NAME(VK_ERROR_FRAGMENTED_POOL)
    ENGINE_VK_NAME(VK_ERROR_OUT_OF_POOL_MEMORY)
    ENGINE_VK_NAME(VK_ERROR_UNKNOWN)
#undef ENGINE_VK_NAME
    default:
      return "VkResult " + std::to_string(static_cast<int>(result));
  }
}

void throw_vk_error(VkResult result, const char* call, const char* file, int line) {
  throw GpuError(std::filesystem::path(file).filename().string() + ":" + std::to_string(line) + ": " + call +
                 " failed: " + vk_result_name(result));
}

}  // namespace engine::gpu
