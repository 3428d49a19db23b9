#pragma once
// A field's radiance maps kept on a Vulkan device between updates
// (probes::ProbeMapStore): slot q of two device buffers holds probe q's
// binary16 history (r | g << 16, then b: 8 bytes a texel) and sampled flags
// (4 bytes a texel), as shaders/probe_accumulation.comp reads and writes
// them in place. Only maps the host changed (a reset, a first update) go
// up, in the update's own submission; nothing comes back unless asked.
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include <vulkan/vulkan_core.h>

#include "engine/gpu/gpu_buffer.h"
#include "engine/gpu/vulkan_context.h"
#include "probes/probe_kernels.h"
#include "probes/probe_map.h"

namespace transgi::gpu {

class VulkanMapStore final : public probes::ProbeMapStore {
 public:
  VulkanMapStore(std::shared_ptr<engine::gpu::VulkanContext> ctx, probes::MapLayout layout, int probes);

  void read_back(std::span<probes::ProbeMapState> states) override;

  // Before an update of states[i] (probe slots[i]): each state this store
  // does not hold yet has its host maps staged, to go up in the update's
  // submission (record_uploads), and is stamped as held. Throws
  // std::logic_error for a state another store holds, std::out_of_range for
  // a slot past the field.
  void stage(std::span<probes::ProbeMapState* const> states, std::span<const int> slots);
  // The staged maps copied into their slots (blank maps zero-filled, with
  // nothing sent), then a barrier before the kernels that read them.
  void record_uploads(VkCommandBuffer cmd) const;

  [[nodiscard]] const engine::gpu::GpuBuffer& history() const { return history_; }
  [[nodiscard]] const engine::gpu::GpuBuffer& sampled() const { return sampled_; }
  [[nodiscard]] const probes::MapLayout& layout() const { return layout_; }
  [[nodiscard]] int probes() const { return probes_; }

 private:
  std::shared_ptr<engine::gpu::VulkanContext> ctx_;
  probes::MapLayout layout_;
  int probes_ = 0;
  std::size_t texels_ = 0;
  engine::gpu::GpuBuffer history_, sampled_;  // device-local where the device has such memory
  std::vector<std::uint64_t> stamp_;          // per slot: the stamp of the state it holds, 0 = none
  // This update's uploads: host maps in staging_ (history then sampled,
  // slot by slot), and the slots whose maps are all zero.
  engine::gpu::GpuBuffer staging_;
  std::vector<VkBufferCopy> history_copies_, sampled_copies_;
  std::vector<int> blank_slots_;
};

}  // namespace transgi::gpu
