#pragma once
// A field's radiance maps kept on a Vulkan device between updates
// (probes::ProbeMapStore): slot q of two device buffers holds probe q's
// binary16 history (r | g << 16, then b: 8 bytes a texel) and sampled flags
// (4 bytes a texel), as shaders/probe_accumulation.comp reads and writes
// them in place. Only maps the host changed (a reset, a first update) go
// up, in the update's own submission; nothing comes back unless asked. It
// also keeps a copy of each probe's depth map (4 bytes a texel, the host's
// DepthMap::Texel), sent up when its version changed, for the kernels that
// read the depth (the raster's guard, the probe rays' bounce light).
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
  void stage(std::span<probes::ProbeMapState* const> states, std::span<const std::uint32_t> slots);
  // The staged maps copied into their slots (blank maps zero-filled, with
  // nothing sent), then a barrier before the kernels that read them.
  void record_uploads(VkCommandBuffer cmd) const;

  // Before a submission that reads depth[q] (one map a probe of the field,
  // null or of another size where the probe holds none): the maps whose
  // version this store does not hold are staged (a blank or missing one as
  // never hit, with nothing sent), for record_depth_uploads. Stages add up
  // until recorded: two stages of one submission may each stage.
  void stage_depth(std::span<const probes::DepthMap* const> depth);
  // The staged uploads into `cmd`, then a barrier; nothing is staged after.
  void record_depth_uploads(VkCommandBuffer cmd);
  // How many maps are staged to go up (blank ones, filled rather than sent, excluded).
  [[nodiscard]] std::size_t depth_maps_staged() const { return depth_copies_.size(); }
  // After a kernel updated slot q's depth copy on the device to what the
  // host's map now holds (the host made the same update): the copy is of
  // `version`, and is not sent again.
  void adopt_depth(std::size_t q, std::uint64_t version);
  // The depth copies, probe q's at q * texels, current once the uploads
  // recorded before have run.
  [[nodiscard]] const engine::gpu::GpuBuffer& depth() const { return depth_; }

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
  // The depth copies: the version each slot holds (0: none known), and
  // this submission's uploads.
  engine::gpu::GpuBuffer depth_, depth_staging_;
  std::vector<std::uint64_t> depth_version_;
  std::vector<VkBufferCopy> depth_copies_;
  std::vector<int> blank_depth_slots_;
  // Per slot, its map's place in depth_staging_ while staged (-1: none),
  // and how many maps the staging holds.
  std::vector<std::ptrdiff_t> depth_pending_at_;
  std::size_t depth_staged_maps_ = 0;
};

}  // namespace transgi::gpu
