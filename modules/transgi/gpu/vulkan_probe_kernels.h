#pragma once
// The probe field's stages on a Vulkan device (probes::ProbeKernels): the
// probe rays traced and shaded, the radiance raster, the accumulation and
// the SH projection. One instance serves every field of a scene; the
// kernels for each map size are made on first use.
#include <map>
#include <memory>
#include <string>
#include <utility>

#include "engine/gpu/gpu_ray_tracer.h"
#include "engine/gpu/vulkan_context.h"
#include "gpu/vulkan_fused_decoder.h"
#include "gpu/vulkan_probe_accumulator.h"
#include "gpu/vulkan_probe_own_depth.h"
#include "gpu/vulkan_probe_shading.h"
#include "gpu/vulkan_radiance_raster.h"
#include "model/transfer_model.h"
#include "gpu/vulkan_sh_projector.h"
#include "probes/probe_kernels.h"

namespace transgi::gpu {

class VulkanProbeKernels : public probes::ProbeKernels {
 public:
  // Builds every stage's kernels; throws where the device cannot
  // (make_probe_kernels checks the capabilities first and says why).
  explicit VulkanProbeKernels(std::shared_ptr<engine::gpu::VulkanContext> ctx);

  // Throws engine::gpu::GpuError where the device cannot hold the scene (its
  // textures past the largest buffer, out of memory) or the scene was made
  // without its assets (nothing to upload): the owner then runs the CPU
  // backend whole.
  void shade_probe_rays(const engine::rt::RtScene& scene, const engine::render::LightSet& lights,
                        std::span<const glm::vec3> origins, std::span<const int> probe_ids,
                        std::span<const glm::vec3> directions, std::uint64_t seed, std::uint64_t sample,
                        const probes::ProbeFeedbackSource& self, const probes::ProbeFeedbackSource* outer,
                        const probes::ProbeRayConsumer& consume) override;
  // The raster, the accumulation and the projection in one submission:
  // the samples and the filled maps stay on the device.
  probes::SharingStats share_accumulate_project(const probes::ProbeGrid& grid, const probes::MapProjector& projector,
                                                const std::vector<std::vector<probes::ShadedPoint>>& points,
                                                const std::vector<const probes::DepthMap*>& own_depth,
                                                const probes::SharingSettings& sharing, std::span<const int> batch,
                                                std::span<probes::ProbeMapState* const> states, probes::ProbeMapStore* store,
                                                const probes::AccumulationSettings& accumulation,
                                                std::span<std::uint8_t> changed, std::span<float> sh,
                                                probes::ShareAccumulateTimes& times) override;
  // Where the field keeps its maps here (a VulkanMapStore) and its own
  // depth is the batch's: the probe rays, the own depth, the raster, the
  // accumulation and the projection in one submission; the rays' hits are
  // handed to `consume` after it. Else the two stages in turn.
  probes::SharingStats shade_and_light(const probes::ProbeRayRequest& rays, const probes::ProbeRayConsumer& consume,
                                       const probes::ProbeLightRequest& light) override;
  // The maps on this device between updates (VulkanMapStore).
  [[nodiscard]] std::unique_ptr<probes::ProbeMapStore> make_map_store(const probes::MapLayout& layout, int probes) override;
  engine::rt::RayBatchTracer* tracer() override { return &tracer_; }
  // Whether shade_probe_rays hands over brief hits (the default): each
  // ray's flags, distance and emission, not its position, normal and
  // radiance, which stay on the device for the raster's points. The host's
  // points are then only their counts, and share_accumulate_project throws
  // std::logic_error for points that are not the last shading's rays. Off:
  // whole hits, for a caller that builds its own points.
  void set_brief_hits(bool brief) { brief_hits_ = brief; }
  // The real-time frame's transfer decoder on this device, made for
  // `model`'s network when first asked (and again for another model); null
  // where the kernel cannot hold that network, so the CPU decodes.
  shading::TransferBatchDecoder* transfer_decoder(const std::shared_ptr<const model::TransferModel>& model);
  // Why the last transfer_decoder() returned null (empty when it did not).
  [[nodiscard]] const std::string& transfer_decoder_why() const { return decoder_why_; }
  [[nodiscard]] const char* name() const override { return name_.c_str(); }
  // GPU milliseconds per stage since the last call (timestamps).
  struct StageMs {
    double trace = 0, raster = 0, projection = 0, shading = 0, accumulation = 0;
    [[nodiscard]] double total() const { return trace + raster + projection + shading + accumulation; }
  };
  // Submissions and bytes between host and device since the last call
  // (engine::gpu::GpuTraffic; all of this context's users).
  engine::gpu::GpuTraffic take_traffic() {
    const engine::gpu::GpuTraffic now = ctx_->traffic(), since = now - traffic_taken_;
    traffic_taken_ = now;
    return since;
  }
  StageMs take_stage_ms() {
    StageMs s{tracer_.take_device_ms(), raster_ms_, project_ms_, shading_->take_gpu_ms(), accumulate_ms_};
    raster_ms_ = project_ms_ = accumulate_ms_ = 0.0;
    return s;
  }

 private:
  // The last shade_probe_rays batch, whose hits stay on the device for the
  // raster (VulkanRadianceRaster::DevicePoints): its probes and rays each.
  std::vector<int> shaded_probes_;
  std::uint32_t shaded_rays_per_probe_ = 0;
  bool brief_hits_ = true;     // shade_probe_rays reads back ProbeRayBriefGpu, not the whole hits
  bool shaded_brief_ = false;  // the last batch's hits came back brief
  std::shared_ptr<engine::gpu::VulkanContext> ctx_;
  std::map<std::pair<int, int>, std::unique_ptr<VulkanRadianceRaster>> rasters_;
  std::map<std::pair<int, int>, std::unique_ptr<VulkanShProjector>> projectors_;
  std::map<std::pair<int, int>, std::unique_ptr<VulkanProbeAccumulator>> accumulators_;
  std::unique_ptr<VulkanProbeOwnDepth> own_depth_;  // made on first use
  // The light's stages for a map size, made on first use.
  struct LightStages {
    VulkanRadianceRaster* raster;
    VulkanProbeAccumulator* accumulator;
    VulkanShProjector* projector;
  };
  LightStages light_stages(const probes::MapProjector& projector);
  // The own-depth kernel prepared for the batch, its rays the last shading's.
  void prepare_own_depth(const probes::ProbeGrid& grid, std::span<const int> batch, std::span<probes::ProbeMapState* const> states,
                         const probes::AccumulationSettings& accumulation, const probes::MapLayout& layout, const VulkanMapStore& maps);
  // The raster (with the own depth first), the accumulation and the
  // projection of `probes` maps into `cmd`, a timestamp after the first two.
  void record_light(VkCommandBuffer cmd, const LightStages& stages, bool own_depth, std::size_t probes) const;
  // The three light stages' device times, from the last submission's stage `first` on.
  void take_light_stage_ms(std::size_t first);
  engine::gpu::GpuRayTracer tracer_;
  std::shared_ptr<const model::TransferModel> decoder_model_;  // kept alive: the cache's key
  std::unique_ptr<VulkanFusedDecoder> decoder_;
  std::string decoder_why_;
  std::unique_ptr<VulkanProbeShading> shading_;
  std::string name_;
  double raster_ms_ = 0.0, project_ms_ = 0.0, accumulate_ms_ = 0.0;
  engine::gpu::GpuTraffic traffic_taken_;
};

// The Vulkan kernels on the chosen device (empty: ENGINE_GPU_DEVICE, then
// the ranked default), or null where the device cannot run every stage:
// *reason says which check failed and *why how (the caller then runs the
// CPU backend whole).
std::shared_ptr<VulkanProbeKernels> make_probe_kernels(const std::string& device, probes::BackendFallback* reason,
                                                       std::string* why);
// The same on a context the caller made (a host engine's device).
std::shared_ptr<VulkanProbeKernels> make_probe_kernels(std::shared_ptr<engine::gpu::VulkanContext> context,
                                                       probes::BackendFallback* reason, std::string* why);

}  // namespace transgi::gpu
