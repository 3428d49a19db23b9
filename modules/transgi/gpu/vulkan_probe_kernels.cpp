#include "gpu/vulkan_probe_kernels.h"

#include <chrono>
#include <exception>
#include <stdexcept>

#include "engine/gpu/gpu_error.h"
#include "engine/jobs/parallel_for.h"

namespace transgi::gpu {

VulkanProbeKernels::VulkanProbeKernels(std::shared_ptr<engine::gpu::VulkanContext> ctx)
    : ctx_(std::move(ctx)), tracer_(*ctx_), shading_(std::make_unique<VulkanProbeShading>(*ctx_)),
      name_(engine::gpu::describe(ctx_->info())) {}

VulkanProbeKernels::LightStages VulkanProbeKernels::light_stages(const probes::MapProjector& projector) {
  const auto& layout = projector.layout();
  const std::pair<int, int> size{layout.width, layout.height};
  auto& r = rasters_[size];
  if (!r) r = std::make_unique<VulkanRadianceRaster>(*ctx_, layout);
  auto& a = accumulators_[size];
  if (!a) a = std::make_unique<VulkanProbeAccumulator>(*ctx_, layout);
  auto& p = projectors_[size];
  if (!p) p = std::make_unique<VulkanShProjector>(*ctx_, projector);
  return {r.get(), a.get(), p.get()};
}

void VulkanProbeKernels::prepare_own_depth(const probes::ProbeGrid& grid, std::span<const int> batch,
                                           std::span<probes::ProbeMapState* const> states,
                                           const probes::AccumulationSettings& accumulation, const probes::MapLayout& layout,
                                           const VulkanMapStore& maps) {
  std::vector<std::size_t> tracing_index(static_cast<std::size_t>(grid.count()), 0);
  for (std::size_t j = 0; j < shaded_probes_.size(); ++j) tracing_index[static_cast<std::size_t>(shaded_probes_[j])] = j;
  std::vector<OwnDepthProbeGpu> records(batch.size());
  for (std::size_t i = 0; i < batch.size(); ++i)
    records[i] = {static_cast<uint>(batch[i]), static_cast<uint>(tracing_index[static_cast<std::size_t>(batch[i])] * shaded_rays_per_probe_),
                  states[i]->depth.unit, probes::own_depth_blend(*states[i], accumulation)};
  if (!own_depth_) own_depth_ = std::make_unique<VulkanProbeOwnDepth>(*ctx_);
  own_depth_->prepare(records, shading_->hits_on_device(), shading_->directions_on_device(), maps.depth(), shaded_rays_per_probe_,
                      layout);
}

namespace {
// The batch's own depth on the host, after the kernel updated the store's
// copies the same way: the store holds the host's new versions.
void update_own_depths_as_the_device(std::span<const int> batch, std::span<probes::ProbeMapState* const> states,
                                     const std::vector<std::vector<probes::ShadedPoint>>& points, const probes::MapLayout& layout,
                                     const probes::AccumulationSettings& accumulation, VulkanMapStore& maps) {
  probes::update_own_depths(batch, states, points, layout, accumulation);
  for (std::size_t k = 0; k < batch.size(); ++k) maps.adopt_depth(static_cast<std::size_t>(batch[k]), states[k]->depth.version);
}

// Which probes of the grid the batch updates, and their map slots.
struct BatchTargets {
  std::vector<std::uint8_t> targets;    // per grid probe
  std::vector<std::uint32_t> frame_maps;  // per batch probe
};
BatchTargets batch_targets(const probes::ProbeGrid& grid, std::span<const int> batch) {
  BatchTargets t{std::vector<std::uint8_t>(static_cast<std::size_t>(grid.count()), 0), std::vector<std::uint32_t>(batch.size())};
  for (std::size_t i = 0; i < batch.size(); ++i) {
    t.targets[static_cast<std::size_t>(batch[i])] = 1;
    t.frame_maps[i] = static_cast<std::uint32_t>(batch[i]);
  }
  return t;
}

// Whether each batch state's depth map is the one own_depth lists for its
// probe (the field's own): only then may a kernel update the copy the
// raster reads in place.
bool batch_depth_is_own(std::span<const int> batch, std::span<probes::ProbeMapState* const> states,
                        const std::vector<const probes::DepthMap*>& own_depth) {
  for (std::size_t i = 0; i < batch.size(); ++i)
    if (own_depth[static_cast<std::size_t>(batch[i])] != &states[i]->depth) return false;
  return true;
}
}  // namespace

void VulkanProbeKernels::record_light(VkCommandBuffer cmd, const LightStages& stages, bool own_depth, std::size_t probes) const {
  stages.raster->record(cmd, own_depth ? own_depth_.get() : nullptr);
  ctx_->mark_stage(cmd);
  engine::gpu::record_compute_barrier(cmd);
  stages.accumulator->record(cmd);
  ctx_->mark_stage(cmd);
  engine::gpu::record_compute_barrier(cmd);
  stages.projector->record(cmd, stages.accumulator->filled_on_device(), probes);
}

void VulkanProbeKernels::take_light_stage_ms(std::size_t first) {
  const std::vector<double>& stage_ms = ctx_->last_stage_ms();
  if (stage_ms.size() != first + 3) return;
  raster_ms_ += stage_ms[first];
  accumulate_ms_ += stage_ms[first + 1];
  project_ms_ += stage_ms[first + 2];
}

probes::SharingStats VulkanProbeKernels::share_accumulate_project(
    const probes::ProbeGrid& grid, const probes::MapProjector& projector,
    const std::vector<std::vector<probes::ShadedPoint>>& points, const std::vector<const probes::DepthMap*>& own_depth,
    const probes::SharingSettings& sharing, std::span<const int> batch, std::span<probes::ProbeMapState* const> states,
    probes::ProbeMapStore* store, const probes::AccumulationSettings& accumulation, std::span<std::uint8_t> changed, std::span<float> sh,
    probes::ShareAccumulateTimes& times) {
  using Clock = std::chrono::steady_clock;
  const auto ms_since = [](Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); };
  const auto t0 = Clock::now();
  const auto& layout = projector.layout();
  const LightStages stages = light_stages(projector);
  const BatchTargets bt = batch_targets(grid, batch);
  auto* maps = dynamic_cast<VulkanMapStore*>(store);
  if (store && !maps) throw std::invalid_argument("VulkanProbeKernels: a map store from another backend");
  // The points are the last shading's rays where they match (the field
  // updates right after it shades): made on the device, not sent again.
  const VulkanRadianceRaster::DevicePoints rays{&shading_->hits_on_device(), &shading_->directions_on_device(), shaded_probes_,
                                                shaded_rays_per_probe_};
  const bool rays_on_device = shaded_rays_per_probe_ > 0 && VulkanRadianceRaster::takes_device_points(points, rays);
  // The batch's own depth: where its rays are on the device and the field
  // keeps its maps there, updated in the store's copies by a kernel (and
  // the host's by the same arithmetic after the submission), so that no
  // updated map goes up; else on the host first, the changed maps sent.
  const bool own_depth_on_device = maps && rays_on_device && batch_depth_is_own(batch, states, own_depth);
  if (!own_depth_on_device) probes::update_own_depths(batch, states, points, layout, accumulation);
  stages.raster->prepare(grid, points, own_depth, sharing, bt.targets, maps, shaded_rays_per_probe_ > 0 ? &rays : nullptr);
  if (own_depth_on_device) prepare_own_depth(grid, batch, states, accumulation, layout, *maps);
  if (shaded_brief_ && !stages.raster->points_made_on_device())
    throw std::logic_error("VulkanProbeKernels: the points are not the last shading's rays, whose hits came back brief "
                           "(set_brief_hits(false) for points of the caller's own)");
  stages.accumulator->prepare(states, stages.raster->samples_on_device(), bt.frame_maps, accumulation, maps);
  times.share_ms = ms_since(t0);
  const auto t1 = Clock::now();
  // One submission, a timestamp after each stage: the samples and the
  // filled maps never leave the device.
  ctx_->submit_and_wait([&](VkCommandBuffer cmd) { record_light(cmd, stages, own_depth_on_device, states.size()); });
  take_light_stage_ms(0);
  const probes::SharingStats stats = stages.raster->finish(nullptr);
  stages.accumulator->finish(states, changed, {});
  stages.projector->read(sh);
  if (own_depth_on_device) update_own_depths_as_the_device(batch, states, points, layout, accumulation, *maps);
  times.accumulate_ms = ms_since(t1);
  return stats;
}

probes::SharingStats VulkanProbeKernels::shade_and_light(const probes::ProbeRayRequest& rays, const probes::ProbeRayConsumer& consume,
                                                         const probes::ProbeLightRequest& light) {
  using Clock = std::chrono::steady_clock;
  const auto ms_since = [](Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); };
  auto* maps = dynamic_cast<VulkanMapStore*>(light.store);
  if (light.store && !maps) throw std::invalid_argument("VulkanProbeKernels: a map store from another backend");
  // One submission needs the maps and the own depth kept on the device;
  // else the two stages in turn, each as it runs alone.
  if (!maps || !batch_depth_is_own(light.batch, light.states, *light.own_depth)) return ProbeKernels::shade_and_light(rays, consume, light);
  const auto t0 = Clock::now();
  shaded_rays_per_probe_ = 0;  // the device's hits are this batch's only once it is prepared
  shaded_brief_ = false;
  if (!shading_->prepare(*rays.scene, *rays.lights, tracer_, rays.origins, rays.probe_ids, rays.directions, rays.seed, rays.sample,
                         rays.self->lit ? rays.self : nullptr, rays.outer))
    throw engine::gpu::GpuError("the Vulkan backend traces only scenes built with their assets (RtScene::assets())");
  const std::size_t m = rays.directions.size();
  shaded_probes_.assign(rays.probe_ids.begin(), rays.probe_ids.end());
  shaded_rays_per_probe_ = static_cast<std::uint32_t>(m);
  shaded_brief_ = brief_hits_;

  // The light stages over the rays' points, which exist on the host only
  // once the submission ran.
  const probes::ProbeGrid& grid = *light.grid;
  const auto& layout = light.projector->layout();
  const LightStages stages = light_stages(*light.projector);
  const BatchTargets bt = batch_targets(grid, light.batch);
  const VulkanRadianceRaster::DevicePoints points{&shading_->hits_on_device(), &shading_->directions_on_device(), shaded_probes_,
                                                  shaded_rays_per_probe_};
  stages.raster->prepare_from_rays(grid, *light.own_depth, *light.sharing, bt.targets, maps, points);
  prepare_own_depth(grid, light.batch, light.states, *light.accumulation, layout, *maps);
  stages.accumulator->prepare(light.states, stages.raster->samples_on_device(), bt.frame_maps, *light.accumulation, maps);
  light.times->share_ms = ms_since(t0);
  // The probe rays, then the light they carry into the probes: one
  // submission, a timestamp after each stage.
  ctx_->submit_and_wait([&](VkCommandBuffer cmd) {
    shading_->record(cmd);
    ctx_->mark_stage(cmd);
    engine::gpu::record_compute_barrier(cmd);
    record_light(cmd, stages, true, light.states.size());
  });
  if (ctx_->last_stage_ms().size() == 4) shading_->add_gpu_ms(ctx_->last_stage_ms()[0]);
  take_light_stage_ms(1);
  std::vector<probes::ProbeRayHit> out;
  shading_->read(out, nullptr, brief_hits_, rays.emission);
  engine::jobs::parallel_for(0, static_cast<int>(rays.origins.size()), 1, [&](int b, int e) {
    for (int j = b; j < e; ++j)
      for (std::size_t i = 0; i < m; ++i) consume(j, static_cast<int>(i), out[static_cast<std::size_t>(j) * m + i]);
  });
  // The submission and the consumer are neither sharing nor accumulation:
  // the caller counts them as its rays' time.
  const auto t2 = Clock::now();
  const probes::SharingStats stats = stages.raster->finish(nullptr);
  stages.accumulator->finish(light.states, light.changed, {});
  stages.projector->read(light.sh);
  update_own_depths_as_the_device(light.batch, light.states, *light.points, layout, *light.accumulation, *maps);
  light.times->accumulate_ms = ms_since(t2);
  return stats;
}

std::unique_ptr<probes::ProbeMapStore> VulkanProbeKernels::make_map_store(const probes::MapLayout& layout, int probes) {
  return std::make_unique<VulkanMapStore>(ctx_, layout, probes);
}

void VulkanProbeKernels::shade_probe_rays(const engine::rt::RtScene& scene, const engine::render::LightSet& lights,
                                          std::span<const glm::vec3> origins, std::span<const int> probe_ids,
                                          std::span<const glm::vec3> directions, std::uint64_t seed, std::uint64_t sample,
                                          const probes::ProbeFeedbackSource& self, const probes::ProbeFeedbackSource* outer,
                                          const probes::ProbeRayConsumer& consume) {
  std::vector<probes::ProbeRayHit> out;
  shaded_rays_per_probe_ = 0;  // the device's hits are this batch's only once it is shaded
  shaded_brief_ = false;
  // The kernel reads no field it is not given: a field with no light yet is left out.
  if (!shading_->shade(scene, lights, tracer_, origins, probe_ids, directions, seed, sample, self.lit ? &self : nullptr,
                       outer, out, nullptr, brief_hits_))
    throw engine::gpu::GpuError("the Vulkan backend traces only scenes built with their assets (RtScene::assets())");
  const std::size_t m = directions.size();
  shaded_probes_.assign(probe_ids.begin(), probe_ids.end());
  shaded_rays_per_probe_ = static_cast<std::uint32_t>(m);
  shaded_brief_ = brief_hits_;
  engine::jobs::parallel_for(0, static_cast<int>(origins.size()), 1, [&](int b, int e) {
    for (int j = b; j < e; ++j)
      for (std::size_t i = 0; i < m; ++i) consume(j, static_cast<int>(i), out[static_cast<std::size_t>(j) * m + i]);
  });
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

std::shared_ptr<VulkanProbeKernels> make_probe_kernels(std::shared_ptr<engine::gpu::VulkanContext> context,
                                                       probes::BackendFallback* reason, std::string* why) {
  const auto refuse = [&](probes::BackendFallback r, const std::string& w) {
    if (reason) *reason = r;
    if (why) *why = w;
    return nullptr;
  };
  if (!context) return refuse(probes::BackendFallback::NoDevice, "no Vulkan context");
  std::string missing;
  if (!VulkanProbeShading::supported(*context, &missing)) return refuse(probes::BackendFallback::MissingCapability, missing);
  try {
    auto kernels = std::make_shared<VulkanProbeKernels>(std::move(context));
    if (reason) *reason = probes::BackendFallback::None;
    return kernels;
  } catch (const std::exception& e) {  // a kernel the device cannot build
    return refuse(probes::BackendFallback::KernelBuildFailed, e.what());
  }
}

std::shared_ptr<VulkanProbeKernels> make_probe_kernels(const std::string& device, probes::BackendFallback* reason,
                                                       std::string* why) {
  engine::gpu::GpuOptions options;
  options.device = device;
  std::shared_ptr<engine::gpu::VulkanContext> context;
  try {
    context = engine::gpu::VulkanContext::create(options, why);
  } catch (const std::exception& e) {
    if (why) *why = e.what();
  }
  if (!context) {
    if (reason) *reason = probes::BackendFallback::NoDevice;
    return nullptr;
  }
  return make_probe_kernels(std::move(context), reason, why);
}

}  // namespace transgi::gpu
