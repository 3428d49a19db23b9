#include "gpu/vulkan_probe_shading.h"

#include <cmath>
#include <cstring>
#include <limits>

#include "engine/gpu/gpu_error.h"
#include "engine/jobs/parallel_for.h"
#include "gpu/probe_grid_gpu.h"
#include "gpu/shader_path.h"
#include "probe_shading_shared.h"
#include "rt_shared.h"

namespace transgi::gpu {
namespace {

using engine::gpu::bind_at_least;
using engine::gpu::GpuBuffer;

constexpr std::size_t kRaysPerTask = 4096;

glm::vec3 vec_of(float x, float y, float z) { return {x, y, z}; }

// The feedback record of one field whose probes start at probe_base and
// depth texels at depth_base in the shared buffers.
ProbeFeedbackFieldGpu field_record(const probes::ProbeFeedbackSource& f, std::uint32_t probe_base, std::uint32_t depth_base) {
  ProbeFeedbackFieldGpu r{};
  const probes::ProbeGrid& grid = *f.grid;
  r.field.grid = probe_grid_gpu(grid);
  r.field.bias_length = f.interpolation.normal_bias * grid.min_spacing();
  r.field.visibility_threshold = f.interpolation.visibility_threshold;
  r.field.flags = (f.interpolation.prune_back_facing ? kInterpolatePruneBackFacing : 0u) |
                  (f.interpolation.prune_occluded ? kInterpolatePruneOccluded : 0u) |
                  (grid.offsets.empty() ? 0u : kInterpolateHasOffsets);
  r.field.map_width = static_cast<uint>(f.layout.width);
  r.field.map_height = static_cast<uint>(f.layout.height);
  r.field.texels = static_cast<uint>(f.layout.texel_count());
  r.probe_base = probe_base;
  r.depth_base = depth_base;
  r.enabled = 1u;
  r.box_min_x = grid.min.x;
  r.box_min_y = grid.min.y;
  r.box_min_z = grid.min.z;
  r.box_max_x = grid.max.x;
  r.box_max_y = grid.max.y;
  r.box_max_z = grid.max.z;
  return r;
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
  begin_ = std::make_unique<engine::gpu::ComputePipeline>(ctx, compile_module_shader("probe_hit_begin.comp"),
                                                          5 + engine::gpu::GpuShadingScene::kBindings,
                                                          static_cast<std::uint32_t>(sizeof(ProbeHitPush)));
  finish_ = std::make_unique<engine::gpu::ComputePipeline>(ctx, compile_module_shader("probe_hit_finish.comp"), 7,
                                                           static_cast<std::uint32_t>(sizeof(ProbeFinishPush)));
}

bool VulkanProbeShading::shade(const engine::rt::RtScene& scene, const engine::render::LightSet& lights,
                               engine::rt::RayBatchTracer& tracer, std::span<const engine::rt::Ray> rays,
                               std::span<const std::uint64_t> items, std::uint64_t seed, std::uint64_t sample,
                               const probes::ProbeFeedbackSource* self, const probes::ProbeFeedbackSource* outer,
                               std::vector<probes::ProbeRayHit>& out) {
  using engine::gpu::HitGpu;
  using engine::gpu::RayGpu;
  const std::size_t n = rays.size();
  if (items.size() != n)
    throw std::invalid_argument("VulkanProbeShading: " + std::to_string(n) + " rays but " + std::to_string(items.size()) + " items");
  if (self) check_source(*self);
  if (outer) check_source(*outer);
  if (!scene.assets()) return false;
  scene_.sync(scene, lights);  // first: a scene the device cannot hold throws before out changes
  std::vector<engine::rt::Hit> hits(n);
  std::vector<std::uint8_t> found(n);
  if (!tracer.intersect(scene, rays, hits, found)) return false;
  out.resize(n);
  if (n == 0) return true;

  // 1. The surfaces and their light samples.
  const auto ray_in = bind_at_least(ctx_, *begin_, 0, rays_, n * sizeof(RayGpu)).mapped_as<RayGpu>(n);
  const auto hit_in = bind_at_least(ctx_, *begin_, 1, hits_, n * sizeof(HitGpu)).mapped_as<HitGpu>(n);
  const auto item_in = bind_at_least(ctx_, *begin_, 2, items_, n * 2 * sizeof(std::uint32_t)).mapped_as<std::uint32_t>(2 * n);
  bind_at_least(ctx_, *begin_, 3, pending_, n * sizeof(PendingProbeRayGpu));
  const auto shadow_out = bind_at_least(ctx_, *begin_, 4, shadows_, n * sizeof(RayGpu)).mapped_as<const RayGpu>(n);
  engine::jobs::parallel_for<std::size_t>(0, n, kRaysPerTask, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      const engine::rt::Ray& r = rays[i];
      ray_in[i] = {r.origin.x, r.origin.y, r.origin.z, r.tmin, r.direction.x, r.direction.y, r.direction.z, r.tmax};
      const engine::rt::Hit& h = hits[i];
      hit_in[i] = found[i] ? HitGpu{h.t, h.barycentric.x, h.barycentric.y, h.instance, h.primitive, h.mesh, 0, 0}
                           : HitGpu{0, 0, 0, engine::gpu::kRtNoHit, 0, 0, 0, 0};
      item_in[2 * i] = static_cast<std::uint32_t>(items[i]);
      item_in[2 * i + 1] = static_cast<std::uint32_t>(items[i] >> 32);
    }
  });
  scene_.bind(*begin_, 5);
  ProbeHitPush push{};
  push.count = static_cast<uint>(n);
  push.seed_lo = static_cast<uint>(seed);
  push.seed_hi = static_cast<uint>(seed >> 32);
  push.sample_lo = static_cast<uint>(sample);
  push.sample_hi = static_cast<uint>(sample >> 32);
  push.offset_scale = scene.offset_scale();
  const auto groups = static_cast<std::uint32_t>((n + kProbeShadingGroupSize - 1) / kProbeShadingGroupSize);
  gpu_ms_ += ctx_.submit_and_wait([&](VkCommandBuffer cmd) { begin_->record_dispatch(cmd, groups, 1, 1, &push); });

  // 2. The shadow rays (those with tmin <= tmax), through the backend's tracer.
  std::vector<engine::rt::Ray> shadows;
  std::vector<std::uint32_t> shadow_of;
  for (std::size_t i = 0; i < n; ++i) {
    const RayGpu& s = shadow_out[i];
    if (!(s.tmin <= s.tmax)) continue;
    shadows.push_back(engine::rt::Ray{vec_of(s.origin_x, s.origin_y, s.origin_z), vec_of(s.dir_x, s.dir_y, s.dir_z), s.tmin, s.tmax});
    shadow_of.push_back(static_cast<std::uint32_t>(i));
  }
  std::vector<std::uint8_t> blocked(shadows.size());
  if (!tracer.occluded(scene, shadows, blocked))
    for (std::size_t j = 0; j < shadows.size(); ++j) blocked[j] = scene.occluded(shadows[j]) ? 1 : 0;
  const auto blocked_in = bind_at_least(ctx_, *finish_, 1, blocked_, n * sizeof(std::uint32_t)).mapped_as<std::uint32_t>(n);
  std::fill(blocked_in.begin(), blocked_in.end(), 0u);
  for (std::size_t j = 0; j < shadows.size(); ++j) blocked_in[shadow_of[j]] = blocked[j];

  // 3. The bounce light from the fields' probes, both fields in one set of buffers.
  const probes::ProbeFeedbackSource* fields[2] = {self, outer};
  std::size_t probe_count = 0, texel_count = 0;
  for (const auto* f : fields)
    if (f) {
      probe_count += static_cast<std::size_t>(f->grid->count());
      texel_count += static_cast<std::size_t>(f->grid->count()) * static_cast<std::size_t>(f->layout.texel_count());
    }
  static_assert(sizeof(probes::DepthMap::Texel) == 4);
  const auto depth = bind_at_least(ctx_, *finish_, 4, depth_, std::max<std::size_t>(1, texel_count) * 4).mapped_as<std::uint32_t>(std::max<std::size_t>(1, texel_count));
  const auto probe_info = bind_at_least(ctx_, *finish_, 5, probes_, std::max<std::size_t>(1, probe_count) * sizeof(ProbeGpu)).mapped_as<ProbeGpu>(std::max<std::size_t>(1, probe_count));
  const auto probe_sh = bind_at_least(ctx_, *finish_, 6, probe_sh_, std::max<std::size_t>(1, probe_count * kTransferOutputs) * sizeof(float)).mapped_as<float>(std::max<std::size_t>(1, probe_count * kTransferOutputs));
  ProbeFeedbackGpu feedback{};
  std::size_t probe_base = 0, depth_base = 0;
  for (int which = 0; which < 2; ++which) {
    const probes::ProbeFeedbackSource* f = fields[which];
    if (!f) continue;
    const auto count = static_cast<std::size_t>(f->grid->count());
    const auto texels = static_cast<std::size_t>(f->layout.texel_count());
    (which == 0 ? feedback.self : feedback.outer) =
        field_record(*f, static_cast<std::uint32_t>(probe_base), static_cast<std::uint32_t>(depth_base));
    engine::jobs::parallel_for<std::size_t>(0, count, 16, [&](std::size_t b, std::size_t e) {
      for (std::size_t q = b; q < e; ++q) {
        const probes::DepthMap& d = (*f->states)[q].depth;
        const bool usable = f->usable.empty() || f->usable[q] != 0;
        std::uint32_t* dst = depth.data() + depth_base + q * texels;
        if (usable && d.texels.size() == texels) std::memcpy(dst, d.texels.data(), texels * 4);
        else std::memset(dst, 0, texels * 4);
        const glm::vec3 off = f->grid->offsets.empty() ? glm::vec3(0.0f) : f->grid->offsets[q];
        probe_info[probe_base + q] = {off.x, off.y, off.z, d.unit, usable ? 1u : 0u, 0, 0, 0};
      }
    });
    std::memcpy(probe_sh.data() + probe_base * kTransferOutputs, f->sh.data(), f->sh.size() * sizeof(float));
    probe_base += count;
    depth_base += count * texels;
  }
  bind_at_least(ctx_, *finish_, 3, feedback_, sizeof(ProbeFeedbackGpu)).upload(std::span<const ProbeFeedbackGpu>(&feedback, 1));
  finish_->bind(0, pending_);
  const auto hits_out = bind_at_least(ctx_, *finish_, 2, out_, n * sizeof(ProbeRayHitGpu)).mapped_as<const ProbeRayHitGpu>(n);
  const ProbeFinishPush finish_push{static_cast<uint>(n), 0, 0, 0};
  gpu_ms_ += ctx_.submit_and_wait([&](VkCommandBuffer cmd) { finish_->record_dispatch(cmd, groups, 1, 1, &finish_push); });

  engine::jobs::parallel_for<std::size_t>(0, n, kRaysPerTask, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      const ProbeRayHitGpu& g = hits_out[i];
      probes::ProbeRayHit& r = out[i];
      r.hit = (g.flags & kProbeRayHit) != 0;
      r.back_face = (g.flags & kProbeRayBackFace) != 0;
      r.saw_light = (g.flags & kProbeRaySawLight) != 0;
      r.replaced_non_finite = (g.flags & kProbeRayReplacedNonFinite) != 0;
      r.distance = r.hit ? g.distance : std::numeric_limits<float>::infinity();
      r.position = vec_of(g.px, g.py, g.pz);
      r.normal = vec_of(g.nx, g.ny, g.nz);
      r.radiance = vec_of(g.rr, g.rg, g.rb);
      r.emitted = vec_of(g.er, g.eg, g.eb);
    }
  });
  return true;
}

}  // namespace transgi::gpu
