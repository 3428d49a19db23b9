#pragma once
// The fused transfer inference as a Vulkan compute kernel
// (shaders/fused_inference.comp, fused_inference_tiled.comp): the same contract as
// shading::FusedDecoder::shade_tile, for any number of points at once.
// The CPU's scalar backend is its oracle (tests/transgi/gpu_fused_test.cpp).
#include <memory>
#include <span>
#include <string>

#include "engine/gpu/compute_pipeline.h"
#include "engine/gpu/gpu_buffer.h"
#include "engine/gpu/vulkan_context.h"
#include "model/mlp.h"
#include "transgi_shared.h"
#include "gpu/vulkan_probe_lights.h"
#include "shading/probe_light_maker.h"
#include "shading/transfer_batch_decoder.h"

namespace transgi::gpu {

// How the kernel holds the weights it stages in shared memory.
enum class FusedWeights {
  Auto,  // fp16 where the device has shaderFloat16, else fp32
  Fp32,
  Fp16,  // GpuError on a device without shaderFloat16
};

// Which kernel decodes. Both follow the same contract and the same CPU oracle.
enum class FusedKernel {
  Auto,      // Tiled where the device has the 32 KB of shared memory it needs, else PerPoint
  PerPoint,  // fused_inference.comp: one invocation per point; the simple twin, and the one with fp16 weights
  Tiled,     // fused_inference_tiled.comp: 64 points per workgroup in shared memory; fp32 weights
};

class VulkanFusedDecoder : public shading::TransferBatchDecoder, public shading::ProbeLightMaker {
 public:
  // Throws std::invalid_argument for a layout the kernel cannot hold (wider
  // than kFusedMaxWidth, or not 75 outputs), GpuError for Vulkan failures.
  // `weights` applies to the per-point kernel; the tiled one reads fp32
  // (GpuError if Fp16 is asked of it).
  VulkanFusedDecoder(engine::gpu::VulkanContext& ctx, const model::Mlp& mlp, FusedWeights weights = FusedWeights::Auto,
                     FusedKernel kernel = FusedKernel::Auto);
  [[nodiscard]] bool fp16_weights() const { return fp16_; }
  [[nodiscard]] bool tiled() const { return tiled_; }

  // rgb (n x 3) = sum_o decoder(inputs[i])[o] * light[i][o]; inputs n x 16,
  // light n x 75. Returns the kernel's GPU time in ms (-1 without timestamps).
  double shade(std::span<const float> inputs, std::span<const float> light, std::span<float> rgb);

  // shading::TransferBatchDecoder: the frame's batch, written in place.
  [[nodiscard]] int inputs() const override { return layout_.inputs; }
  Batch begin(std::size_t n, bool second) override;
  double run(glm::vec3* out, glm::vec3* out2) override;
  // The lights made on this device (VulkanProbeLights) where the frame
  // hands over points instead; null after set_probes failed to make the
  // kernel (why: probe_lights_why()).
  shading::ProbeLightMaker* probe_lights() override { return this; }
  bool set_probes(std::span<const probes::ProbeField* const> fields, int rotations, const ShOf& sh) override;
  std::span<Point> points(std::size_t n) override;
  [[nodiscard]] const std::string& probe_lights_why() const { return lights_why_; }

 private:
  void reserve(std::size_t n, bool second);
  double dispatch(std::size_t n, bool second);
  [[nodiscard]] FusedPush push_for(std::size_t n, bool second) const;
  [[nodiscard]] std::uint32_t groups_for(std::size_t n) const;

  engine::gpu::VulkanContext& ctx_;
  model::MlpLayout layout_;
  bool fp16_ = false;
  bool tiled_ = false;
  engine::gpu::GpuBuffer params_;
  engine::gpu::GpuBuffer inputs_, light_, rgb_, light2_, rgb2_;
  std::size_t capacity_ = 0;
  std::size_t batch_points_ = 0;
  bool batch_second_ = false;
  std::unique_ptr<engine::gpu::ComputePipeline> pipeline_;
  // The device-made lights: the kernel, whether this batch's points are
  // waiting for it, and device-local light buffers it writes and the decoder
  // reads (the mapped ones above are for lights the CPU writes).
  std::unique_ptr<VulkanProbeLights> lights_;
  bool lights_failed_ = false, points_pending_ = false;
  std::string lights_why_;
  engine::gpu::GpuBuffer device_light_, device_light2_;
};

}  // namespace transgi::gpu
