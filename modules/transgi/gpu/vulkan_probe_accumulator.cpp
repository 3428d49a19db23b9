#include "gpu/vulkan_probe_accumulator.h"

#include <stdexcept>
#include <string>

#include "engine/jobs/parallel_for.h"
#include "gpu/shader_path.h"
#include "probe_accumulation_shared.h"

namespace transgi::gpu {

using engine::gpu::bind_at_least;

VulkanProbeAccumulator::VulkanProbeAccumulator(engine::gpu::VulkanContext& ctx, probes::MapLayout layout)
    : ctx_(ctx), layout_(layout) {
  pipeline_ = std::make_unique<engine::gpu::ComputePipeline>(ctx, compile_module_shader("probe_accumulation.comp"), 9,
                                                             static_cast<std::uint32_t>(sizeof(AccumulatePush)));
  const auto texels = static_cast<std::size_t>(layout.texel_count());
  std::vector<float> angles(texels);
  for (std::size_t t = 0; t < texels; ++t) angles[t] = static_cast<float>(layout.solid_angle(static_cast<int>(t)));
  bind_at_least(ctx_, *pipeline_, 5, solid_angle_, texels * sizeof(float)).upload(std::span<const float>(angles));
}

void VulkanProbeAccumulator::write_states(std::span<probes::ProbeMapState* const> states,
                                          const probes::AccumulationSettings& s) {
  const std::size_t n = states.size(), texels = static_cast<std::size_t>(layout_.texel_count());
  for (std::size_t i = 0; i < n; ++i)
    if (states[i]->radiance.size() != texels || states[i]->sampled.size() != texels)
      throw std::invalid_argument("VulkanProbeAccumulator: probe " + std::to_string(i) + "'s maps are not of " +
                                  std::to_string(texels) + " texels");
  probes_ = n;
  const std::size_t all = n * texels;
  const auto st = bind_at_least(ctx_, *pipeline_, 0, states_, std::max<std::size_t>(1, n) * sizeof(ProbeAccumulationGpu))
                      .mapped_as<ProbeAccumulationGpu>(n);
  bind_at_least(ctx_, *pipeline_, 4, filled_, std::max<std::size_t>(1, all) * 3 * sizeof(float));
  bind_at_least(ctx_, *pipeline_, 6, known_, std::max<std::size_t>(1, all) * sizeof(std::uint32_t));
  for (std::size_t i = 0; i < n; ++i) {
    const probes::ProbeMapState& m = *states[i];
    st[i] = {m.radiance_scale, m.noise_variance, m.drift, 0.0f, m.noise_frames, m.frames, m.stable_frames, 0u};
  }
  const AccumulatePush push{static_cast<uint>(n), static_cast<uint>(texels), static_cast<uint>(layout_.width),
                            static_cast<uint>(layout_.height), s.hysteresis, s.change_threshold, s.change_sigmas,
                            s.fast_hysteresis, s.warmup_frames, s.fill_passes, 0u, 0u};
  push_.assign(reinterpret_cast<const std::uint8_t*>(&push), reinterpret_cast<const std::uint8_t*>(&push) + sizeof(push));
}

void VulkanProbeAccumulator::write_maps(std::span<probes::ProbeMapState* const> states) {
  const std::size_t n = states.size(), texels = static_cast<std::size_t>(layout_.texel_count()), all = n * texels;
  for (std::size_t i = 0; i < n; ++i)
    if (states[i]->device_stamp != 0)
      throw std::logic_error("VulkanProbeAccumulator: state " + std::to_string(i) +
                             "'s maps are held by a map store; read them back first");
  const auto hist = bind_at_least(ctx_, *pipeline_, 1, history_, std::max<std::size_t>(1, all) * 2 * sizeof(std::uint32_t))
                        .mapped_as<std::uint32_t>(2 * all);
  const auto smp = bind_at_least(ctx_, *pipeline_, 2, sampled_, std::max<std::size_t>(1, all) * sizeof(std::uint32_t))
                       .mapped_as<std::uint32_t>(all);
  // A store's buffers may have been bound since these were made.
  pipeline_->bind(1, history_);
  pipeline_->bind(2, sampled_);
  engine::jobs::parallel_for<std::size_t>(0, n, 1, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      const probes::ProbeMapState& m = *states[i];
      for (std::size_t t = 0; t < texels; ++t) {
        const probes::HalfRgb& h = m.radiance[t];
        hist[2 * (i * texels + t)] = std::uint32_t{h.r} | std::uint32_t{h.g} << 16;
        hist[2 * (i * texels + t) + 1] = h.b;
        smp[i * texels + t] = m.sampled[t];
      }
    }
  });
}

void VulkanProbeAccumulator::prepare(std::span<probes::ProbeMapState* const> states,
                                     const engine::gpu::GpuBuffer& device_frames, std::span<const std::uint32_t> frame_maps,
                                     const probes::AccumulationSettings& settings, VulkanMapStore* store) {
  if (frame_maps.size() != states.size())
    throw std::invalid_argument("VulkanProbeAccumulator::prepare: " + std::to_string(states.size()) + " states but " +
                                std::to_string(frame_maps.size()) + " frame maps");
  if (store && store->layout().texel_count() != layout_.texel_count())
    throw std::invalid_argument("VulkanProbeAccumulator::prepare: a map store of " + std::to_string(store->layout().texel_count()) +
                                " texels a map for maps of " + std::to_string(layout_.texel_count()));
  write_states(states, settings);
  store_ = store;
  // Where each state's maps are: its slot of the store, or its place in this batch.
  std::vector<std::uint32_t> slots(states.size());
  if (store) {
    store->stage(states, frame_maps);
    pipeline_->bind(1, store->history());
    pipeline_->bind(2, store->sampled());
    slots.assign(frame_maps.begin(), frame_maps.end());
  } else {
    write_maps(states);
    for (std::size_t i = 0; i < slots.size(); ++i) slots[i] = static_cast<std::uint32_t>(i);
  }
  bind_at_least(ctx_, *pipeline_, 8, map_slots_, std::max<std::size_t>(1, slots.size()) * sizeof(std::uint32_t))
      .upload(std::span<const std::uint32_t>(slots));
  pipeline_->bind(3, device_frames);
  bind_at_least(ctx_, *pipeline_, 7, frame_maps_, std::max<std::size_t>(1, frame_maps.size()) * sizeof(std::uint32_t))
      .upload(frame_maps);
}

void VulkanProbeAccumulator::record(VkCommandBuffer cmd) const {
  if (store_) store_->record_uploads(cmd);
  if (probes_ > 0) pipeline_->record_dispatch(cmd, static_cast<std::uint32_t>(probes_), 1, 1, push_.data());
}

void VulkanProbeAccumulator::finish(std::span<probes::ProbeMapState* const> states, std::span<std::uint8_t> changed,
                                    std::span<glm::vec3> filled) const {
  const std::size_t n = states.size(), texels = static_cast<std::size_t>(layout_.texel_count()), all = n * texels;
  if (n != probes_ || changed.size() != n || (!filled.empty() && filled.size() != all))
    throw std::invalid_argument("VulkanProbeAccumulator::finish: " + std::to_string(n) + " states, " +
                                std::to_string(changed.size()) + " flags, " + std::to_string(filled.size()) +
                                " filled texels for a batch of " + std::to_string(probes_));
  if (n == 0) return;
  const auto st = states_.mapped_as<const ProbeAccumulationGpu>(n);
  // The maps stay in the store where there is one.
  const auto hist = store_ ? std::span<const std::uint32_t>() : history_.mapped_as<const std::uint32_t>(2 * all);
  const auto smp = store_ ? std::span<const std::uint32_t>() : sampled_.mapped_as<const std::uint32_t>(all);
  // Read back only where the caller asked for the filled maps.
  const auto out = filled.empty() ? std::span<const float>() : filled_.mapped_as<const float>(3 * all);
  engine::jobs::parallel_for<std::size_t>(0, n, 1, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      probes::ProbeMapState& m = *states[i];
      const ProbeAccumulationGpu& g = st[i];
      m.radiance_scale = g.radiance_scale;
      m.noise_variance = g.noise_variance;
      m.drift = g.drift;
      m.noise_frames = g.noise_frames;
      m.frames = g.frames;
      m.stable_frames = g.stable_frames;
      changed[i] = g.changed != 0 ? 1 : 0;
      for (std::size_t t = 0; t < texels && (!store_ || !filled.empty()); ++t) {
        if (!store_) {
          const std::uint32_t rg = hist[2 * (i * texels + t)], bb = hist[2 * (i * texels + t) + 1];
          m.radiance[t] = {static_cast<std::uint16_t>(rg & 0xffffu), static_cast<std::uint16_t>(rg >> 16), static_cast<std::uint16_t>(bb)};
          m.sampled[t] = static_cast<std::uint8_t>(smp[i * texels + t]);
        }
        const std::size_t at = i * texels + t;
        if (!filled.empty()) filled[at] = glm::vec3(out[3 * at], out[3 * at + 1], out[3 * at + 2]);
      }
    }
  });
}

double VulkanProbeAccumulator::accumulate(std::span<probes::ProbeMapState* const> states,
                                          std::span<const probes::FrameSamples* const> frames,
                                          const probes::AccumulationSettings& s, std::span<std::uint8_t> changed,
                                          std::span<glm::vec3> filled) {
  const std::size_t n = states.size(), texels = static_cast<std::size_t>(layout_.texel_count());
  if (frames.size() != n || changed.size() != n || filled.size() != n * texels)
    throw std::invalid_argument("VulkanProbeAccumulator: " + std::to_string(n) + " states but " + std::to_string(frames.size()) +
                                " frames, " + std::to_string(changed.size()) + " flags, " + std::to_string(filled.size()) +
                                " filled texels");
  if (n == 0) return 0.0;
  for (std::size_t i = 0; i < n; ++i)
    if (frames[i]->sum.size() != texels || frames[i]->count.size() != texels)
      throw std::invalid_argument("VulkanProbeAccumulator: probe " + std::to_string(i) + "'s frame is not of " +
                                  std::to_string(texels) + " texels");
  const std::size_t all = n * texels;
  const auto frm = engine::gpu::bind_at_least(ctx_, *pipeline_, 3, frame_, all * sizeof(glm::vec4)).mapped_as<glm::vec4>(all);
  engine::jobs::parallel_for<std::size_t>(0, n, 1, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i)
      for (std::size_t t = 0; t < texels; ++t) frm[i * texels + t] = glm::vec4(frames[i]->sum[t], frames[i]->count[t]);
  });
  std::vector<std::uint32_t> identity(n);
  for (std::size_t i = 0; i < n; ++i) identity[i] = static_cast<std::uint32_t>(i);
  prepare(states, frame_, identity, s);
  const double ms = ctx_.submit_and_wait([&](VkCommandBuffer cmd) { record(cmd); });
  finish(states, changed, filled);
  return ms;
}

}  // namespace transgi::gpu
