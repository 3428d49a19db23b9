#pragma once
// TransGI's accumulation on a Vulkan device (shaders/probe_accumulation.comp):
// probes::accumulate and probes::filled_radiance for every updated probe in
// one dispatch. The CPU functions are the oracle
// (tests/gpu/probe_accumulation_test.cpp).
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "engine/gpu/compute_pipeline.h"
#include "engine/gpu/gpu_buffer.h"
#include "engine/gpu/vulkan_context.h"
#include "gpu/vulkan_map_store.h"
#include "probes/probe_map.h"

namespace transgi::gpu {

class VulkanProbeAccumulator {
 public:
  VulkanProbeAccumulator(engine::gpu::VulkanContext& ctx, probes::MapLayout layout);

  // For each i: accumulate(*states[i], *frames[i], settings) (changed[i] its
  // result) and filled_radiance(*states[i], layout, settings.fill_passes)
  // into filled (states.size() x texel_count()), in one submission. Returns
  // its GPU time in ms (-1 without timestamps).
  double accumulate(std::span<probes::ProbeMapState* const> states, std::span<const probes::FrameSamples* const> frames,
                    const probes::AccumulationSettings& settings, std::span<std::uint8_t> changed,
                    std::span<glm::vec3> filled);

  // The same in three steps, for a submission that holds other stages too.
  // prepare: the states' maps written for the kernel; this frame's samples
  // read from `device_frames` (a device buffer of vec4 (sum, count) per
  // texel, one map per probe of a grid: probe i's is map frame_maps[i]),
  // not uploaded. With a `store`, the maps are its slots frame_maps[i]
  // (VulkanMapStore::stage sends up only what it does not hold); without,
  // they are written here from the states and read back by finish.
  void prepare(std::span<probes::ProbeMapState* const> states, const engine::gpu::GpuBuffer& device_frames,
               std::span<const std::uint32_t> frame_maps, const probes::AccumulationSettings& settings,
               VulkanMapStore* store = nullptr);
  // record: the store's uploads and the dispatch, into a command buffer being recorded.
  void record(VkCommandBuffer cmd) const;
  // finish, after the submission completed: the states' scalars and flags
  // read back (changed[i]), their maps too where prepare had no store, and
  // the filled maps where `filled` is not empty.
  void finish(std::span<probes::ProbeMapState* const> states, std::span<std::uint8_t> changed,
              std::span<glm::vec3> filled) const;
  // The filled maps on the device (states.size() x texel_count() x 3
  // floats), valid after the submission that recorded the dispatch.
  [[nodiscard]] const engine::gpu::GpuBuffer& filled_on_device() const { return filled_; }

 private:
  // The states' scalars (and, without a store, their maps) into the
  // kernel's buffers, the push constants set.
  void write_states(std::span<probes::ProbeMapState* const> states, const probes::AccumulationSettings& settings);
  void write_maps(std::span<probes::ProbeMapState* const> states);

  engine::gpu::VulkanContext& ctx_;
  probes::MapLayout layout_;
  std::unique_ptr<engine::gpu::ComputePipeline> pipeline_;
  engine::gpu::GpuBuffer states_, history_, sampled_, frame_, filled_, solid_angle_, known_, frame_maps_, map_slots_;
  std::size_t probes_ = 0;
  const VulkanMapStore* store_ = nullptr;  // this update's, from prepare
  std::vector<std::uint8_t> push_;
};

}  // namespace transgi::gpu
