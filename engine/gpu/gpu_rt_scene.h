#pragma once
// The ray-tracing scene on the GPU, mirrored from an RtScene: one BLAS per
// mesh asset and a TLAS over the live instances, rebuilt at every sync (a
// move needs no BLAS rebuild). Two traversals, chosen by the device
// (DeviceInfo::ray_query):
// - VK_KHR_ray_query: the driver builds the BLAS (over the triangle buffer,
//   whose corners are 16 bytes apart) and the TLAS on the device
//   (GpuAccelerationStructures) and traverses them, on RT cores where the
//   GPU has them;
// - elsewhere (lavapipe 22.3, GPUs without ray queries): BLAS built once on
//   the CPU (engine/rt/bvh_builder) and the TLAS at every sync (a few
//   thousand instances take well under a millisecond), uploaded with the
//   instances' world-to-object transforms and traversed in a compute shader.
// Kernels include shaders/rt_traversal.glsl, compiled with shader_defines(),
// make their pipelines with binding_types(), and bind() kBindings
// consecutive slots; both traversals give the same hits.
#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <vector>

#include "engine/gpu/compute_pipeline.h"
#include "engine/gpu/gpu_acceleration_structures.h"
#include "engine/gpu/gpu_buffer.h"
#include "engine/gpu/shader_compiler.h"
#include "engine/gpu/vulkan_context.h"
#include "engine/rt/bvh_builder.h"
#include "engine/rt/rt_scene.h"
#include "rt_shared.h"

namespace engine::gpu {

// Where the engine's kernels are read at run time: $ENGINE_SHADER_DIR, else
// the installed folder beside the program (bin/ ->
// ../ENGINE_INSTALLED_SHADER_DIR), else the source tree's.
std::filesystem::path engine_shader_dir();
// What the engine's kernels are compiled with: the folders their includes
// are found in (the shader folder, and installed, the headers' folder).
ShaderCompileOptions engine_shader_options();

// What a raster pass over the scene reads (VisibilityPass): the buffers
// rt_traversal.glsl's BVH variant binds, in its order (where the driver
// holds the TLAS, the instances' buffer stands in for the TLAS nodes, which
// no raster stage reads), and one draw per live instance: `triangles` of
// the triangle buffer from `first_triangle` (its mesh's finite ones), under
// InstanceGpu `instance`.
struct GpuRtRasterView {
  struct Draw {
    std::uint32_t first_triangle = 0, triangles = 0, instance = 0;
  };
  std::array<const GpuBuffer*, 8> buffers{};
  std::span<const Draw> draws;
};

struct GpuRtStats {
  bool ray_query = false;  // traced with VK_KHR_ray_query (the node counts are then 0)
  std::size_t blas_builds = 0;
  std::size_t blas_nodes = 0, triangles = 0, tlas_nodes = 0, instances = 0;
};

class GpuRtScene {
 public:
  explicit GpuRtScene(VulkanContext& ctx);
  ~GpuRtScene();
  GpuRtScene(const GpuRtScene&) = delete;
  GpuRtScene& operator=(const GpuRtScene&) = delete;

  // Mirrors rt's instances (and, for a new asset generation, its meshes).
  void sync(const rt::RtScene& rt);

  // Binds the TLAS, instances, BLAS, triangles and the alpha test's four
  // buffers at first .. first + 7 (rt_traversal.glsl's order); with ray
  // queries the TLAS is the acceleration structure.
  void bind(ComputePipeline& pipeline, std::uint32_t first) const;

  // What rt_traversal.glsl is compiled with on this device (RT_RAY_QUERY).
  static std::vector<ShaderDefine> shader_defines(const VulkanContext& ctx);
  // The descriptor types of a kernel with `total` bindings that binds the
  // scene at `first`: storage buffers, and the TLAS where it is an
  // acceleration structure.
  static std::vector<VkDescriptorType> binding_types(const VulkanContext& ctx, std::uint32_t first, std::uint32_t total);

  // Closest hits of a batch of rays (shaders/rt_query.comp) in the scene as
  // of the last sync; found[i] says whether ray i hit. Hits carry the entity
  // and instance id as Embree's do, so RtScene::instance_of and make_surface
  // take them.
  void intersect(std::span<const rt::Ray> rays, std::span<rt::Hit> hits, std::span<std::uint8_t> found,
                 double* gpu_ms = nullptr);
  // Shadow rays: blocked[i] = whether anything lies on ray i within
  // (tmin, tmax]; traversal stops at the first hit.
  void occluded(std::span<const rt::Ray> rays, std::span<std::uint8_t> blocked, double* gpu_ms = nullptr);

  // Shadow rays traced at the head of the device's next submission,
  // whichever stage makes it (VulkanContext::record_before_next), so that
  // they cost none of their own; take_occluded reads their answers (and
  // submits them alone if nothing else did). One batch at a time: a second
  // waits for the first.
  void occluded_later(std::span<const rt::Ray> rays);
  // blocked[i] for ray i of the batch occluded_later queued; throws GpuError
  // for another count or none queued.
  void take_occluded(std::span<std::uint8_t> blocked);
  // Closest hits' distances queued the same way (a batch of their own,
  // beside occluded_later's: both may ride with one submission), read by
  // take_distances: +infinity where a ray hits nothing up to its tmax.
  // Queued batches bring back 4 bytes a ray (shaders/rt_distances.comp).
  void distances_later(std::span<const rt::Ray> rays);
  void take_distances(std::span<float> distances);
  // Device milliseconds of this scene's queued work (the TLAS's builds,
  // the later batches) since the last call.
  double take_deferred_ms();
  // The entity of RtScene instance `id` as of the last sync (a hit's
  // Hit::entity), or none.
  [[nodiscard]] ecs::Entity entity_of(std::uint32_t id) const;
  // Its whole record (entity, mesh, transform), or null.
  [[nodiscard]] const rt::InstanceRecord* instance_record(std::uint32_t id) const;

  // For a raster pass; throws GpuError before the first sync.
  [[nodiscard]] GpuRtRasterView raster_view() const;

  // Bindings bind() fills.
  static constexpr std::uint32_t kBindings = 8;

  [[nodiscard]] const GpuRtStats& stats() const { return stats_; }

 private:
  // The query kernel over a batch; any_hit: stop at the first hit. The hits
  // are a view of the mapped result buffer, valid until the next query. Rays
  // go in and hits come out in parallel, straight through mapped memory: at
  // 1080p a serial copy each way cost more than the GPU's traversal.
  std::span<const HitGpu> run_query(std::span<const rt::Ray> rays, bool any_hit, double* gpu_ms);

  VulkanContext& ctx_;
  const rt::RtScene* synced_ = nullptr;
  std::uint64_t generation_ = 0;
  std::vector<std::uint32_t> blas_root_, triangle_offset_, finite_triangles_;  // per mesh
  std::vector<GpuRtRasterView::Draw> draws_;
  // Per mesh, the object-space box of its finite triangles: a mesh with a
  // stray non-finite vertex has a non-finite MeshAsset box, which would drop
  // every instance of it from the TLAS, while Embree skips only the
  // triangles that use it.
  std::vector<rt::BvhBox> mesh_box_;
  GpuBuffer tlas_, instances_, blas_, triangles_;
  GpuBuffer triangle_uvs_, alpha_materials_, alpha_bytes_, alpha_textures_;
  GpuBuffer rays_, hits_;
  // A batch queued for the next submission: its own kernel (its own
  // descriptor set, so that two batches can share a command buffer),
  // buffers and count (-1: none queued).
  struct LaterBatch {
    std::unique_ptr<ComputePipeline> kernel;
    GpuBuffer rays, distances;
    std::ptrdiff_t count = -1;
  };
  void queue_later(LaterBatch& batch, std::span<const rt::Ray> rays, bool any_hit);
  // The queued batch's distances (submitted now if nothing else did), or
  // throws GpuError for another count or none queued.
  std::span<const float> take_later(LaterBatch& batch, std::size_t count, const char* what);
  // A query's hit as RtScene's.
  void to_hit(const HitGpu& in, rt::Hit& out) const;
  LaterBatch later_occluded_, later_distances_;
  std::vector<std::uint32_t> distances_spirv_;  // rt_distances.comp, for each queued batch's kernel
  std::unique_ptr<ComputePipeline> query_;
  std::unique_ptr<GpuAccelerationStructures> structures_;  // ray queries only
  GpuRtStats stats_;
};

}  // namespace engine::gpu
