#include "gpu/vulkan_fused_decoder.h"

#include <stdexcept>
#include <string>

#include "engine/gpu/gpu_error.h"
#include "gpu/shader_path.h"
#include "transgi_shared.h"

namespace transgi::gpu {

VulkanFusedDecoder::VulkanFusedDecoder(engine::gpu::VulkanContext& ctx, const model::Mlp& mlp, FusedWeights weights)
    : ctx_(ctx), layout_(mlp.layout()) {
  const auto& l = layout_;
  if (l.outputs != static_cast<int>(kTransferOutputs) || l.width > static_cast<int>(kFusedMaxWidth) ||
      l.inputs > static_cast<int>(kFusedMaxWidth) || l.width < 1 || l.inputs < 1)
    throw std::invalid_argument("VulkanFusedDecoder: the kernel holds layers up to " + std::to_string(kFusedMaxWidth) +
                                " wide with 75 outputs; got " + std::to_string(l.inputs) + " -> " +
                                std::to_string(l.width) + " -> " + std::to_string(l.outputs));
  params_ = engine::gpu::GpuBuffer(ctx, mlp.params().size() * sizeof(float), engine::gpu::GpuBuffer::Placement::DeviceOnly);
  params_.upload(std::span<const float>(mlp.params()));
  if (weights == FusedWeights::Fp16 && !ctx.info().shader_float16)
    throw engine::gpu::GpuError("VulkanFusedDecoder: fp16 weights asked for, but " + ctx.info().name + " has no shaderFloat16");
  fp16_ = weights == FusedWeights::Fp16 || (weights == FusedWeights::Auto && ctx.info().shader_float16);
  std::vector<engine::gpu::ShaderDefine> defines = {{"FUSED_INPUTS", std::to_string(l.inputs) + "u"},
                                                    {"FUSED_WIDTH", std::to_string(l.width) + "u"},
                                                    {"FUSED_HIDDEN", std::to_string(l.hidden_layers) + "u"}};
  if (fp16_) defines.push_back({"FUSED_F16_WEIGHTS", "1"});
  const auto spirv = compile_module_shader("fused_inference.comp", std::move(defines));
  pipeline_ = std::make_unique<engine::gpu::ComputePipeline>(ctx, spirv, 4, static_cast<std::uint32_t>(sizeof(FusedPush)));
  pipeline_->bind(0, params_);
}

void VulkanFusedDecoder::reserve(std::size_t n) {
  if (n <= capacity_) return;
  capacity_ = n;
  inputs_ = engine::gpu::GpuBuffer(ctx_, n * static_cast<std::size_t>(layout_.inputs) * sizeof(float));
  light_ = engine::gpu::GpuBuffer(ctx_, n * kTransferOutputs * sizeof(float));
  rgb_ = engine::gpu::GpuBuffer(ctx_, n * 3 * sizeof(float));
  pipeline_->bind(1, inputs_);
  pipeline_->bind(2, light_);
  pipeline_->bind(3, rgb_);
}

double VulkanFusedDecoder::shade(std::span<const float> inputs, std::span<const float> light, std::span<float> rgb) {
  const std::size_t n = rgb.size() / 3;
  if (rgb.size() != n * 3 || inputs.size() != n * static_cast<std::size_t>(layout_.inputs) ||
      light.size() != n * kTransferOutputs)
    throw std::invalid_argument("VulkanFusedDecoder::shade: sizes disagree (inputs " + std::to_string(inputs.size()) +
                                ", light " + std::to_string(light.size()) + ", rgb " + std::to_string(rgb.size()) + ")");
  if (n == 0) return 0.0;
  reserve(n);
  inputs_.upload(inputs);
  light_.upload(light);
  FusedPush push{static_cast<uint>(n), static_cast<uint>(layout_.inputs), static_cast<uint>(layout_.width),
                 static_cast<uint>(layout_.hidden_layers), static_cast<uint>(layout_.outputs), 0, 0, 0};
  const auto groups = static_cast<std::uint32_t>((n + kFusedGroupSize - 1) / kFusedGroupSize);
  const double ms = ctx_.submit_and_wait([&](VkCommandBuffer cmd) { pipeline_->record_dispatch(cmd, groups, 1, 1, &push); });
  rgb_.download(rgb);
  return ms;
}

}  // namespace transgi::gpu
