#include "gpu/vulkan_fused_decoder.h"

#include <algorithm>
#include <stdexcept>
#include <vector>
#include <string>

#include "engine/gpu/gpu_error.h"
#include "engine/jobs/parallel_for.h"
#include "gpu/shader_path.h"
#include "transgi_shared.h"

namespace transgi::gpu {

namespace {

// The tiled kernel's weights: per layer transposed to in x out with each
// row of outputs zero-padded to a multiple of 4, then the biases padded
// likewise (fused_inference_tiled.comp reads them as vec4s).
std::vector<float> fused_tiled_params(const model::Mlp& mlp) {
  const model::MlpLayout& l = mlp.layout();
  std::vector<float> out;
  for (int layer = 0; layer < l.layer_count(); ++layer) {
    const std::size_t w = l.weight_offset(layer), b = l.bias_offset(layer);
    const auto n_in = static_cast<std::size_t>(l.in_of(layer)), n_out = static_cast<std::size_t>(l.out_of(layer));
    const std::size_t padded = (n_out + 3) / 4 * 4, first = out.size();
    out.resize(first + (n_in + 1) * padded, 0.0f);
    for (std::size_t o = 0; o < n_out; ++o) {
      for (std::size_t k = 0; k < n_in; ++k) out[first + k * padded + o] = mlp.params()[w + o * n_in + k];
      out[first + n_in * padded + o] = mlp.params()[b + o];
    }
  }
  return out;
}

}  // namespace

VulkanFusedDecoder::VulkanFusedDecoder(engine::gpu::VulkanContext& ctx, const model::Mlp& mlp, FusedWeights weights,
                                       FusedKernel kernel)
    : ctx_(ctx), layout_(mlp.layout()) {
  const auto& l = layout_;
  if (l.outputs != static_cast<int>(kTransferOutputs) || l.width > static_cast<int>(kFusedMaxWidth) ||
      l.inputs > static_cast<int>(kFusedMaxWidth) || l.width < 1 || l.inputs < 1)
    throw std::invalid_argument("VulkanFusedDecoder: the kernel holds layers up to " + std::to_string(kFusedMaxWidth) +
                                " wide with 75 outputs; got " + std::to_string(l.inputs) + " -> " +
                                std::to_string(l.width) + " -> " + std::to_string(l.outputs));
  const std::uint32_t tiled_shared = kFusedMaxWidth * kFusedTiledPoints * sizeof(float);
  tiled_ = kernel == FusedKernel::Tiled ||
           (kernel == FusedKernel::Auto && weights != FusedWeights::Fp16 && ctx.info().max_shared_memory >= tiled_shared);
  if (tiled_ && weights == FusedWeights::Fp16)
    throw engine::gpu::GpuError("VulkanFusedDecoder: the tiled kernel reads fp32 weights; fp16 asked for");
  if (tiled_ && ctx.info().max_shared_memory < tiled_shared)
    throw engine::gpu::GpuError("VulkanFusedDecoder: the tiled kernel needs " + std::to_string(tiled_shared) +
                                " bytes of shared memory; " + ctx.info().name + " has " +
                                std::to_string(ctx.info().max_shared_memory));
  if (weights == FusedWeights::Fp16 && !ctx.info().shader_float16)
    throw engine::gpu::GpuError("VulkanFusedDecoder: fp16 weights asked for, but " + ctx.info().name + " has no shaderFloat16");
  fp16_ = !tiled_ && (weights == FusedWeights::Fp16 || (weights == FusedWeights::Auto && ctx.info().shader_float16));
  const std::vector<float> params = tiled_ ? fused_tiled_params(mlp) : mlp.params();
  params_ = engine::gpu::GpuBuffer(ctx, params.size() * sizeof(float), engine::gpu::GpuBuffer::Placement::DeviceOnly);
  params_.upload(std::span<const float>(params));
  std::vector<engine::gpu::ShaderDefine> defines = {{"FUSED_INPUTS", std::to_string(l.inputs) + "u"},
                                                    {"FUSED_WIDTH", std::to_string(l.width) + "u"},
                                                    {"FUSED_HIDDEN", std::to_string(l.hidden_layers) + "u"}};
  if (fp16_) defines.push_back({"FUSED_F16_WEIGHTS", "1"});
  const auto spirv = compile_module_shader(tiled_ ? "fused_inference_tiled.comp" : "fused_inference.comp", std::move(defines));
  pipeline_ = std::make_unique<engine::gpu::ComputePipeline>(ctx, spirv, 6, static_cast<std::uint32_t>(sizeof(FusedPush)));
  pipeline_->bind(0, params_);
  reserve(1, false);
}

void VulkanFusedDecoder::reserve(std::size_t n, bool second) {
  if (n > capacity_) {
    capacity_ = n;
    inputs_ = engine::gpu::GpuBuffer(ctx_, n * static_cast<std::size_t>(layout_.inputs) * sizeof(float));
    light_ = engine::gpu::GpuBuffer(ctx_, n * kTransferOutputs * sizeof(float));
    rgb_ = engine::gpu::GpuBuffer(ctx_, n * 3 * sizeof(float));
    pipeline_->bind(1, inputs_);
    pipeline_->bind(2, light_);
    pipeline_->bind(3, rgb_);
  }
  // The second light's buffers: a placeholder until one is asked for (every
  // binding needs a buffer), then grown with the rest.
  const std::size_t n2 = second ? capacity_ : 1;
  if (light2_.handle() == VK_NULL_HANDLE || light2_.size() < n2 * kTransferOutputs * sizeof(float)) {
    light2_ = engine::gpu::GpuBuffer(ctx_, n2 * kTransferOutputs * sizeof(float));
    rgb2_ = engine::gpu::GpuBuffer(ctx_, n2 * 3 * sizeof(float));
    pipeline_->bind(4, light2_);
    pipeline_->bind(5, rgb2_);
  }
}

FusedPush VulkanFusedDecoder::push_for(std::size_t n, bool second) const {
  return {static_cast<uint>(n), static_cast<uint>(layout_.inputs), static_cast<uint>(layout_.width),
          static_cast<uint>(layout_.hidden_layers), static_cast<uint>(layout_.outputs), second ? 1u : 0u, 0, 0};
}

std::uint32_t VulkanFusedDecoder::groups_for(std::size_t n) const {
  const std::size_t per_group = tiled_ ? kFusedTiledPoints : kFusedGroupSize;
  return static_cast<std::uint32_t>((n + per_group - 1) / per_group);
}

double VulkanFusedDecoder::dispatch(std::size_t n, bool second) {
  const FusedPush push = push_for(n, second);
  return ctx_.submit_and_wait([&](VkCommandBuffer cmd) { pipeline_->record_dispatch(cmd, groups_for(n), 1, 1, &push); });
}

bool VulkanFusedDecoder::set_probes(std::span<const probes::ProbeField* const> fields, int rotations, const ShOf& sh) {
  if (lights_failed_) return false;
  if (!lights_) {
    try {
      lights_ = std::make_unique<VulkanProbeLights>(ctx_);
    } catch (const std::exception& e) {
      lights_failed_ = true;
      lights_why_ = e.what();
      return false;
    }
  }
  return lights_->set_probes(fields, rotations, sh, &lights_why_);
}

std::span<shading::ProbeLightMaker::Point> VulkanFusedDecoder::points(std::size_t n) {
  if (!lights_) throw std::logic_error("VulkanFusedDecoder::points before a successful set_probes");
  points_pending_ = true;
  return lights_->points(n);
}

double VulkanFusedDecoder::shade(std::span<const float> inputs, std::span<const float> light, std::span<float> rgb) {
  const std::size_t n = rgb.size() / 3;
  if (rgb.size() != n * 3 || inputs.size() != n * static_cast<std::size_t>(layout_.inputs) ||
      light.size() != n * kTransferOutputs)
    throw std::invalid_argument("VulkanFusedDecoder::shade: sizes disagree (inputs " + std::to_string(inputs.size()) +
                                ", light " + std::to_string(light.size()) + ", rgb " + std::to_string(rgb.size()) + ")");
  if (n == 0) return 0.0;
  reserve(n, false);
  inputs_.upload(inputs);
  light_.upload(light);
  const double ms = dispatch(n, false);
  rgb_.download(rgb);
  return ms;
}

shading::TransferBatchDecoder::Batch VulkanFusedDecoder::begin(std::size_t n, bool second) {
  reserve(std::max<std::size_t>(n, 1), second);
  batch_points_ = n;
  batch_second_ = second;
  points_pending_ = false;
  return {inputs_.mapped_as<float>(n * static_cast<std::size_t>(layout_.inputs)), light_.mapped_as<float>(n * kTransferOutputs),
          second ? light2_.mapped_as<float>(n * kTransferOutputs) : std::span<float>()};
}

double VulkanFusedDecoder::run(glm::vec3* out, glm::vec3* out2) {
  const std::size_t n = batch_points_;
  if (n == 0) return 0.0;
  if (out2 && !batch_second_) throw std::invalid_argument("VulkanFusedDecoder::run: a second output, but begin() asked for no second light");
  double ms = 0.0;
  if (points_pending_) {
    // The lights from the probes on the device, into device-local buffers
    // the decoder reads, in the same submission.
    points_pending_ = false;
    const std::size_t bytes = n * kTransferOutputs * sizeof(float);
    const auto device_only = engine::gpu::GpuBuffer::Placement::DeviceOnly;
    if (device_light_.handle() == VK_NULL_HANDLE || device_light_.size() < bytes) device_light_ = engine::gpu::GpuBuffer(ctx_, bytes, device_only);
    const std::size_t bytes2 = batch_second_ ? bytes : 4;
    if (device_light2_.handle() == VK_NULL_HANDLE || device_light2_.size() < bytes2) device_light2_ = engine::gpu::GpuBuffer(ctx_, bytes2, device_only);
    pipeline_->bind(2, device_light_);
    pipeline_->bind(4, batch_second_ ? device_light2_ : light2_);
    const FusedPush push = push_for(n, batch_second_);
    ms = ctx_.submit_and_wait([&](VkCommandBuffer cmd) {
      lights_->record(cmd, n, batch_second_, device_light_, device_light2_);
      engine::gpu::record_compute_barrier(cmd);
      pipeline_->record_dispatch(cmd, groups_for(n), 1, 1, &push);
    });
    pipeline_->bind(2, light_);
    pipeline_->bind(4, light2_);
  } else {
    ms = dispatch(n, batch_second_);
  }
  static_assert(sizeof(glm::vec3) == 3 * sizeof(float));
  const auto rgb = rgb_.mapped_as<const float>(n * 3);
  const auto rgb2 = batch_second_ ? rgb2_.mapped_as<const float>(n * 3) : std::span<const float>();
  engine::jobs::parallel_for<std::size_t>(0, n, 8192, [&](std::size_t b, std::size_t e) {
    std::copy(rgb.begin() + static_cast<std::ptrdiff_t>(3 * b), rgb.begin() + static_cast<std::ptrdiff_t>(3 * e), &out[b].x);
    if (out2) std::copy(rgb2.begin() + static_cast<std::ptrdiff_t>(3 * b), rgb2.begin() + static_cast<std::ptrdiff_t>(3 * e), &out2[b].x);
  });
  return ms;
}

}  // namespace transgi::gpu
