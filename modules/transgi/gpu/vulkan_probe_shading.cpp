#include "gpu/vulkan_probe_shading.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>

#include "engine/gpu/gpu_error.h"
#include "engine/jobs/parallel_for.h"
#include "gpu/probe_grid_gpu.h"
#include "gpu/shader_path.h"
#include "gpu/vulkan_map_store.h"
#include "probe_shading_shared.h"
#include "rt_shared.h"

namespace transgi::gpu {
namespace {

using engine::gpu::GpuBuffer;

constexpr std::size_t kRaysPerTask = 4096;

glm::vec3 vec_of(float x, float y, float z) { return {x, y, z}; }

// What a brief and a whole hit share: the flags, the distance (infinite
// where the ray escaped) and the emission.
void take_brief(std::uint32_t flags, float distance, const glm::vec3& emitted, probes::ProbeRayHit& r) {
  r.hit = (flags & kProbeRayHit) != 0;
  r.back_face = (flags & kProbeRayBackFace) != 0;
  r.saw_light = (flags & kProbeRaySawLight) != 0;
  r.replaced_non_finite = (flags & kProbeRayReplacedNonFinite) != 0;
  r.distance = r.hit ? distance : std::numeric_limits<float>::infinity();
  r.emitted = emitted;
}

void check_source(const probes::ProbeFeedbackSource& f) {
  const auto count = static_cast<std::size_t>(f.grid->count());
  if (f.states->size() != count || f.sh.size() != count * kTransferOutputs || (!f.usable.empty() && f.usable.size() != count))
    throw std::invalid_argument("VulkanProbeShading: a field of " + std::to_string(count) + " probes with " +
                                std::to_string(f.states->size()) + " states, " + std::to_string(f.sh.size()) +
                                " SH values, " + std::to_string(f.usable.size()) + " usable flags");
}

}  // namespace

bool VulkanProbeShading::supported(const engine::gpu::VulkanContext& ctx, std::string* why) {
  if (ctx.info().shader_int64) return true;
  if (why) *why = "the device has no 64-bit integers in shaders (shaderInt64), which the probe-ray shading's generator needs";
  return false;
}

VulkanProbeShading::VulkanProbeShading(engine::gpu::VulkanContext& ctx) : ctx_(ctx), scene_(ctx) {
  std::string why;
  if (!supported(ctx, &why)) throw engine::gpu::GpuError("VulkanProbeShading: " + why);
  using engine::gpu::ComputePipeline;
  using engine::gpu::GpuRtScene;
  const auto query = compile_module_shader("rt_query.comp", GpuRtScene::shader_defines(ctx));
  const auto query_bindings = GpuRtScene::binding_types(ctx, 2, 2 + GpuRtScene::kBindings);
  generate_ = std::make_unique<ComputePipeline>(ctx, compile_module_shader("probe_rays.comp"), 4, 2 * sizeof(std::uint32_t));
  trace_ = std::make_unique<ComputePipeline>(ctx, query, query_bindings, 2 * sizeof(std::uint32_t));
  begin_ = std::make_unique<ComputePipeline>(ctx, compile_module_shader("probe_hit_begin.comp"),
                                             5 + engine::gpu::GpuShadingScene::kBindings, static_cast<std::uint32_t>(sizeof(ProbeHitPush)));
  shadow_trace_ = std::make_unique<ComputePipeline>(ctx, query, query_bindings, 2 * sizeof(std::uint32_t));
  finish_ = std::make_unique<ComputePipeline>(ctx, compile_module_shader("probe_hit_finish.comp"), 9,
                                              static_cast<std::uint32_t>(sizeof(ProbeFinishPush)));
}

namespace {
// `b` with room for `bytes` (grown, never shrunk).
GpuBuffer& at_least(engine::gpu::VulkanContext& ctx, GpuBuffer& b, std::size_t bytes) {
  if (b.handle() == VK_NULL_HANDLE || b.size() < bytes) b = GpuBuffer(ctx, std::max<std::size_t>(bytes, 4));
  return b;
}
}  // namespace

bool VulkanProbeShading::shade(const engine::rt::RtScene& scene, const engine::render::LightSet& lights,
                               engine::gpu::GpuRayTracer& tracer, std::span<const glm::vec3> origins,
                               std::span<const int> probe_ids, std::span<const glm::vec3> directions, std::uint64_t seed,
                               std::uint64_t sample, const probes::ProbeFeedbackSource* self,
                               const probes::ProbeFeedbackSource* outer, std::vector<probes::ProbeRayHit>& out,
                               std::vector<BounceInput>* bounce_inputs, bool brief) {
  if (!prepare(scene, lights, tracer, origins, probe_ids, directions, seed, sample, self, outer)) return false;
  if (prepared_.rays > 0) gpu_ms_ += std::max(0.0, ctx_.submit_and_wait([&](VkCommandBuffer cmd) { record(cmd); }));
  read(out, bounce_inputs, brief);
  return true;
}

bool VulkanProbeShading::prepare(const engine::rt::RtScene& scene, const engine::render::LightSet& lights,
                                 engine::gpu::GpuRayTracer& tracer, std::span<const glm::vec3> origins,
                                 std::span<const int> probe_ids, std::span<const glm::vec3> directions, std::uint64_t seed,
                                 std::uint64_t sample, const probes::ProbeFeedbackSource* self,
                                 const probes::ProbeFeedbackSource* outer) {
  using engine::gpu::HitGpu;
  using engine::gpu::RayGpu;
  if (probe_ids.size() != origins.size())
    throw std::invalid_argument("VulkanProbeShading: " + std::to_string(origins.size()) + " origins but " +
                                std::to_string(probe_ids.size()) + " probe indices");
  if (self) check_source(*self);
  if (outer) check_source(*outer);
  prepared_ = Prepared{};
  if (!scene.assets()) return false;
  scene_.sync(scene, lights);  // first: a scene the device cannot hold throws before out changes
  engine::gpu::GpuRtScene* rt = tracer.device_scene(scene);
  if (!rt) return false;
  const std::size_t m = directions.size(), n = origins.size() * m;
  prepared_.rays = n;
  if (n == 0) return true;

  // The probes and the frame's directions in; every per-ray buffer sized for n.
  const auto origin_in = at_least(ctx_, origins_, origins.size() * sizeof(glm::vec4)).mapped_as<glm::vec4>(origins.size());
  for (std::size_t j = 0; j < origins.size(); ++j)
    origin_in[j] = glm::vec4(origins[j], std::bit_cast<float>(static_cast<std::uint32_t>(probe_ids[j])));
  const auto direction_in = at_least(ctx_, directions_, m * sizeof(glm::vec4)).mapped_as<glm::vec4>(m);
  for (std::size_t i = 0; i < m; ++i) direction_in[i] = glm::vec4(directions[i], 0.0f);
  at_least(ctx_, rays_, n * sizeof(RayGpu));
  at_least(ctx_, hits_, n * sizeof(HitGpu));
  at_least(ctx_, items_, n * 2 * sizeof(std::uint32_t));
  at_least(ctx_, pending_, n * sizeof(PendingProbeRayGpu));
  at_least(ctx_, shadows_, n * sizeof(RayGpu));
  at_least(ctx_, shadow_hits_, n * sizeof(HitGpu));
  at_least(ctx_, out_, n * sizeof(ProbeRayHitGpu));
  at_least(ctx_, briefs_, n * sizeof(ProbeRayBriefGpu));
  at_least(ctx_, emission_, n * sizeof(ProbeRayEmissionGpu));

  // The bounce light from the fields' probes, both fields in one set of buffers.
  const probes::ProbeFeedbackSource* fields[2] = {self, outer};
  std::size_t probe_count = 0, texel_count = 0;
  for (const auto* f : fields)
    if (f) {
      probe_count += static_cast<std::size_t>(f->grid->count());
      texel_count += static_cast<std::size_t>(f->grid->count()) * static_cast<std::size_t>(f->layout.texel_count());
    }
  // At least one element each: a binding needs a buffer even without fields.
  texel_count = std::max<std::size_t>(1, texel_count);
  const std::size_t probe_slots = std::max<std::size_t>(1, probe_count);
  if (depth_.handle() == VK_NULL_HANDLE || depth_.size() < texel_count * 4)
    depth_ = GpuBuffer(ctx_, texel_count * 4, GpuBuffer::Placement::DeviceOnly);
  // Fields without a store send their depth up through staging; those with
  // one have it staged into their store (only the changed maps).
  std::vector<VkBufferCopy>& host_depth = prepared_.host_depth;
  std::vector<VkBufferCopy>* store_depth = prepared_.store_depth;
  VulkanMapStore** stores = prepared_.stores;
  std::size_t host_texels = 0;
  for (int which = 0; which < 2; ++which) {
    const probes::ProbeFeedbackSource* f = fields[which];
    if (!f) continue;
    stores[which] = dynamic_cast<VulkanMapStore*>(f->maps);
    if (!stores[which]) host_texels += static_cast<std::size_t>(f->grid->count()) * static_cast<std::size_t>(f->layout.texel_count());
  }
  const auto staged = host_texels ? at_least(ctx_, depth_staging_, host_texels * 4).mapped_as<std::uint32_t>(host_texels)
                                  : std::span<std::uint32_t>();
  std::size_t staged_at = 0;
  const auto probe_info = at_least(ctx_, probes_, probe_slots * sizeof(ProbeGpu)).mapped_as<ProbeGpu>(probe_slots);
  const auto probe_sh = at_least(ctx_, probe_sh_, probe_slots * kTransferOutputs * sizeof(float))
                            .mapped_as<float>(probe_slots * kTransferOutputs);
  ProbeFeedbackGpu feedback{};
  std::size_t probe_base = 0, depth_base = 0;
  for (int which = 0; which < 2; ++which) {
    const probes::ProbeFeedbackSource* f = fields[which];
    if (!f) continue;
    const auto count = static_cast<std::size_t>(f->grid->count());
    const auto texels = static_cast<std::size_t>(f->layout.texel_count());
    ProbeFieldGpu& record = which == 0 ? feedback.self : feedback.outer;
    record = probe_field_gpu(*f->grid, f->layout, f->interpolation, nullptr, 0.0f, static_cast<std::uint32_t>(probe_base),
                             static_cast<std::uint32_t>(depth_base));
    // The points it holds: past them a hit takes the outer field's light.
    const glm::vec3 held_min = f->held_min(), held_max = f->held_max();
    record.box_min_x = held_min.x, record.box_min_y = held_min.y, record.box_min_z = held_min.z;
    record.box_max_x = held_max.x, record.box_max_y = held_max.y, record.box_max_z = held_max.z;
    const std::size_t field_bytes = count * texels * 4;
    if (VulkanMapStore* store = stores[which]) {
      std::vector<const probes::DepthMap*> maps(count);
      for (std::size_t q = 0; q < count; ++q) maps[q] = &(*f->states)[q].depth;
      store->stage_depth(maps);
      store_depth[which].push_back({0, depth_base * 4, field_bytes});
      write_probe_field(*f->grid, *f->states, f->usable, texels, probe_base, 0, {}, probe_info);
    } else {
      write_probe_field(*f->grid, *f->states, f->usable, texels, probe_base, 0, staged.subspan(staged_at, count * texels), probe_info);
      host_depth.push_back({staged_at * 4, depth_base * 4, field_bytes});
      staged_at += count * texels;
    }
    std::memcpy(probe_sh.data() + probe_base * kTransferOutputs, f->sh.data(), f->sh.size() * sizeof(float));
    probe_base += count;
    depth_base += count * texels;
  }
  at_least(ctx_, feedback_, sizeof(ProbeFeedbackGpu)).upload(std::span<const ProbeFeedbackGpu>(&feedback, 1));

  // Every kernel's buffers, bound afresh: any may have grown.
  generate_->bind(0, origins_);
  generate_->bind(1, directions_);
  generate_->bind(2, rays_);
  generate_->bind(3, items_);
  trace_->bind(0, rays_);
  trace_->bind(1, hits_);
  rt->bind(*trace_, 2);
  begin_->bind(0, rays_);
  begin_->bind(1, hits_);
  begin_->bind(2, items_);
  begin_->bind(3, pending_);
  begin_->bind(4, shadows_);
  scene_.bind(*begin_, 5);
  shadow_trace_->bind(0, shadows_);
  shadow_trace_->bind(1, shadow_hits_);
  rt->bind(*shadow_trace_, 2);
  finish_->bind(0, pending_);
  finish_->bind(1, shadow_hits_);
  finish_->bind(2, out_);
  finish_->bind(7, briefs_);
  finish_->bind(8, emission_);
  finish_->bind(3, feedback_);
  finish_->bind(4, depth_);
  finish_->bind(5, probes_);
  finish_->bind(6, probe_sh_);

  ProbeHitPush& push = prepared_.push;
  push.count = static_cast<uint>(n);
  push.seed_lo = static_cast<uint>(seed);
  push.seed_hi = static_cast<uint>(seed >> 32);
  push.sample_lo = static_cast<uint>(sample);
  push.sample_hi = static_cast<uint>(sample >> 32);
  push.offset_scale = scene.offset_scale();
  prepared_.m = m;
  return true;
}

void VulkanProbeShading::record(VkCommandBuffer cmd) const {
  const Prepared& pr = prepared_;
  const std::size_t n = pr.rays, m = pr.m;
  if (n == 0) return;
  const std::uint32_t generate_push[2] = {static_cast<std::uint32_t>(n), static_cast<std::uint32_t>(m)};
  const std::uint32_t closest[2] = {static_cast<std::uint32_t>(n), 0u}, any_hit[2] = {static_cast<std::uint32_t>(n), 1u};
  const ProbeFinishPush finish_push{static_cast<uint>(n), 0, 0, 0};
  const auto groups = static_cast<std::uint32_t>((n + kProbeShadingGroupSize - 1) / kProbeShadingGroupSize);
  const auto rt_groups = static_cast<std::uint32_t>((n + engine::gpu::kRtGroupSize - 1) / engine::gpu::kRtGroupSize);
  // The depth maps first: the stores' changed ones up, then both fields' into depth_.
  for (int which = 0; which < 2; ++which)
    if (pr.stores[which]) pr.stores[which]->record_depth_uploads(cmd);
  for (int which = 0; which < 2; ++which)
    if (pr.stores[which])
      vkCmdCopyBuffer(cmd, pr.stores[which]->depth().handle(), depth_.handle(), static_cast<std::uint32_t>(pr.store_depth[which].size()),
                      pr.store_depth[which].data());
  if (!pr.host_depth.empty())
    vkCmdCopyBuffer(cmd, depth_staging_.handle(), depth_.handle(), static_cast<std::uint32_t>(pr.host_depth.size()),
                    pr.host_depth.data());
  engine::gpu::record_memory_barrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                                     VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT);
  generate_->record_dispatch(cmd, groups, 1, 1, generate_push);
  engine::gpu::record_compute_barrier(cmd);
  trace_->record_dispatch(cmd, rt_groups, 1, 1, closest);
  engine::gpu::record_compute_barrier(cmd);
  begin_->record_dispatch(cmd, groups, 1, 1, &pr.push);
  engine::gpu::record_compute_barrier(cmd);
  shadow_trace_->record_dispatch(cmd, rt_groups, 1, 1, any_hit);
  engine::gpu::record_compute_barrier(cmd);
  finish_->record_dispatch(cmd, groups, 1, 1, &finish_push);
}

void VulkanProbeShading::read(std::vector<probes::ProbeRayHit>& out, std::vector<BounceInput>* bounce_inputs, bool brief,
                              bool emission) const {
  if (brief && bounce_inputs) throw std::invalid_argument("VulkanProbeShading: brief hits carry no bounce inputs");
  const std::size_t n = prepared_.rays;
  out.resize(n);
  if (n == 0) return;
  if (brief) {
    const auto briefs = briefs_.mapped_as<const ProbeRayBriefGpu>(n);
    const auto emitted = emission ? emission_.mapped_as<const ProbeRayEmissionGpu>(n) : std::span<const ProbeRayEmissionGpu>();
    engine::jobs::parallel_for<std::size_t>(0, n, kRaysPerTask, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) {
        const ProbeRayBriefGpu& g = briefs[i];
        out[i] = probes::ProbeRayHit{};
        take_brief(g.flags, g.distance, emission ? vec_of(emitted[i].er, emitted[i].eg, emitted[i].eb) : glm::vec3(0.0f), out[i]);
      }
    });
    return;
  }
  const auto hits_out = out_.mapped_as<const ProbeRayHitGpu>(n);
  engine::jobs::parallel_for<std::size_t>(0, n, kRaysPerTask, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      const ProbeRayHitGpu& g = hits_out[i];
      probes::ProbeRayHit& r = out[i];
      take_brief(g.flags, g.distance, vec_of(g.er, g.eg, g.eb), r);
      r.position = vec_of(g.px, g.py, g.pz);
      r.normal = vec_of(g.nx, g.ny, g.nz);
      r.radiance = vec_of(g.rr, g.rg, g.rb);
    }
  });
  if (bounce_inputs) {
    bounce_inputs->resize(n);
    const auto pending = pending_.mapped_as<const PendingProbeRayGpu>(n);
    engine::jobs::parallel_for<std::size_t>(0, n, kRaysPerTask, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) {
        const PendingProbeRayGpu& p = pending[i];
        (*bounce_inputs)[i] = {vec_of(p.ar, p.ag, p.ab), vec_of(p.sx, p.sy, p.sz), (p.flags & kProbeRayTakesFeedback) != 0};
      }
    });
  }
}

}  // namespace transgi::gpu
