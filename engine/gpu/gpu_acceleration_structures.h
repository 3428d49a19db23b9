#pragma once
// The ray-query path's acceleration structures (VK_KHR_acceleration_structure),
// built by the driver on the device: one bottom level (BLAS) per mesh, built
// when the meshes change, and one top level (TLAS) over the instances, rebuilt
// at every sync (a move is a new transform, never a BLAS rebuild). GpuRtScene
// keeps one of these where the device traces with ray queries; the driver's
// own builder and traversal replace engine/rt/bvh_builder and
// rt_traversal.glsl's compute loop, on RT cores where the GPU has them.
#include <cstdint>
#include <span>
#include <vector>

#include <vulkan/vulkan_core.h>

#include "engine/gpu/gpu_buffer.h"

namespace engine::gpu {

class VulkanContext;

// One mesh's triangles: `triangles` triangles of three consecutive vertices
// each (no index buffer), vertex k at vertices + k * stride.
struct BlasInput {
  VkDeviceAddress vertices = 0;
  std::uint32_t triangles = 0;
  // Every candidate hit counts; false: the kernel's alpha test decides
  // (rayQueryConfirmIntersectionEXT), as Embree's filter does.
  bool opaque = true;
};

struct TlasInstance {
  float object_to_world[3][4] = {};  // rows of a 3 x 4 matrix
  std::uint32_t custom_index = 0;    // what rayQueryGetIntersectionInstanceCustomIndexEXT returns (24 bits)
  std::uint32_t blas = 0;            // index into the meshes of build_bottom
};

class GpuAccelerationStructures {
 public:
  // Throws GpuError where the device does not trace with ray queries.
  explicit GpuAccelerationStructures(VulkanContext& ctx);
  ~GpuAccelerationStructures();
  GpuAccelerationStructures(const GpuAccelerationStructures&) = delete;
  GpuAccelerationStructures& operator=(const GpuAccelerationStructures&) = delete;

  // Replaces every BLAS, all built in one submission. A mesh without
  // triangles gets none, and instances of it are inactive.
  void build_bottom(std::span<const BlasInput> meshes, VkDeviceSize vertex_stride);
  // Rebuilds the TLAS (after build_bottom); its storage grows, never shrinks.
  void build_top(std::span<const TlasInstance> instances);

  [[nodiscard]] VkAccelerationStructureKHR top() const { return top_.handle; }
  [[nodiscard]] std::size_t bottom_count() const { return bottom_.size(); }

 private:
  struct Structure {
    VkAccelerationStructureKHR handle = VK_NULL_HANDLE;
    VkDeviceAddress address = 0;
  };
  // A structure of `bytes` at `offset` (a multiple of 256) in `storage`.
  Structure make(VkAccelerationStructureTypeKHR type, const GpuBuffer& storage, VkDeviceSize offset, VkDeviceSize bytes);
  void destroy(Structure& s);
  // A scratch buffer of at least `bytes` at the device's scratch alignment;
  // returns its aligned address.
  VkDeviceAddress scratch(VkDeviceSize bytes);

  VulkanContext& ctx_;
  // Every BLAS in one buffer: one memory allocation, however many meshes
  // (drivers allow as few as 4,096 allocations).
  std::vector<Structure> bottom_;  // per mesh; handle null for an empty mesh
  GpuBuffer bottom_storage_;
  Structure top_;
  GpuBuffer top_storage_;
  std::uint32_t top_capacity_ = 0;
  GpuBuffer instances_, scratch_;
};

}  // namespace engine::gpu
