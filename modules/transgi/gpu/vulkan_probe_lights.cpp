#include "gpu/vulkan_probe_lights.h"

#include <cstring>

#include "engine/jobs/parallel_for.h"
#include "gpu/probe_grid_gpu.h"
#include "gpu/shader_path.h"
#include "probes/cascades.h"

namespace transgi::gpu {

static_assert(sizeof(shading::ProbeLightMaker::Point) == sizeof(ProbeLightPointGpu) &&
                  offsetof(shading::ProbeLightMaker::Point, rotation) == offsetof(ProbeLightPointGpu, rotation) &&
                  offsetof(shading::ProbeLightMaker::Point, normal) == offsetof(ProbeLightPointGpu, nx),
              "a point is written by the CPU in the kernel's layout");

VulkanProbeLights::VulkanProbeLights(engine::gpu::VulkanContext& ctx) : ctx_(ctx) {
  pipeline_ = std::make_unique<engine::gpu::ComputePipeline>(ctx, compile_module_shader("probe_lights.comp"), 8,
                                                             static_cast<std::uint32_t>(sizeof(ProbeLightsPush)));
}

bool VulkanProbeLights::set_probes(std::span<const probes::ProbeField* const> fields, int rotations,
                                   const shading::ProbeLightMaker::ShOf& sh, std::string* why) {
  if (fields.empty() || fields.size() > kProbeLightsMaxFields) {
    if (why) *why = std::to_string(fields.size()) + " probe fields (the kernel takes 1 to " + std::to_string(kProbeLightsMaxFields) + ")";
    return false;
  }
  const std::size_t f_count = fields.size(), copies = static_cast<std::size_t>(rotations) + 1;
  std::size_t probe_count = 0, texel_count = 0;
  for (const probes::ProbeField* f : fields) {
    probe_count += static_cast<std::size_t>(f->grid().count());
    texel_count += static_cast<std::size_t>(f->grid().count()) * static_cast<std::size_t>(f->settings().map.texel_count());
  }
  // SH: every copy of every field (indirect, direct), then each field's mean light.
  const std::size_t sh_floats = copies * 2 * probe_count * kTransferOutputs + f_count * 2 * kTransferOutputs;
  const auto depth = engine::gpu::bind_at_least(ctx_, *pipeline_, 2, depth_, std::max<std::size_t>(1, texel_count) * 4)
                         .mapped_as<std::uint32_t>(std::max<std::size_t>(1, texel_count));
  const auto probe_info = engine::gpu::bind_at_least(ctx_, *pipeline_, 3, probes_, probe_count * sizeof(ProbeGpu))
                              .mapped_as<ProbeGpu>(probe_count);
  const auto sh_out = engine::gpu::bind_at_least(ctx_, *pipeline_, 4, sh_, sh_floats * sizeof(float)).mapped_as<float>(sh_floats);
  const auto sh_at = engine::gpu::bind_at_least(ctx_, *pipeline_, 5, sh_at_, copies * 2 * f_count * sizeof(std::uint32_t))
                         .mapped_as<std::uint32_t>(copies * 2 * f_count);
  const auto records = engine::gpu::bind_at_least(ctx_, *pipeline_, 1, fields_, f_count * sizeof(ProbeFieldGpu))
                           .mapped_as<ProbeFieldGpu>(f_count);
  std::size_t probe_base = 0, depth_base = 0, sh_base = 0;
  const std::size_t mean_base = copies * 2 * probe_count * kTransferOutputs;
  for (std::size_t f = 0; f < f_count; ++f) {
    const probes::ProbeField& field = *fields[f];
    const probes::ProbeGrid& grid = field.grid();
    const auto count = static_cast<std::size_t>(grid.count());
    const auto texels = static_cast<std::size_t>(field.settings().map.texel_count());
    // Relocation moves probes, not the box, so the grid's box is the placed
    // one that mix_at and next_holding hand points over by.
    const bool fallback = field.settings().blend_cells == probes::kFallbackBlendCells;
    ProbeFieldGpu r = probe_field_gpu(grid, field.settings().map, field.settings().interpolation, field.viewer(),
                                      fallback ? 0.0f : field.settings().blend_cells * grid.min_spacing(), static_cast<uint>(probe_base),
                                      static_cast<uint>(depth_base));
    r.fallback = fallback ? 1u : 0u;
    const glm::vec3 held_min = grid.held_min(field.settings().hold_cells), held_max = grid.held_max(field.settings().hold_cells);
    r.box_min_x = held_min.x, r.box_min_y = held_min.y, r.box_min_z = held_min.z;
    r.box_max_x = held_max.x, r.box_max_y = held_max.y, r.box_max_z = held_max.z;
    r.mean_at = static_cast<uint>(mean_base + f * 2 * kTransferOutputs);
    records[f] = r;
    write_probe_field(grid, field.states(), field.usable(), texels, probe_base, depth_base, depth, probe_info);
    for (std::size_t c = 0; c < copies; ++c)
      for (int direct = 0; direct < 2; ++direct) {
        const float* src = sh(static_cast<int>(c) - 1, &field, direct != 0);
        sh_at[(c * f_count + f) * 2 + static_cast<std::size_t>(direct)] = static_cast<std::uint32_t>(sh_base);
        std::memcpy(sh_out.data() + sh_base, src, count * kTransferOutputs * sizeof(float));
        sh_base += count * kTransferOutputs;
      }
    std::memcpy(sh_out.data() + r.mean_at, field.mean_light_sh(), kTransferOutputs * sizeof(float));
    std::memcpy(sh_out.data() + r.mean_at + kTransferOutputs, field.mean_direct_sh(), kTransferOutputs * sizeof(float));
    probe_base += count;
    depth_base += count * texels;
  }
  field_count_ = static_cast<std::uint32_t>(f_count);
  rotations_ = static_cast<std::uint32_t>(rotations);
  return true;
}

std::span<shading::ProbeLightMaker::Point> VulkanProbeLights::points(std::size_t n) {
  const auto raw = engine::gpu::bind_at_least(ctx_, *pipeline_, 0, points_, std::max<std::size_t>(1, n) * sizeof(ProbeLightPointGpu))
                       .mapped_as<shading::ProbeLightMaker::Point>(n);
  return raw;
}

void VulkanProbeLights::record(VkCommandBuffer cmd, std::size_t n, bool second, const engine::gpu::GpuBuffer& light,
                               const engine::gpu::GpuBuffer& light2) {
  pipeline_->bind(6, light);
  pipeline_->bind(7, light2);
  const ProbeLightsPush push{static_cast<uint>(n), field_count_, second ? 1u : 0u, rotations_};
  pipeline_->record_dispatch(cmd, static_cast<std::uint32_t>((n + kProbeLightsGroupSize - 1) / kProbeLightsGroupSize), 1, 1, &push);
}

}  // namespace transgi::gpu
