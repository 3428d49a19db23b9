#include "gpu/vulkan_map_store.h"

#include <atomic>
#include <cstring>
#include <stdexcept>
#include <string>

#include "engine/gpu/compute_pipeline.h"
#include "engine/jobs/parallel_for.h"

namespace transgi::gpu {

namespace {
constexpr std::size_t kHistoryBytes = 2 * sizeof(std::uint32_t), kSampledBytes = sizeof(std::uint32_t);
constexpr std::size_t kDepthBytes = sizeof(probes::DepthMap::Texel);
static_assert(kDepthBytes == 4, "a depth texel is two binary16, one 32-bit word on the device");
// A texel never hit (DepthMap::Texel's initialiser: mean NaN, variance 0),
// as the 32-bit word vkCmdFillBuffer repeats (mean in the low half).
constexpr probes::DepthMap::Texel kNeverHit{};
constexpr std::uint32_t kNeverHitBits = std::uint32_t{kNeverHit.mean} | std::uint32_t{kNeverHit.variance} << 16;
// The version a slot holds when its map is blank (no stamp is ever this).
constexpr std::uint64_t kBlankDepth = ~std::uint64_t{0};

// Stamps are unique across every store of the process, so a state one
// store holds is never taken for one another store holds.
std::uint64_t next_stamp() {
  static std::atomic<std::uint64_t> last{0};
  return last.fetch_add(1, std::memory_order_relaxed) + 1;
}

bool blank(const probes::ProbeMapState& m) {
  for (const probes::HalfRgb& h : m.radiance)
    if (h.r != 0 || h.g != 0 || h.b != 0) return false;
  for (const std::uint8_t s : m.sampled)
    if (s != 0) return false;
  return true;
}
}  // namespace

VulkanMapStore::VulkanMapStore(std::shared_ptr<engine::gpu::VulkanContext> ctx, probes::MapLayout layout, int probes)
    : ctx_(std::move(ctx)), layout_(layout), probes_(std::max(0, probes)),
      texels_(static_cast<std::size_t>(layout.texel_count())),
      history_(*ctx_, std::max<std::size_t>(1, static_cast<std::size_t>(probes_) * texels_) * kHistoryBytes,
               engine::gpu::GpuBuffer::Placement::DeviceOnly),
      sampled_(*ctx_, std::max<std::size_t>(1, static_cast<std::size_t>(probes_) * texels_) * kSampledBytes,
               engine::gpu::GpuBuffer::Placement::DeviceOnly),
      stamp_(static_cast<std::size_t>(probes_), 0),
      depth_(*ctx_, std::max<std::size_t>(1, static_cast<std::size_t>(probes_) * texels_) * kDepthBytes,
             engine::gpu::GpuBuffer::Placement::DeviceOnly),
      depth_version_(static_cast<std::size_t>(probes_), 0) {}

void VulkanMapStore::stage_depth(std::span<const probes::DepthMap* const> depth) {
  if (depth.size() != static_cast<std::size_t>(probes_))
    throw std::invalid_argument("VulkanMapStore::stage_depth: " + std::to_string(depth.size()) + " depth maps for a field of " +
                                std::to_string(probes_) + " probes");
  // What an earlier stage_depth left for the same submission stays staged
  // (the probe rays' and the raster's both stage, and record in one
  // submission): a map staged again is rewritten in its place.
  if (depth_pending_at_.size() != depth.size()) depth_pending_at_.assign(depth.size(), -1);
  const auto drop_pending_copy = [&](std::size_t q) {
    if (depth_pending_at_[q] < 0) return;
    std::erase_if(depth_copies_, [&](const VkBufferCopy& c) { return c.dstOffset == static_cast<VkDeviceSize>(q) * texels_ * kDepthBytes; });
    depth_pending_at_[q] = -1;
  };
  std::vector<std::size_t> send;
  for (std::size_t q = 0; q < depth.size(); ++q) {
    const probes::DepthMap* d = depth[q];
    const bool held = d && d->texels.size() == texels_;
    if (held && d->version != 0 && d->version == depth_version_[q]) continue;
    bool blank = true;
    for (std::size_t t = 0; held && t < texels_ && blank; ++t)
      blank = d->texels[t].mean == kNeverHit.mean && d->texels[t].variance == kNeverHit.variance;
    if (blank) {
      // Never hit, as DepthMap::reset leaves it; "blank" is a version of its own.
      drop_pending_copy(q);
      if (depth_version_[q] != kBlankDepth) blank_depth_slots_.push_back(static_cast<int>(q));
      depth_version_[q] = kBlankDepth;
      continue;
    }
    std::erase(blank_depth_slots_, static_cast<int>(q));
    send.push_back(q);
    depth_version_[q] = d->version;  // 0 (not stamped) goes up every time
  }
  if (send.empty()) return;
  const std::size_t per = texels_ * kDepthBytes;
  std::vector<std::size_t> at(send.size());
  std::size_t slots = depth_staged_maps_;
  for (std::size_t k = 0; k < send.size(); ++k) {
    std::ptrdiff_t& pending = depth_pending_at_[send[k]];
    if (pending < 0) {
      pending = static_cast<std::ptrdiff_t>(slots++);
      depth_copies_.push_back({static_cast<VkDeviceSize>(pending) * per, static_cast<VkDeviceSize>(send[k]) * per, per});
    }
    at[k] = static_cast<std::size_t>(pending);
  }
  if (depth_staging_.handle() == VK_NULL_HANDLE || depth_staging_.size() < slots * per) {
    engine::gpu::GpuBuffer grown(*ctx_, slots * per);
    if (depth_staged_maps_ > 0) {
      const auto old = depth_staging_.mapped_as<const std::uint8_t>(depth_staged_maps_ * per);
      std::memcpy(grown.mapped_as<std::uint8_t>(depth_staged_maps_ * per).data(), old.data(), depth_staged_maps_ * per);
    }
    depth_staging_ = std::move(grown);
  }
  depth_staged_maps_ = slots;
  const auto bytes = depth_staging_.mapped_as<std::uint8_t>(slots * per);
  engine::jobs::parallel_for<std::size_t>(0, send.size(), 8, [&](std::size_t b, std::size_t e) {
    for (std::size_t k = b; k < e; ++k) std::memcpy(bytes.data() + at[k] * per, depth[send[k]]->texels.data(), per);
  });
}

void VulkanMapStore::adopt_depth(std::size_t q, std::uint64_t version) {
  if (q >= depth_version_.size())
    throw std::out_of_range("VulkanMapStore::adopt_depth: slot " + std::to_string(q) + " of a field of " + std::to_string(probes_) +
                            " probes");
  depth_version_[q] = version;
}

void VulkanMapStore::record_depth_uploads(VkCommandBuffer cmd) {
  if (depth_copies_.empty() && blank_depth_slots_.empty()) return;
  const std::size_t per = texels_ * kDepthBytes;
  for (const int q : blank_depth_slots_) vkCmdFillBuffer(cmd, depth_.handle(), static_cast<VkDeviceSize>(q) * per, per, kNeverHitBits);
  if (!depth_copies_.empty())
    vkCmdCopyBuffer(cmd, depth_staging_.handle(), depth_.handle(), static_cast<std::uint32_t>(depth_copies_.size()), depth_copies_.data());
  engine::gpu::record_memory_barrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                                     VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                                     VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_TRANSFER_READ_BIT);
  // Recorded: the next stage_depth starts afresh (the staging is read when
  // the submission runs, before any later stage_depth writes it again).
  depth_copies_.clear();
  blank_depth_slots_.clear();
  std::fill(depth_pending_at_.begin(), depth_pending_at_.end(), -1);
  depth_staged_maps_ = 0;
}

void VulkanMapStore::stage(std::span<probes::ProbeMapState* const> states, std::span<const std::uint32_t> slots) {
  if (states.size() != slots.size())
    throw std::invalid_argument("VulkanMapStore::stage: " + std::to_string(states.size()) + " states for " +
                                std::to_string(slots.size()) + " slots");
  history_copies_.clear();
  sampled_copies_.clear();
  blank_slots_.clear();
  std::vector<std::size_t> send;  // indices into states
  for (std::size_t i = 0; i < states.size(); ++i) {
    const std::uint32_t q = slots[i];
    if (q >= static_cast<std::uint32_t>(probes_))
      throw std::out_of_range("VulkanMapStore: slot " + std::to_string(q) + " of a field of " + std::to_string(probes_) + " probes");
    probes::ProbeMapState& m = *states[i];
    const std::uint64_t held = stamp_[static_cast<std::size_t>(q)];
    if (m.device_stamp != 0 && m.device_stamp == held) continue;  // the device's maps are the newest
    if (m.device_stamp != 0)
      throw std::logic_error("VulkanMapStore: probe " + std::to_string(q) + "'s maps are held by another store; read them back first");
    if (m.radiance.size() != texels_ || m.sampled.size() != texels_)
      throw std::invalid_argument("VulkanMapStore: probe " + std::to_string(q) + "'s maps are not of " + std::to_string(texels_) +
                                  " texels");
    if (blank(m))
      blank_slots_.push_back(static_cast<int>(q));
    else
      send.push_back(i);
    m.device_stamp = stamp_[static_cast<std::size_t>(q)] = next_stamp();
  }
  if (send.empty()) return;
  const std::size_t per = texels_ * (kHistoryBytes + kSampledBytes);
  if (staging_.size() < send.size() * per) staging_ = engine::gpu::GpuBuffer(*ctx_, send.size() * per);
  const auto words = staging_.mapped_as<std::uint32_t>(send.size() * per / sizeof(std::uint32_t));
  engine::jobs::parallel_for<std::size_t>(0, send.size(), 1, [&](std::size_t b, std::size_t e) {
    for (std::size_t k = b; k < e; ++k) {
      const probes::ProbeMapState& m = *states[send[k]];
      std::uint32_t* hist = words.data() + k * per / sizeof(std::uint32_t);
      std::uint32_t* smp = hist + 2 * texels_;
      for (std::size_t t = 0; t < texels_; ++t) {
        hist[2 * t] = std::uint32_t{m.radiance[t].r} | std::uint32_t{m.radiance[t].g} << 16;
        hist[2 * t + 1] = m.radiance[t].b;
        smp[t] = m.sampled[t];
      }
    }
  });
  for (std::size_t k = 0; k < send.size(); ++k) {
    const auto q = static_cast<VkDeviceSize>(slots[send[k]]);
    history_copies_.push_back({k * per, q * texels_ * kHistoryBytes, texels_ * kHistoryBytes});
    sampled_copies_.push_back({k * per + texels_ * kHistoryBytes, q * texels_ * kSampledBytes, texels_ * kSampledBytes});
  }
}

void VulkanMapStore::record_uploads(VkCommandBuffer cmd) const {
  if (history_copies_.empty() && blank_slots_.empty()) return;
  for (const int q : blank_slots_) {
    const auto slot = static_cast<VkDeviceSize>(q);
    vkCmdFillBuffer(cmd, history_.handle(), slot * texels_ * kHistoryBytes, texels_ * kHistoryBytes, 0u);
    vkCmdFillBuffer(cmd, sampled_.handle(), slot * texels_ * kSampledBytes, texels_ * kSampledBytes, 0u);
  }
  if (!history_copies_.empty()) {
    vkCmdCopyBuffer(cmd, staging_.handle(), history_.handle(), static_cast<std::uint32_t>(history_copies_.size()),
                    history_copies_.data());
    vkCmdCopyBuffer(cmd, staging_.handle(), sampled_.handle(), static_cast<std::uint32_t>(sampled_copies_.size()),
                    sampled_copies_.data());
  }
  engine::gpu::record_memory_barrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                                     VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
}

void VulkanMapStore::read_back(std::span<probes::ProbeMapState> states) {
  if (states.size() != static_cast<std::size_t>(probes_))
    throw std::invalid_argument("VulkanMapStore::read_back: " + std::to_string(states.size()) + " states for a field of " +
                                std::to_string(probes_) + " probes");
  bool any = false;
  for (std::size_t q = 0; q < states.size(); ++q) any = any || (states[q].device_stamp != 0 && states[q].device_stamp == stamp_[q]);
  if (!any) return;
  std::vector<std::uint32_t> hist(static_cast<std::size_t>(probes_) * texels_ * 2), smp(static_cast<std::size_t>(probes_) * texels_);
  history_.download(std::span<std::uint32_t>(hist));
  sampled_.download(std::span<std::uint32_t>(smp));
  engine::jobs::parallel_for<std::size_t>(0, states.size(), 16, [&](std::size_t b, std::size_t e) {
    for (std::size_t q = b; q < e; ++q) {
      probes::ProbeMapState& m = states[q];
      if (m.device_stamp == 0 || m.device_stamp != stamp_[q]) continue;
      for (std::size_t t = 0; t < texels_; ++t) {
        const std::uint32_t rg = hist[2 * (q * texels_ + t)];
        m.radiance[t] = {static_cast<std::uint16_t>(rg & 0xffffu), static_cast<std::uint16_t>(rg >> 16),
                         static_cast<std::uint16_t>(hist[2 * (q * texels_ + t) + 1])};
        m.sampled[t] = static_cast<std::uint8_t>(smp[q * texels_ + t]);
      }
      m.device_stamp = 0;
      stamp_[q] = 0;
    }
  });
}

}  // namespace transgi::gpu
