#include "gpu/vulkan_probe_kernels.h"

#include <exception>
#include <stdexcept>

#include "engine/gpu/gpu_error.h"

namespace transgi::gpu {

probes::SharingStats VulkanProbeKernels::rasterize(const probes::ProbeGrid& grid, const probes::MapLayout& layout,
                                                   const std::vector<std::vector<probes::ShadedPoint>>& points,
                                                   const std::vector<const probes::DepthMap*>& own_depth,
                                                   const probes::SharingSettings& settings,
                                                   std::vector<probes::FrameSamples>& out,
                                                   std::span<const std::uint8_t> targets) {
  auto& r = rasters_[{layout.width, layout.height}];
  if (!r) r = std::make_unique<VulkanRadianceRaster>(*ctx_, layout);
  double ms = 0;
  const auto stats = r->rasterize(grid, points, own_depth, settings, out, targets, &ms);
  raster_ms_ += std::max(0.0, ms);
  return stats;
}

void VulkanProbeKernels::project(const probes::MapProjector& projector, std::span<const glm::vec3> radiance,
                                 std::span<float> out) {
  const auto& l = projector.layout();
  auto& p = projectors_[{l.width, l.height}];
  if (!p) p = std::make_unique<VulkanShProjector>(*ctx_, projector);
  project_ms_ += std::max(0.0, p->project(radiance, out));
}

bool VulkanProbeKernels::accumulate(const probes::MapLayout& layout, std::span<probes::ProbeMapState* const> states,
                                    std::span<const probes::FrameSamples* const> frames,
                                    const probes::AccumulationSettings& settings, std::span<std::uint8_t> changed,
                                    std::span<glm::vec3> filled) {
  auto& a = accumulators_[{layout.width, layout.height}];
  if (!a) a = std::make_unique<VulkanProbeAccumulator>(*ctx_, layout);
  accumulate_ms_ += std::max(0.0, a->accumulate(states, frames, settings, changed, filled));
  return true;
}

bool VulkanProbeKernels::shade_probe_rays(const engine::rt::RtScene& scene, const engine::render::LightSet& lights,
                                          std::span<const glm::vec3> origins, std::span<const int> probe_ids,
                                          std::span<const glm::vec3> directions, std::uint64_t seed, std::uint64_t sample,
                                          const probes::ProbeFeedbackSource* self, const probes::ProbeFeedbackSource* outer,
                                          std::vector<probes::ProbeRayHit>& out) {
  if (!device_shading_) return false;
  if (!shading_tried_) {
    shading_tried_ = true;
    try {
      if (VulkanProbeShading::supported(*ctx_, &shading_why_)) shading_ = std::make_unique<VulkanProbeShading>(*ctx_);
    } catch (const std::exception& e) {
      // A kernel the device cannot build: the CPU shades, and says why.
      shading_why_ = e.what();
    }
  }
  if (!shading_) return false;
  try {
    return shading_->shade(scene, lights, tracer_, origins, probe_ids, directions, seed, sample, self, outer, out);
  } catch (const engine::gpu::GpuError& e) {
    // A scene the device cannot hold (textures past its largest buffer, out
    // of memory): the CPU shades from now on, and the frame says why.
    shading_.reset();
    shading_why_ = e.what();
    return false;
  }
}

shading::TransferBatchDecoder* VulkanProbeKernels::transfer_decoder(const std::shared_ptr<const model::TransferModel>& model) {
  if (!model) return nullptr;
  if (model != decoder_model_) {
    decoder_model_ = model;
    decoder_.reset();
    try {
      decoder_ = std::make_unique<VulkanFusedDecoder>(*ctx_, model->decoder);
      decoder_why_.clear();
    } catch (const std::exception& e) {
      // A network wider than the kernels hold, or a kernel the device cannot
      // build: the CPU decodes it, and the frame says why.
      decoder_why_ = e.what();
    }
  }
  return decoder_.get();
}

std::shared_ptr<VulkanProbeKernels> make_probe_kernels(std::shared_ptr<engine::gpu::VulkanContext> context, std::string* why) {
  if (!context) return nullptr;
  try {
    return std::make_shared<VulkanProbeKernels>(std::move(context));
  } catch (const std::exception& e) {  // a kernel the device cannot build: the CPU runs them, and says why
    if (why) *why = e.what();
  }
  return nullptr;
}

std::shared_ptr<VulkanProbeKernels> make_probe_kernels(const std::string& device, std::string* why) {
  engine::gpu::GpuOptions options;
  options.device = device;
  try {
    if (auto ctx = engine::gpu::VulkanContext::create(options, why)) return make_probe_kernels(std::shared_ptr<engine::gpu::VulkanContext>(std::move(ctx)), why);
  } catch (const std::exception& e) {
    if (why) *why = e.what();
  }
  return nullptr;
}

}  // namespace transgi::gpu
