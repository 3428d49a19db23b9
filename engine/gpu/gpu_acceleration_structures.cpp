#include "engine/gpu/gpu_acceleration_structures.h"

#include <algorithm>
#include <memory>
#include <string>
#include <utility>

#include "engine/gpu/compute_pipeline.h"
#include "engine/gpu/gpu_error.h"
#include "engine/gpu/vulkan_context.h"

namespace engine::gpu {
namespace {

constexpr VkBufferUsageFlags kAddressable = VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;

VkDeviceSize round_up(VkDeviceSize x, VkDeviceSize a) { return a > 1 ? (x + a - 1) / a * a : x; }

// The specification's alignment of an acceleration structure in its buffer.
constexpr VkDeviceSize kStructureAlignment = 256;

GpuBuffer storage_buffer(VulkanContext& ctx, VkDeviceSize bytes) {
  return GpuBuffer(ctx, bytes, GpuBuffer::Placement::DeviceOnly,
                   VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR | kAddressable);
}

constexpr VkPipelineStageFlags kBuildStage = VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR;

// Build inputs written by copies or the host become visible to the builder;
// the builds' writes become visible to later builds and to the kernels'
// ray queries (later submissions are in the barrier's second scope).
void inputs_visible_to_build(VkCommandBuffer cmd) {
  record_memory_barrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_HOST_BIT | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                        VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_HOST_WRITE_BIT | VK_ACCESS_SHADER_WRITE_BIT, kBuildStage,
                        VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_ACCELERATION_STRUCTURE_READ_BIT_KHR);
}

void build_visible_to_queries(VkCommandBuffer cmd) {
  record_memory_barrier(cmd, kBuildStage, VK_ACCESS_ACCELERATION_STRUCTURE_WRITE_BIT_KHR,
                        kBuildStage | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                        VK_ACCESS_ACCELERATION_STRUCTURE_READ_BIT_KHR | VK_ACCESS_SHADER_READ_BIT);
}

}  // namespace

GpuAccelerationStructures::GpuAccelerationStructures(VulkanContext& ctx) : ctx_(ctx) {
  if (!ctx.info().ray_query)
    throw GpuError("GpuAccelerationStructures: " + ctx.info().name + " does not trace with VK_KHR_ray_query");
}

GpuAccelerationStructures::~GpuAccelerationStructures() {
  ctx_.forget_deferred(this);
  for (auto& s : bottom_) destroy(s);
  destroy(top_);
}

GpuAccelerationStructures::Structure GpuAccelerationStructures::make(VkAccelerationStructureTypeKHR type,
                                                                     const GpuBuffer& storage, VkDeviceSize offset,
                                                                     VkDeviceSize bytes) {
  Structure s;
  VkAccelerationStructureCreateInfoKHR ci{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
  ci.buffer = storage.handle();
  ci.offset = offset;
  ci.size = bytes;
  ci.type = type;
  ENGINE_VK_CHECK(ctx_.acceleration_structures().create(ctx_.device(), &ci, nullptr, &s.handle));
  VkAccelerationStructureDeviceAddressInfoKHR ai{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_DEVICE_ADDRESS_INFO_KHR};
  ai.accelerationStructure = s.handle;
  s.address = ctx_.acceleration_structures().device_address(ctx_.device(), &ai);
  return s;
}

void GpuAccelerationStructures::destroy(Structure& s) {
  if (s.handle) ctx_.acceleration_structures().destroy(ctx_.device(), s.handle, nullptr);
  s = Structure{};
}

VkDeviceAddress GpuAccelerationStructures::scratch(VkDeviceSize bytes) {
  const VkDeviceSize align = std::max<VkDeviceSize>(1, ctx_.info().scratch_alignment);
  if (scratch_.handle() == VK_NULL_HANDLE || scratch_.size() < bytes + align)
    scratch_ = GpuBuffer(ctx_, bytes + align, GpuBuffer::Placement::DeviceOnly, kAddressable);
  return round_up(scratch_.device_address(), align);
}

void GpuAccelerationStructures::build_bottom(std::span<const BlasInput> meshes, VkDeviceSize vertex_stride) {
  const AccelerationStructureApi& api = ctx_.acceleration_structures();
  // A queued TLAS build names the BLAS this replaces.
  if (ctx_.has_deferred(this)) ctx_.flush();
  for (auto& s : bottom_) destroy(s);
  bottom_.assign(meshes.size(), Structure{});
  bottom_storage_ = GpuBuffer();
  const std::size_t n = meshes.size();
  std::vector<VkAccelerationStructureGeometryKHR> geometry(n, {VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR});
  std::vector<VkAccelerationStructureBuildGeometryInfoKHR> info(n, {VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR});
  std::vector<VkAccelerationStructureBuildRangeInfoKHR> range(n);
  std::vector<VkDeviceSize> scratch_offset(n, 0), storage_offset(n, 0), storage_size(n, 0);
  const VkDeviceSize align = std::max<VkDeviceSize>(1, ctx_.info().scratch_alignment);
  VkDeviceSize scratch_bytes = 0, storage_bytes = 0;
  std::vector<std::size_t> built;
  for (std::size_t m = 0; m < n; ++m) {
    if (meshes[m].triangles == 0) continue;
    VkAccelerationStructureGeometryKHR& g = geometry[m];
    g.geometryType = VK_GEOMETRY_TYPE_TRIANGLES_KHR;
    g.flags = meshes[m].opaque ? VK_GEOMETRY_OPAQUE_BIT_KHR : 0;
    VkAccelerationStructureGeometryTrianglesDataKHR& t = g.geometry.triangles;
    t.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR;
    t.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
    t.vertexData.deviceAddress = meshes[m].vertices;
    t.vertexStride = vertex_stride;
    t.maxVertex = 3 * meshes[m].triangles - 1;
    t.indexType = VK_INDEX_TYPE_NONE_KHR;
    VkAccelerationStructureBuildGeometryInfoKHR& b = info[m];
    b.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
    b.flags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;
    b.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
    b.geometryCount = 1;
    b.pGeometries = &g;
    VkAccelerationStructureBuildSizesInfoKHR sizes{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR};
    api.build_sizes(ctx_.device(), VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &b, &meshes[m].triangles, &sizes);
    storage_offset[m] = storage_bytes;
    storage_size[m] = sizes.accelerationStructureSize;
    storage_bytes += round_up(sizes.accelerationStructureSize, kStructureAlignment);
    scratch_offset[m] = scratch_bytes;
    scratch_bytes += round_up(sizes.buildScratchSize, align);
    range[m] = {meshes[m].triangles, 0, 0, 0};
    built.push_back(m);
  }
  if (built.empty()) return;
  bottom_storage_ = storage_buffer(ctx_, storage_bytes);
  const VkDeviceAddress base = scratch(scratch_bytes);
  std::vector<VkAccelerationStructureBuildGeometryInfoKHR> infos;
  std::vector<const VkAccelerationStructureBuildRangeInfoKHR*> ranges;
  for (const std::size_t m : built) {
    bottom_[m] = make(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, bottom_storage_, storage_offset[m], storage_size[m]);
    info[m].dstAccelerationStructure = bottom_[m].handle;
    info[m].scratchData.deviceAddress = base + scratch_offset[m];
    infos.push_back(info[m]);
    ranges.push_back(&range[m]);
  }
  ctx_.submit_and_wait([&](VkCommandBuffer cmd) {
    inputs_visible_to_build(cmd);
    api.cmd_build(cmd, static_cast<std::uint32_t>(infos.size()), infos.data(), ranges.data());
    build_visible_to_queries(cmd);
  });
}

void GpuAccelerationStructures::build_top(std::span<const TlasInstance> instances) {
  const AccelerationStructureApi& api = ctx_.acceleration_structures();
  // A queued build still reads the instances, the scratch and the TLAS this
  // one rewrites: it runs first.
  if (ctx_.has_deferred(this)) ctx_.flush();
  const auto count = static_cast<std::uint32_t>(instances.size());
  const std::size_t slots = std::max<std::size_t>(1, count);
  if (instances_.handle() == VK_NULL_HANDLE || instances_.size() < slots * sizeof(VkAccelerationStructureInstanceKHR))
    instances_ = GpuBuffer(ctx_, slots * sizeof(VkAccelerationStructureInstanceKHR), GpuBuffer::Placement::Mapped,
                           VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR | kAddressable);
  const auto out = instances_.mapped_as<VkAccelerationStructureInstanceKHR>(count);
  for (std::uint32_t i = 0; i < count; ++i) {
    const TlasInstance& in = instances[i];
    if (in.blas >= bottom_.size())
      throw GpuError("GpuAccelerationStructures::build_top: instance " + std::to_string(i) + " names mesh " +
                     std::to_string(in.blas) + " of " + std::to_string(bottom_.size()));
    if (in.custom_index >= (1u << 24))
      throw GpuError("GpuAccelerationStructures::build_top: custom index " + std::to_string(in.custom_index) +
                     " does not fit 24 bits");
    VkAccelerationStructureInstanceKHR& o = out[i];
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) o.transform.matrix[r][c] = in.object_to_world[r][c];
    o.instanceCustomIndex = in.custom_index & 0xffffffu;  // checked above
    o.mask = 0xff;
    o.instanceShaderBindingTableRecordOffset = 0;
    // Hits from both sides, as Embree's and the compute traversal's.
    o.flags = VK_GEOMETRY_INSTANCE_TRIANGLE_FACING_CULL_DISABLE_BIT_KHR;
    o.accelerationStructureReference = bottom_[in.blas].address;  // 0 (an empty mesh): inactive
  }

  // What the queued recording reads: the build info points at the geometry,
  // so both live with the recording.
  struct TopBuild {
    VkAccelerationStructureGeometryKHR g{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
    VkAccelerationStructureBuildGeometryInfoKHR b{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
    VkAccelerationStructureBuildRangeInfoKHR range{};
  };
  auto build = std::make_shared<TopBuild>();
  VkAccelerationStructureGeometryKHR& g = build->g;
  g.geometryType = VK_GEOMETRY_TYPE_INSTANCES_KHR;
  g.geometry.instances.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_INSTANCES_DATA_KHR;
  g.geometry.instances.arrayOfPointers = VK_FALSE;
  g.geometry.instances.data.deviceAddress = instances_.device_address();
  VkAccelerationStructureBuildGeometryInfoKHR& b = build->b;
  b.type = VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR;
  b.flags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;
  b.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
  b.geometryCount = 1;
  b.pGeometries = &g;
  const auto capacity = static_cast<std::uint32_t>(slots);
  VkAccelerationStructureBuildSizesInfoKHR sizes{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR};
  api.build_sizes(ctx_.device(), VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &b, &capacity, &sizes);
  if (!top_.handle || top_capacity_ < capacity) {
    destroy(top_);
    top_storage_ = storage_buffer(ctx_, sizes.accelerationStructureSize);
    top_ = make(VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, top_storage_, 0, sizes.accelerationStructureSize);
    top_capacity_ = capacity;
  }
  b.dstAccelerationStructure = top_.handle;
  b.scratchData.deviceAddress = scratch(sizes.buildScratchSize);
  build->range = {count, 0, 0, 0};
  // Nothing on the host waits for the TLAS: it is built at the head of the
  // next submission (the first that traces against it).
  ctx_.record_before_next(this, [build, &api](VkCommandBuffer cmd) {
    const VkAccelerationStructureBuildRangeInfoKHR* ranges = &build->range;
    inputs_visible_to_build(cmd);
    api.cmd_build(cmd, 1, &build->b, &ranges);
    build_visible_to_queries(cmd);
  });
}

}  // namespace engine::gpu
