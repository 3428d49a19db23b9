#include "engine/rt/rt_scene.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <string>

#include "engine/core/cpu_isa.h"

namespace engine::rt {

namespace {

// Embree calls this on the thread of the failing API call. Throwing through
// Embree's C frames would be undefined, so the message is kept and raised by
// check_embree() right after the call.
thread_local std::string g_embree_error;

void embree_error(void*, RTCError code, const char* message) {
  if (code == RTC_ERROR_NONE) return;
  g_embree_error = "Embree error " + std::to_string(static_cast<int>(code)) + ": " + (message ? message : "");
}

void check_embree(const char* what) {
  if (g_embree_error.empty()) return;
  const std::string msg = std::string(what) + ": " + g_embree_error;
  g_embree_error.clear();
  throw RtError(msg);
}

// Data the alpha filter needs for one mesh.
struct AlphaTestData {
  const scene::MeshAsset* mesh = nullptr;
  const scene::SceneAssets* assets = nullptr;
};

bool alpha_passes(const AlphaTestData& d, std::uint32_t prim, float u, float v) {
  const auto& mat = d.assets->materials[d.mesh->triangle_material[prim]];
  if (mat.alpha_mode != material::AlphaMode::Mask) return true;
  float alpha = mat.base_color_factor.a;
  if (mat.base_color_texture >= 0 && !d.mesh->uvs.empty()) {
    const glm::uvec3 t = d.mesh->triangles[prim];
    const glm::vec2 uv = (1 - u - v) * d.mesh->uvs[t.x] + u * d.mesh->uvs[t.y] + v * d.mesh->uvs[t.z];
    alpha *= d.assets->textures[static_cast<std::size_t>(mat.base_color_texture)].alpha_nearest(uv);
  }
  return alpha >= mat.alpha_cutoff;
}

void alpha_filter(const RTCFilterFunctionNArguments* args) {
  const auto* data = static_cast<const AlphaTestData*>(args->geometryUserPtr);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    const unsigned prim = RTCHitN_primID(args->hit, args->N, i);
    if (!alpha_passes(*data, prim, RTCHitN_u(args->hit, args->N, i), RTCHitN_v(args->hit, args->N, i)))
      args->valid[i] = 0;
  }
}

}  // namespace

// Embree dispatches on the CPU by itself; max_isa holds it to the engine's
// effective level, so a capped run traces rays as that machine would.
namespace {
std::string embree_config() {
  switch (cpu::effective_isa()) {
    case cpu::Isa::Scalar: return "verbose=0,max_isa=sse2";
    case cpu::Isa::Avx2: return "verbose=0,max_isa=avx2";
    default: return "verbose=0";
  }
}
}  // namespace

struct RtScene::Impl {
  RTCDevice device = nullptr;
  RTCScene top = nullptr;
  std::vector<RTCScene> blas;  // by mesh index, built on demand
  std::vector<std::unique_ptr<AlphaTestData>> alpha_data;
  std::vector<std::uint32_t> free_ids;

  Impl() {
    device = rtcNewDevice(embree_config().c_str());
    if (!device) throw RtError("cannot create Embree device (error " + std::to_string(rtcGetDeviceError(nullptr)) + ")");
    rtcSetDeviceErrorFunction(device, embree_error, nullptr);
    top = rtcNewScene(device);
    rtcSetSceneFlags(top, RTC_SCENE_FLAG_DYNAMIC);
    rtcSetSceneBuildQuality(top, RTC_BUILD_QUALITY_LOW);
    // Committed empty, so a query before the first sync misses instead of
    // leaving Embree's sticky "scene not committed" error for the next check.
    rtcCommitScene(top);
  }
  ~Impl() {
    for (RTCScene s : blas)
      if (s) rtcReleaseScene(s);
    if (top) rtcReleaseScene(top);
    if (device) rtcReleaseDevice(device);
  }
  void release_blas() {
    for (RTCScene& s : blas)
      if (s) rtcReleaseScene(s), s = nullptr;
    alpha_data.clear();
  }
};

RtScene::RtScene() : impl_(std::make_unique<Impl>()) {}
RtScene::~RtScene() = default;

namespace {
WorldBounds world_bounds(const scene::MeshAsset& m, const transform::Similarity& to_world) {
  WorldBounds b{glm::vec3(std::numeric_limits<float>::infinity()), glm::vec3(-std::numeric_limits<float>::infinity())};
  for (int c = 0; c < 8; ++c) {
    const glm::vec3 corner((c & 1) ? m.bounds_max.x : m.bounds_min.x, (c & 2) ? m.bounds_max.y : m.bounds_min.y,
                           (c & 4) ? m.bounds_max.z : m.bounds_min.z);
    const glm::vec3 w = to_world.apply_point(corner);
    b.min = glm::min(b.min, w);
    b.max = glm::max(b.max, w);
  }
  return b;
}
}  // namespace

void RtScene::set_assets(const scene::SceneAssets* assets) {
  if (assets == assets_ && (!assets || assets->generation == generation_)) return;
  // A new asset set invalidates every instance and mesh scene.
  for (const auto& [entity, id] : entity_to_id_) rtcDetachGeometry(impl_->top, id);
  entity_to_id_.clear();
  instances_.clear();
  impl_->free_ids.clear();
  impl_->release_blas();
  assets_ = assets;
  generation_ = assets ? assets->generation : 0;
  impl_->blas.assign(assets_ ? assets_->meshes.size() : 0, nullptr);
  dirty_ = true;
}

void RtScene::upsert_instance(ecs::Entity e, std::uint32_t mesh, const transform::Similarity& to_world) {
  if (!assets_ || mesh >= assets_->meshes.size())
    throw RtError("instance of mesh " + std::to_string(mesh) + " but the scene has " +
                  std::to_string(assets_ ? assets_->meshes.size() : 0) + " meshes");
  if (mesh >= impl_->blas.size()) impl_->blas.resize(assets_->meshes.size(), nullptr);  // meshes added at run time
  if (!impl_->blas[mesh]) {
    const scene::MeshAsset& m = *assets_->meshes[mesh];
    RTCScene s = rtcNewScene(impl_->device);
    RTCGeometry g = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                           3 * sizeof(float), m.positions.size()));
    for (std::size_t i = 0; i < m.positions.size(); ++i) {
      vb[3 * i + 0] = m.positions[i].x;
      vb[3 * i + 1] = m.positions[i].y;
      vb[3 * i + 2] = m.positions[i].z;
    }
    auto* ib = static_cast<unsigned*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                              3 * sizeof(unsigned), m.triangles.size()));
    for (std::size_t i = 0; i < m.triangles.size(); ++i) {
      ib[3 * i + 0] = m.triangles[i].x;
      ib[3 * i + 1] = m.triangles[i].y;
      ib[3 * i + 2] = m.triangles[i].z;
    }
    bool needs_alpha = false;
    for (std::uint32_t mat : m.triangle_material)
      needs_alpha = needs_alpha || assets_->materials[mat].alpha_mode == material::AlphaMode::Mask;
    if (needs_alpha) {
      impl_->alpha_data.push_back(std::make_unique<AlphaTestData>(AlphaTestData{&m, assets_}));
      rtcSetGeometryUserData(g, impl_->alpha_data.back().get());
      rtcSetGeometryIntersectFilterFunction(g, alpha_filter);
      rtcSetGeometryOccludedFilterFunction(g, alpha_filter);
    }
    rtcCommitGeometry(g);
    rtcAttachGeometry(s, g);
    rtcReleaseGeometry(g);
    rtcCommitScene(s);
    check_embree(("building mesh scene for '" + m.name + "'").c_str());
    impl_->blas[mesh] = s;
    ++stats_.blas_builds;
  }

  const glm::mat4 matrix = to_world.matrix();
  const WorldBounds bounds = world_bounds(*assets_->meshes[mesh], to_world);
  auto it = entity_to_id_.find(e);
  if (it != entity_to_id_.end() && instances_[it->second].mesh == mesh) {
    RTCGeometry inst = rtcGetGeometry(impl_->top, it->second);
    rtcSetGeometryTransform(inst, 0, RTC_FORMAT_FLOAT4X4_COLUMN_MAJOR, &matrix[0][0]);
    rtcCommitGeometry(inst);
    InstanceRecord& r = instances_[it->second];
    changed_pending_.push_back({glm::min(r.bounds.min, bounds.min), glm::max(r.bounds.max, bounds.max)});
    r.to_world = to_world;
    r.bounds = bounds;
    ++stats_.instances_moved;
    dirty_ = true;
    return;
  }
  if (it != entity_to_id_.end()) remove_instance(e);  // the mesh itself changed

  RTCGeometry inst = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_INSTANCE);
  rtcSetGeometryInstancedScene(inst, impl_->blas[mesh]);
  rtcSetGeometryTimeStepCount(inst, 1);
  rtcSetGeometryTransform(inst, 0, RTC_FORMAT_FLOAT4X4_COLUMN_MAJOR, &matrix[0][0]);
  rtcCommitGeometry(inst);
  std::uint32_t id;
  if (!impl_->free_ids.empty()) {
    id = impl_->free_ids.back();
    impl_->free_ids.pop_back();
    rtcAttachGeometryByID(impl_->top, inst, id);
  } else {
    id = rtcAttachGeometry(impl_->top, inst);
  }
  rtcReleaseGeometry(inst);
  check_embree("adding an instance");
  if (id >= instances_.size()) instances_.resize(id + 1);
  instances_[id] = InstanceRecord{e, mesh, to_world, true, bounds};
  changed_pending_.push_back(bounds);
  entity_to_id_[e] = id;
  ++stats_.instances_added;
  dirty_ = true;
}

void RtScene::remove_instance(ecs::Entity e) {
  auto it = entity_to_id_.find(e);
  if (it == entity_to_id_.end()) return;
  rtcDetachGeometry(impl_->top, it->second);
  instances_[it->second].active = false;
  changed_pending_.push_back(instances_[it->second].bounds);
  impl_->free_ids.push_back(it->second);
  entity_to_id_.erase(it);
  ++stats_.instances_removed;
  dirty_ = true;
}

void RtScene::commit() {
  if (!dirty_) return;
  rtcCommitScene(impl_->top);
  check_embree("committing the top-level scene");
  ++stats_.top_level_commits;
  dirty_ = false;
  changed_at_commit_ = std::move(changed_pending_);
  changed_pending_.clear();
  RTCBounds b;
  rtcGetSceneBounds(impl_->top, &b);
  if (entity_to_id_.empty()) {
    bounds_min_ = bounds_max_ = glm::vec3(0.0f);
  } else {
    bounds_min_ = {b.lower_x, b.lower_y, b.lower_z};
    bounds_max_ = {b.upper_x, b.upper_y, b.upper_z};
  }
  const glm::vec3 m = glm::max(glm::abs(bounds_min_), glm::abs(bounds_max_));
  const float extent = std::max(m.x, std::max(m.y, m.z));
  offset_scale_ = std::isfinite(extent) && extent > 0 ? std::clamp(extent, 1e-6f, 1.0f) : 1.0f;
}

namespace {
bool valid_ray(const Ray& r) {
  return is_finite(r.origin) && is_finite(r.direction) && !std::isnan(r.tmin) && !std::isnan(r.tmax) &&
         (r.direction.x != 0 || r.direction.y != 0 || r.direction.z != 0);
}
void fill(RTCRay& out, const Ray& r) {
  out.org_x = r.origin.x;
  out.org_y = r.origin.y;
  out.org_z = r.origin.z;
  out.dir_x = r.direction.x;
  out.dir_y = r.direction.y;
  out.dir_z = r.direction.z;
  out.tnear = r.tmin;
  out.tfar = r.tmax;
  out.time = 0.0f;
  out.mask = 0xffffffffu;
  out.id = 0;
  out.flags = 0;
}
}  // namespace

bool RtScene::intersect(const Ray& ray, Hit& hit) const {
  if (!valid_ray(ray)) {
    rejected_.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  RTCRayHit rh;
  fill(rh.ray, ray);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(impl_->top, &ctx, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
  const InstanceRecord& inst = instances_[rh.hit.instID[0]];
  hit.entity = inst.entity;
  hit.instance = rh.hit.instID[0];
  hit.mesh = inst.mesh;
  hit.primitive = rh.hit.primID;
  hit.barycentric = {rh.hit.u, rh.hit.v};
  hit.t = rh.ray.tfar;
  return true;
}

bool RtScene::occluded(const Ray& ray) const {
  if (!valid_ray(ray)) {
    rejected_.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  RTCRay r;
  fill(r, ray);
  rtcOccluded1(impl_->top, &ctx, &r);
  return r.tfar < 0.0f;  // Embree sets tfar = -inf on a hit
}

namespace {
template <class Packet>
void fill16(Packet& out, const Ray* rays, int n, int* valid, std::atomic<std::uint64_t>& rejected) {
  // Inactive lanes repeat an active ray, so their (ignored) data is a
  // well-formed ray near the others. Suspected at first of causing a hang,
  // it was not the cause (that was the coherent kernel, see intersect16); kept
  // because it costs nothing. tests/engine/rt_test.cpp keeps packets equal to
  // single rays.
  Ray filler{};
  for (int i = 0; i < n; ++i)
    if (valid_ray(rays[i])) {
      filler = rays[i];
      break;
    }
  for (int i = 0; i < 16; ++i) {
    const bool ok = i < n && valid_ray(rays[i]);
    if (i < n && !ok) rejected.fetch_add(1, std::memory_order_relaxed);
    valid[i] = ok ? -1 : 0;
    const Ray r = ok ? rays[i] : filler;
    out.org_x[i] = r.origin.x;
    out.org_y[i] = r.origin.y;
    out.org_z[i] = r.origin.z;
    out.dir_x[i] = r.direction.x;
    out.dir_y[i] = r.direction.y;
    out.dir_z[i] = r.direction.z;
    out.tnear[i] = r.tmin;
    out.tfar[i] = r.tmax;
    out.time[i] = 0.0f;
    out.mask[i] = 0xffffffffu;
    out.id[i] = static_cast<unsigned>(i);
    out.flags[i] = 0;
  }
}
}  // namespace

void RtScene::intersect16(const Ray* rays, int n, Hit* hits, bool* found) const {
  intersect16_with(rays, n, hits, found, RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT);
}
void RtScene::intersect16_coherent(const Ray* rays, int n, Hit* hits, bool* found) const {
  intersect16_with(rays, n, hits, found, RTC_INTERSECT_CONTEXT_FLAG_COHERENT);
}

void RtScene::intersect16_with(const Ray* rays, int n, Hit* hits, bool* found, int flags) const {
  alignas(64) int valid[16];
  alignas(64) RTCRayHit16 rh;
  fill16(rh.ray, rays, std::min(n, 16), valid, rejected_);
  for (int i = 0; i < 16; ++i) {
    rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
  }
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  ctx.flags = static_cast<RTCIntersectContextFlags>(flags);
  rtcIntersect16(valid, impl_->top, &ctx, &rh);
  for (int i = 0; i < std::min(n, 16); ++i) {
    found[i] = valid[i] && rh.hit.geomID[i] != RTC_INVALID_GEOMETRY_ID;
    if (!found[i]) continue;
    const InstanceRecord& inst = instances_[rh.hit.instID[0][i]];
    hits[i].entity = inst.entity;
    hits[i].instance = rh.hit.instID[0][i];
    hits[i].mesh = inst.mesh;
    hits[i].primitive = rh.hit.primID[i];
    hits[i].barycentric = {rh.hit.u[i], rh.hit.v[i]};
    hits[i].t = rh.ray.tfar[i];
  }
}

void RtScene::occluded16(const Ray* rays, int n, bool* blocked) const {
  alignas(64) int valid[16];
  alignas(64) RTCRay16 r;
  fill16(r, rays, std::min(n, 16), valid, rejected_);
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  // Not the coherent kernel: Embree 3.13.5's coherent packet traversal
  // loops forever on some shadow packets (the sample level at frame ~23 on
  // one machine; the daylit Breakfast Room with AVX-512 kernels, 2026-11-27).
  ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
  rtcOccluded16(valid, impl_->top, &ctx, &r);
  for (int i = 0; i < std::min(n, 16); ++i) blocked[i] = valid[i] && r.tfar[i] < 0.0f;
}

const InstanceRecord* RtScene::instance(std::uint32_t id) const {
  return id < instances_.size() && instances_[id].active ? &instances_[id] : nullptr;
}

const InstanceRecord* RtScene::instance_of(const Hit& hit) const {
  if (hit.instance < instances_.size() && instances_[hit.instance].active && instances_[hit.instance].entity == hit.entity)
    return &instances_[hit.instance];
  return instance_of(hit.entity);
}

const InstanceRecord* RtScene::instance_of(ecs::Entity e) const {
  auto it = entity_to_id_.find(e);
  return it == entity_to_id_.end() ? nullptr : &instances_[it->second];
}

}  // namespace engine::rt
