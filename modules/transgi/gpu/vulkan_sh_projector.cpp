#include "gpu/vulkan_sh_projector.h"

#include <stdexcept>
#include <string>
#include <vector>

#include "gpu/shader_path.h"
#include "transgi_shared.h"

namespace transgi::gpu {

VulkanShProjector::VulkanShProjector(engine::gpu::VulkanContext& ctx, const probes::MapProjector& projector)
    : ctx_(ctx), texels_(projector.layout().texel_count()) {
  static_assert(engine::math::kShCount == static_cast<int>(kShCoefficients));
  const auto& b = projector.basis_integrals();
  basis_ = engine::gpu::GpuBuffer(ctx, b.size() * kShCoefficients * sizeof(float), engine::gpu::GpuBuffer::Placement::DeviceOnly);
  basis_.upload(std::span<const float>(b.front().data(), b.size() * kShCoefficients));
  pipeline_ = std::make_unique<engine::gpu::ComputePipeline>(ctx, compile_module_shader("sh_projection.comp"), 3,
                                                              static_cast<std::uint32_t>(sizeof(ProjectPush)));
  pipeline_->bind(0, basis_);
}

double VulkanShProjector::project(std::span<const glm::vec3> radiance, std::span<float> out) {
  const std::size_t probes = out.size() / kTransferOutputs;
  if (out.size() != probes * kTransferOutputs || radiance.size() != probes * static_cast<std::size_t>(texels_))
    throw std::invalid_argument("VulkanShProjector::project: " + std::to_string(radiance.size()) + " texels for " +
                                std::to_string(out.size()) + " coefficients (maps of " + std::to_string(texels_) + ")");
  if (probes == 0) return 0.0;
  if (probes > capacity_) {
    capacity_ = probes;
    radiance_ = engine::gpu::GpuBuffer(ctx_, probes * static_cast<std::size_t>(texels_) * 3 * sizeof(float));
  }
  pipeline_->bind(1, radiance_);
  reserve_out(probes);
  static_assert(sizeof(glm::vec3) == 3 * sizeof(float));
  radiance_.upload(std::span<const float>(&radiance.front().x, radiance.size() * 3));
  const ProjectPush push{static_cast<uint>(probes), static_cast<uint>(texels_), 0, 0};
  const double ms = ctx_.submit_and_wait(
      [&](VkCommandBuffer cmd) { pipeline_->record_dispatch(cmd, static_cast<std::uint32_t>(probes), 1, 1, &push); });
  out_.download(out);
  return ms;
}

void VulkanShProjector::reserve_out(std::size_t probes) {
  if (probes > out_capacity_) {
    out_capacity_ = probes;
    out_ = engine::gpu::GpuBuffer(ctx_, probes * kTransferOutputs * sizeof(float));
  }
  pipeline_->bind(2, out_);
}

void VulkanShProjector::record(VkCommandBuffer cmd, const engine::gpu::GpuBuffer& radiance, std::size_t probes) {
  if (radiance.size() < probes * static_cast<std::size_t>(texels_) * 3 * sizeof(float))
    throw std::invalid_argument("VulkanShProjector::record: the radiance buffer holds fewer than " + std::to_string(probes) +
                                " maps of " + std::to_string(texels_) + " texels");
  recorded_ = probes;
  if (probes == 0) return;
  pipeline_->bind(1, radiance);
  reserve_out(probes);
  const ProjectPush push{static_cast<uint>(probes), static_cast<uint>(texels_), 0, 0};
  pipeline_->record_dispatch(cmd, static_cast<std::uint32_t>(probes), 1, 1, &push);
}

void VulkanShProjector::read(std::span<float> out) {
  if (out.size() != recorded_ * kTransferOutputs)
    throw std::invalid_argument("VulkanShProjector::read: " + std::to_string(out.size()) + " coefficients for " +
                                std::to_string(recorded_) + " recorded probes");
  if (!out.empty()) out_.download(out);
}

}  // namespace transgi::gpu
