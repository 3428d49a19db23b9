#pragma once
// DDGI's probe rays and blend on a Vulkan device (ddgi::DdgiKernels).
#include <algorithm>
#include <exception>
#include <memory>
#include <string>

#include "ddgi/ddgi_kernels.h"
#include "engine/gpu/gpu_ray_tracer.h"
#include "gpu/vulkan_ddgi_blend.h"
#include "gpu/vulkan_ddgi_irradiance.h"

namespace transgi::gpu {

class VulkanDdgiKernels : public ddgi::DdgiKernels {
 public:
  explicit VulkanDdgiKernels(std::shared_ptr<engine::gpu::VulkanContext> ctx)
      : ctx_(std::move(ctx)), tracer_(*ctx_), blend_(*ctx_), name_(engine::gpu::describe(ctx_->info())) {}

  engine::rt::RayBatchTracer* tracer() override { return &tracer_; }
  void blend(std::vector<ddgi::OctahedralMap<glm::vec3>>& irradiance, std::vector<ddgi::OctahedralMap<glm::vec2>>& distance,
             const std::vector<std::vector<ddgi::RayRecord>>& records, const ddgi::DdgiSettings& settings, float hysteresis,
             bool clamp_brightness, float max_distance) override {
    blend_.blend(irradiance, distance, records, settings, hysteresis, clamp_brightness, max_distance);
  }
  bool irradiance(const ddgi::DdgiVolume& volume, std::span<const glm::vec3> positions, std::span<const glm::vec3> normals,
                  std::span<const glm::vec3> view_dirs, std::span<glm::vec3> out, std::span<std::uint8_t> lit) override {
    const GpuDdgiIrradiance r = irradiance_.irradiance(volume, positions, normals, view_dirs);
    std::copy(r.irradiance.begin(), r.irradiance.end(), out.begin());
    std::copy(r.lit.begin(), r.lit.end(), lit.begin());
    return true;
  }
  [[nodiscard]] const char* name() const override { return name_.c_str(); }

 private:
  std::shared_ptr<engine::gpu::VulkanContext> ctx_;
  engine::gpu::GpuRayTracer tracer_;
  VulkanDdgiBlend blend_;
  VulkanDdgiIrradiance irradiance_{*ctx_};
  std::string name_;
};

// The backend --backend NAME asks for: null for "cpu", or for "vulkan" when
// no device can be had (then *why says why).
inline std::shared_ptr<ddgi::DdgiKernels> make_ddgi_kernels(const std::string& backend, const std::string& device,
                                                           std::string* why) {
  if (backend != "vulkan") return nullptr;
  engine::gpu::GpuOptions options;
  options.device = device;
  try {  // as make_probe_kernels: a device or shader failure falls back to the CPU with its reason
    if (auto ctx = engine::gpu::VulkanContext::create(options, why))
      return std::make_shared<VulkanDdgiKernels>(std::shared_ptr<engine::gpu::VulkanContext>(std::move(ctx)));
  } catch (const std::exception& e) {
    if (why) *why = e.what();
  }
  return nullptr;
}

}  // namespace transgi::gpu
