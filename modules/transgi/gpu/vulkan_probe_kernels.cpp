#include "gpu/vulkan_probe_kernels.h"

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
  gpu_ms_ += std::max(0.0, ms);
  return stats;
}

void VulkanProbeKernels::project(const probes::MapProjector& projector, std::span<const glm::vec3> radiance,
                                 std::span<float> out) {
  const auto& l = projector.layout();
  auto& p = projectors_[{l.width, l.height}];
  if (!p) p = std::make_unique<VulkanShProjector>(*ctx_, projector);
  gpu_ms_ += std::max(0.0, p->project(radiance, out));
}

bool VulkanProbeKernels::intersect(const engine::rt::RtScene& scene, std::span<const engine::rt::Ray> rays,
                                   std::span<engine::rt::Hit> hits, std::span<std::uint8_t> found) {
  if (!scene.assets() || !engine::gpu::GpuRtScene::traces_exactly(*scene.assets())) return false;
  if (!rt_) rt_ = std::make_unique<engine::gpu::GpuRtScene>(*ctx_);
  // A new commit (something moved) or another scene: the TLAS follows.
  if (rt_scene_ != &scene || rt_commits_ != scene.stats().top_level_commits) {
    rt_->sync(scene);
    rt_scene_ = &scene;
    rt_commits_ = scene.stats().top_level_commits;
  }
  double ms = 0;
  rt_->intersect(rays, hits, found, &ms);
  gpu_ms_ += std::max(0.0, ms);
  return true;
}

}  // namespace transgi::gpu
