#include "engine/gpu/gpu_rt_scene.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <limits>
#include <string_view>

#include "engine/core/install_paths.h"
#include "engine/gpu/gpu_error.h"
#include "engine/gpu/shader_compiler.h"
#include "engine/jobs/parallel_for.h"
#include "engine/rt/bvh_builder.h"
#include "rt_shared.h"

namespace engine::gpu {

std::filesystem::path engine_shader_dir() {
  if (const char* env = std::getenv("ENGINE_SHADER_DIR"); env && *env) return env;
  if (const std::string_view installed = ENGINE_INSTALLED_SHADER_DIR; !installed.empty())
    if (auto dir = core::beside_executable(std::filesystem::path("..") / installed)) return *dir;
  return ENGINE_SOURCE_SHADER_DIR;
}

ShaderCompileOptions engine_shader_options() {
  const auto dir = engine_shader_dir();
  ShaderCompileOptions options;
  options.include_dirs.push_back(dir);
  // Installed, the headers the kernels share with C++ are with the C++ headers.
  if (auto shared = core::installed_twin(dir, ENGINE_INSTALLED_SHADER_DIR, ENGINE_INSTALLED_SHADER_INCLUDE_DIR))
    options.include_dirs.push_back(*shared);
  return options;
}

namespace {

BvhNodeGpu to_gpu(const rt::BvhNode& n) {
  return {n.bounds.min.x, n.bounds.min.y, n.bounds.min.z, n.first, n.bounds.max.x, n.bounds.max.y, n.bounds.max.z, n.count};
}

// `what` names the data in the error where it is larger than a kernel can bind.
template <class T>
void upload_to(VulkanContext& ctx, GpuBuffer& b, const std::vector<T>& v, const char* what,
               GpuBuffer::Placement placement = GpuBuffer::Placement::Mapped, VkBufferUsageFlags usage = 0) {
  const std::size_t bytes = v.size() * sizeof(T);
  require_storage_range(ctx, bytes, "GpuRtScene", what);
  if (b.handle() == VK_NULL_HANDLE || b.size() < bytes) b = GpuBuffer(ctx, bytes, placement, usage);
  b.upload(std::span<const T>(v));
}

// Every ray reads the scene many times and the CPU changes it at most once a
// frame (the TLAS): device memory, not a PCIe fetch per node.
constexpr GpuBuffer::Placement kStatic = GpuBuffer::Placement::DeviceOnly;
constexpr std::size_t kRaysPerTask = 4096;

// The triangle buffer is also the ray-query BLAS's vertex buffer: TriangleGpu
// keeps its corners 16 bytes apart (p0 at 0, p1 at 16, p2 at 32).
constexpr VkDeviceSize kCornerStride = 16;
static_assert(offsetof(TriangleGpu, p1_x) == kCornerStride && offsetof(TriangleGpu, p2_x) == 2 * kCornerStride &&
              sizeof(TriangleGpu) == 3 * kCornerStride);

bool finite(glm::vec3 p) { return !glm::any(glm::isnan(p)) && !glm::any(glm::isinf(p)); }

// The world box around an object-space box under a similarity (its eight
// corners carried over).
rt::BvhBox world_box(const rt::BvhBox& b, const transform::Similarity& s) {
  glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
  for (int k = 0; k < 8; ++k) {
    const glm::vec3 p = s.apply_point({k & 1 ? b.max.x : b.min.x, k & 2 ? b.max.y : b.min.y, k & 4 ? b.max.z : b.min.z});
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  return {lo, hi};
}

// A similarity's object-to-world 3 x 4 matrix, rows first (the TLAS's).
void object_to_world(const transform::Similarity& s, float out[3][4]) {
  const glm::mat3 r = glm::mat3_cast(s.rotation) * s.scale;
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 3; ++col) out[row][col] = r[col][row];
    out[row][3] = s.translation[row];
  }
}

}  // namespace

std::vector<ShaderDefine> GpuRtScene::shader_defines(const VulkanContext& ctx) {
  if (ctx.info().ray_query) return {{"RT_RAY_QUERY", "1"}};
  return {};
}

std::vector<VkDescriptorType> GpuRtScene::binding_types(const VulkanContext& ctx, std::uint32_t first, std::uint32_t total) {
  std::vector<VkDescriptorType> types(total, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER);
  if (ctx.info().ray_query && first < total) types[first] = VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR;
  return types;
}

GpuRtScene::GpuRtScene(VulkanContext& ctx) : ctx_(ctx) {
  const auto dir = engine_shader_dir();
  ShaderCompileOptions options = engine_shader_options();
  options.defines = shader_defines(ctx);
  query_ = std::make_unique<ComputePipeline>(ctx, compile_compute_shader(dir / "rt_query.comp", options),
                                             binding_types(ctx, 2, 2 + kBindings),
                                             static_cast<std::uint32_t>(2 * sizeof(std::uint32_t)));
  distances_spirv_ = compile_compute_shader(dir / "rt_distances.comp", options);
  stats_.ray_query = ctx.info().ray_query;
  if (stats_.ray_query) structures_ = std::make_unique<GpuAccelerationStructures>(ctx);
}

GpuRtScene::~GpuRtScene() { ctx_.forget_deferred(this); }

void GpuRtScene::sync(const rt::RtScene& rt) {
  // A queued batch reads the instances and meshes this rewrites.
  if (ctx_.has_deferred(this)) ctx_.flush();
  synced_ = &rt;
  const scene::SceneAssets* assets = rt.assets();
  if (assets && assets->generation != generation_) {
    generation_ = assets->generation;
    std::vector<BvhNodeGpu> nodes;
    std::vector<TriangleGpu> tris;
    std::vector<RtTriangleUvGpu> uvs;
    // The alpha test's materials and textures: only the masked ones.
    std::vector<RtAlphaMaterialGpu> alpha_materials;
    std::vector<RtAlphaTextureGpu> alpha_textures;
    std::vector<std::uint32_t> alpha_bytes;
    std::vector<std::uint32_t> alpha_of_material(assets->materials.size(), kRtOpaque);
    std::vector<int> alpha_of_texture(assets->textures.size(), -1);
    for (std::size_t mi = 0; mi < assets->materials.size(); ++mi) {
      const material::Material& m = assets->materials[mi];
      if (m.alpha_mode != material::AlphaMode::Mask) continue;
      int tex = -1;
      const int ti = m.base_color_texture;
      if (ti >= 0 && static_cast<std::size_t>(ti) < assets->textures.size()) {
        if (alpha_of_texture[static_cast<std::size_t>(ti)] < 0) {
          const scene::Texture& t = assets->textures[static_cast<std::size_t>(ti)];
          const std::size_t texels = static_cast<std::size_t>(t.width) * static_cast<std::size_t>(t.height);
          const std::size_t first = alpha_bytes.size() * 4;
          alpha_bytes.resize((first + texels + 3) / 4, 0u);
          for (std::size_t i = 0; i < texels; ++i)
            alpha_bytes[(first + i) / 4] |= static_cast<std::uint32_t>(t.rgba[i * 4 + 3]) << ((first + i) % 4 * 8);
          alpha_of_texture[static_cast<std::size_t>(ti)] = static_cast<int>(alpha_textures.size());
          alpha_textures.push_back({static_cast<std::uint32_t>(first), t.width, t.height,
                                    static_cast<std::uint32_t>(t.wrap_s) | static_cast<std::uint32_t>(t.wrap_t) << 8});
        }
        tex = alpha_of_texture[static_cast<std::size_t>(ti)];
      }
      alpha_of_material[mi] = static_cast<std::uint32_t>(alpha_materials.size());
      alpha_materials.push_back({m.base_color_factor.a, m.alpha_cutoff, tex, 0});
    }
    blas_root_.assign(assets->meshes.size(), 0);
    triangle_offset_.assign(assets->meshes.size(), 0);
    finite_triangles_.assign(assets->meshes.size(), 0);
    mesh_box_.assign(assets->meshes.size(), rt::BvhBox{});
    std::vector<BlasInput> blas_inputs(assets->meshes.size());
    for (std::size_t m = 0; m < assets->meshes.size(); ++m) {
      const scene::MeshAsset& mesh = *assets->meshes[m];
      std::vector<rt::BvhBox> boxes(mesh.triangles.size());
      std::vector<std::uint32_t> finite_triangles, broken_triangles;
      glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
      for (std::uint32_t t = 0; t < boxes.size(); ++t) {
        const glm::uvec3 tri = mesh.triangles[t];
        const glm::vec3 a = mesh.positions[tri.x], b = mesh.positions[tri.y], c = mesh.positions[tri.z];
        boxes[t] = {glm::min(a, glm::min(b, c)), glm::max(a, glm::max(b, c))};
        // Embree skips a triangle with a non-finite corner; so do both traversals.
        if (!(finite(a) && finite(b) && finite(c))) {
          broken_triangles.push_back(t);
          continue;
        }
        finite_triangles.push_back(t);
        lo = glm::min(lo, boxes[t].min);
        hi = glm::max(hi, boxes[t].max);
      }
      if (!finite_triangles.empty()) mesh_box_[m] = {lo, hi};
      rt::Bvh bvh;
      if (stats_.ray_query) {
        // The driver builds the BLAS over the finite triangles, in the mesh's
        // order; the broken ones follow, outside it.
        bvh.order = finite_triangles;
        bvh.order.insert(bvh.order.end(), broken_triangles.begin(), broken_triangles.end());
      } else {
        bvh = rt::build_bvh(boxes);  // non-finite boxes are listed last, outside every leaf
      }
      blas_root_[m] = static_cast<std::uint32_t>(nodes.size());
      triangle_offset_[m] = static_cast<std::uint32_t>(tris.size());
      blas_inputs[m].triangles = static_cast<std::uint32_t>(finite_triangles.size());
      // Both orders list the finite triangles first.
      finite_triangles_[m] = static_cast<std::uint32_t>(finite_triangles.size());
      for (const auto& n : bvh.nodes) nodes.push_back(to_gpu(n));
      for (std::uint32_t item : bvh.order) {
        const glm::uvec3 tri = mesh.triangles[item];
        const glm::vec3 a = mesh.positions[tri.x], b = mesh.positions[tri.y], c = mesh.positions[tri.z];
        const std::uint32_t mat = item < mesh.triangle_material.size() ? mesh.triangle_material[item] : 0;
        const std::uint32_t alpha = mat < alpha_of_material.size() ? alpha_of_material[mat] : kRtOpaque;
        tris.push_back({a.x, a.y, a.z, item, b.x, b.y, b.z, alpha, c.x, c.y, c.z, 0});
        if (alpha != kRtOpaque) blas_inputs[m].opaque = false;
        RtTriangleUvGpu uv{};
        if (!mesh.uvs.empty()) {
          uv = {mesh.uvs[tri.x].x, mesh.uvs[tri.x].y, mesh.uvs[tri.y].x, mesh.uvs[tri.y].y,
                mesh.uvs[tri.z].x, mesh.uvs[tri.z].y, 1u, 0u};
        }
        uvs.push_back(uv);
      }
      ++stats_.blas_builds;
    }
    if (uvs.empty()) uvs.push_back({});
    if (alpha_materials.empty()) alpha_materials.push_back({});
    if (alpha_textures.empty()) alpha_textures.push_back({});
    if (alpha_bytes.empty()) alpha_bytes.push_back(0);
    upload_to(ctx_, triangle_uvs_, uvs, "triangle texture coordinates", kStatic);
    upload_to(ctx_, alpha_materials_, alpha_materials, "alpha-tested materials", kStatic);
    upload_to(ctx_, alpha_bytes_, alpha_bytes, "alpha textures", kStatic);
    upload_to(ctx_, alpha_textures_, alpha_textures, "alpha texture table", kStatic);
    if (nodes.empty()) nodes.push_back(to_gpu(rt::BvhNode{}));
    if (tris.empty()) tris.push_back({});
    upload_to(ctx_, blas_, nodes, "mesh BVH nodes", kStatic);
    const VkBufferUsageFlags build_input =
        stats_.ray_query ? VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT : 0;
    upload_to(ctx_, triangles_, tris, "triangles", kStatic, build_input);
    stats_.blas_nodes = stats_.ray_query ? 0 : nodes.size();
    stats_.triangles = tris.size();
    if (structures_) {
      for (std::size_t m = 0; m < blas_inputs.size(); ++m)
        blas_inputs[m].vertices = triangles_.device_address() + triangle_offset_[m] * sizeof(TriangleGpu);
      structures_->build_bottom(blas_inputs, kCornerStride);
    }
  }

  std::vector<const rt::InstanceRecord*> live;
  std::vector<std::uint32_t> ids;
  std::vector<rt::BvhBox> boxes;
  for (std::uint32_t id = 0; id < rt.instance_id_end(); ++id) {
    const rt::InstanceRecord* r = rt.instance(id);
    if (!r || r->mesh >= blas_root_.size()) continue;
    live.push_back(r);
    ids.push_back(id);
    if (!structures_) boxes.push_back(world_box(mesh_box_[r->mesh], r->to_world));
  }
  // With ray queries the driver builds the TLAS (build_top below): the
  // instances keep their id order, and no node buffer is made or uploaded.
  rt::Bvh tlas;
  if (structures_) {
    tlas.order.resize(live.size());
    for (std::uint32_t i = 0; i < tlas.order.size(); ++i) tlas.order[i] = i;
  } else {
    tlas = rt::build_bvh(boxes, 1);
  }
  std::vector<InstanceGpu> instances;
  std::vector<TlasInstance> tlas_instances;
  draws_.clear();
  for (std::uint32_t item : tlas.order) {
    const rt::InstanceRecord& r = *live[item];
    if (finite_triangles_[r.mesh] > 0)
      draws_.push_back({triangle_offset_[r.mesh], finite_triangles_[r.mesh], static_cast<std::uint32_t>(instances.size())});
    // World to object: x_o = R^T (x_w - T) / s, as rows of a 3 x 4 matrix.
    const glm::mat3 rt_ = glm::transpose(glm::mat3_cast(r.to_world.rotation)) / r.to_world.scale;
    const glm::vec3 off = -(rt_ * r.to_world.translation);
    instances.push_back({rt_[0][0], rt_[1][0], rt_[2][0], off.x, rt_[0][1], rt_[1][1], rt_[2][1], off.y, rt_[0][2],
                         rt_[1][2], rt_[2][2], off.z, blas_root_[r.mesh], triangle_offset_[r.mesh], ids[item], r.mesh});
    if (structures_) {
      TlasInstance t;
      object_to_world(r.to_world, t.object_to_world);
      t.custom_index = static_cast<std::uint32_t>(instances.size() - 1);  // its InstanceGpu
      t.blas = r.mesh;
      tlas_instances.push_back(t);
    }
  }
  if (instances.empty()) instances.push_back({});
  upload_to(ctx_, instances_, instances, "instances", kStatic);
  stats_.instances = live.size();
  if (structures_) {
    structures_->build_top(tlas_instances);
    return;
  }
  std::vector<BvhNodeGpu> nodes;
  for (const auto& n : tlas.nodes) nodes.push_back(to_gpu(n));
  upload_to(ctx_, tlas_, nodes, "instance BVH nodes", kStatic);
  stats_.tlas_nodes = nodes.size();
}

void GpuRtScene::bind(ComputePipeline& pipeline, std::uint32_t first) const {
  if (instances_.handle() == VK_NULL_HANDLE) throw GpuError("GpuRtScene::bind before sync");
  if (structures_) pipeline.bind(first, structures_->top());
  else pipeline.bind(first, tlas_);
  pipeline.bind(first + 1, instances_);
  pipeline.bind(first + 2, blas_);
  pipeline.bind(first + 3, triangles_);
  pipeline.bind(first + 4, triangle_uvs_);
  pipeline.bind(first + 5, alpha_materials_);
  pipeline.bind(first + 6, alpha_bytes_);
  pipeline.bind(first + 7, alpha_textures_);
}

ecs::Entity GpuRtScene::entity_of(std::uint32_t id) const {
  const rt::InstanceRecord* record = instance_record(id);
  return record ? record->entity : ecs::Entity{};
}

const rt::InstanceRecord* GpuRtScene::instance_record(std::uint32_t id) const { return synced_ ? synced_->instance(id) : nullptr; }

GpuRtRasterView GpuRtScene::raster_view() const {
  if (instances_.handle() == VK_NULL_HANDLE) throw GpuError("GpuRtScene::raster_view before sync");
  GpuRtRasterView v;
  v.buffers = {structures_ ? &instances_ : &tlas_, &instances_, &blas_, &triangles_, &triangle_uvs_, &alpha_materials_,
               &alpha_bytes_, &alpha_textures_};
  v.draws = draws_;
  return v;
}

namespace {
// A ray as rt_query.comp reads it.
void write_rays(std::span<const rt::Ray> rays, std::span<RayGpu> in) {
  jobs::parallel_for<std::size_t>(0, rays.size(), kRaysPerTask, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      const rt::Ray& r = rays[i];
      in[i] = {r.origin.x, r.origin.y, r.origin.z, r.tmin, r.direction.x, r.direction.y, r.direction.z, r.tmax};
    }
  });
}
}  // namespace

void GpuRtScene::queue_later(LaterBatch& batch, std::span<const rt::Ray> rays, bool any_hit) {
  // One batch a slot: a second waits for the first.
  if (batch.count >= 0 && ctx_.has_deferred(this)) ctx_.flush();
  const std::size_t n = rays.size();
  batch.count = static_cast<std::ptrdiff_t>(n);
  if (n == 0) return;
  if (!batch.kernel)
    batch.kernel = std::make_unique<ComputePipeline>(ctx_, distances_spirv_, binding_types(ctx_, 2, 2 + kBindings),
                                                     static_cast<std::uint32_t>(2 * sizeof(std::uint32_t)));
  if (batch.rays.handle() == VK_NULL_HANDLE || batch.rays.size() < n * sizeof(RayGpu)) batch.rays = GpuBuffer(ctx_, n * sizeof(RayGpu));
  if (batch.distances.handle() == VK_NULL_HANDLE || batch.distances.size() < n * sizeof(float))
    batch.distances = GpuBuffer(ctx_, n * sizeof(float));
  write_rays(rays, batch.rays.mapped_as<RayGpu>(n));
  // Bound when the submission is recorded, after any sync before it.
  ctx_.record_before_next(this, [this, &batch, n, any_hit](VkCommandBuffer cmd) {
    batch.kernel->bind(0, batch.rays);
    batch.kernel->bind(1, batch.distances);
    bind(*batch.kernel, 2);
    const std::uint32_t push[2] = {static_cast<std::uint32_t>(n), any_hit ? 1u : 0u};
    batch.kernel->record_dispatch(cmd, (push[0] + kRtGroupSize - 1) / kRtGroupSize, 1, 1, push);
  });
}

std::span<const float> GpuRtScene::take_later(LaterBatch& batch, std::size_t count, const char* what) {
  if (batch.count < 0 || static_cast<std::size_t>(batch.count) != count)
    throw GpuError(std::string("GpuRtScene::") + what + ": " + std::to_string(count) + " answers for a batch of " +
                   (batch.count < 0 ? std::string("none") : std::to_string(batch.count)));
  batch.count = -1;
  if (count == 0) return {};
  if (ctx_.has_deferred(this)) ctx_.flush();
  return batch.distances.mapped_as<const float>(count);
}

void GpuRtScene::occluded_later(std::span<const rt::Ray> rays) { queue_later(later_occluded_, rays, true); }

void GpuRtScene::take_occluded(std::span<std::uint8_t> blocked) {
  const std::span<const float> out = take_later(later_occluded_, blocked.size(), "take_occluded");
  jobs::parallel_for<std::size_t>(0, out.size(), kRaysPerTask, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) blocked[i] = std::isinf(out[i]) ? 0 : 1;
  });
}

void GpuRtScene::distances_later(std::span<const rt::Ray> rays) { queue_later(later_distances_, rays, false); }

void GpuRtScene::take_distances(std::span<float> distances) {
  const std::span<const float> out = take_later(later_distances_, distances.size(), "take_distances");
  std::copy(out.begin(), out.end(), distances.begin());
}

void GpuRtScene::to_hit(const HitGpu& h, rt::Hit& out) const {
  out.entity = entity_of(h.instance);
  out.instance = h.instance;
  out.mesh = h.mesh;
  out.primitive = h.primitive;
  out.barycentric = {h.u, h.v};
  out.t = h.t;
}

double GpuRtScene::take_deferred_ms() {
  return ctx_.take_deferred_ms(this) + (structures_ ? ctx_.take_deferred_ms(structures_.get()) : 0.0);
}

std::span<const HitGpu> GpuRtScene::run_query(std::span<const rt::Ray> rays, bool any_hit, double* gpu_ms) {
  // Queued batches have kernels of their own: they ride at the head of this
  // submission.
  const std::size_t n = rays.size();
  if (rays_.handle() == VK_NULL_HANDLE || rays_.size() < n * sizeof(RayGpu)) rays_ = GpuBuffer(ctx_, n * sizeof(RayGpu));
  if (hits_.handle() == VK_NULL_HANDLE || hits_.size() < n * sizeof(HitGpu)) hits_ = GpuBuffer(ctx_, n * sizeof(HitGpu));
  write_rays(rays, rays_.mapped_as<RayGpu>(n));
  query_->bind(0, rays_);
  query_->bind(1, hits_);
  bind(*query_, 2);
  const std::uint32_t push[2] = {static_cast<std::uint32_t>(n), any_hit ? 1u : 0u};
  const double ms = ctx_.submit_and_wait([&](VkCommandBuffer cmd) {
    query_->record_dispatch(cmd, (push[0] + kRtGroupSize - 1) / kRtGroupSize, 1, 1, push);
  });
  if (gpu_ms) *gpu_ms = ms;
  return hits_.mapped_as<const HitGpu>(n);
}

void GpuRtScene::intersect(std::span<const rt::Ray> rays, std::span<rt::Hit> hits, std::span<std::uint8_t> found,
                           double* gpu_ms) {
  if (hits.size() != rays.size() || found.size() != rays.size())
    throw GpuError("GpuRtScene::intersect: " + std::to_string(rays.size()) + " rays, " + std::to_string(hits.size()) +
                   " hits, " + std::to_string(found.size()) + " flags");
  if (rays.empty()) return;
  const std::span<const HitGpu> out = run_query(rays, false, gpu_ms);
  jobs::parallel_for<std::size_t>(0, rays.size(), kRaysPerTask, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      const HitGpu h = out[i];
      found[i] = h.instance != kRtNoHit ? 1 : 0;
      if (found[i]) to_hit(h, hits[i]);
    }
  });
}

void GpuRtScene::occluded(std::span<const rt::Ray> rays, std::span<std::uint8_t> blocked, double* gpu_ms) {
  if (blocked.size() != rays.size())
    throw GpuError("GpuRtScene::occluded: " + std::to_string(rays.size()) + " rays, " + std::to_string(blocked.size()) + " flags");
  if (rays.empty()) return;
  const std::span<const HitGpu> out = run_query(rays, true, gpu_ms);
  jobs::parallel_for<std::size_t>(0, rays.size(), kRaysPerTask, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) blocked[i] = out[i].instance != kRtNoHit ? 1 : 0;
  });
}

}  // namespace engine::gpu
