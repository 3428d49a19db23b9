#pragma once
// Embree scene mirrored from the ECS. One RTCScene per mesh asset (built
// once) and a dynamic top-level scene with one instance per entity that has
// MeshInstance + WorldTransform. Moving an entity costs
// rtcSetGeometryTransform and a top-level commit, never a mesh rebuild.
//
// Queries are thread-safe between syncs. Rays with non-finite origin or
// direction are rejected before Embree sees them (it does not check) and
// counted in rejected_rays().
#include <atomic>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include "engine/ecs/entity.h"
#include "engine/rt/ray.h"
#include "engine/scene/scene_assets.h"
#include "engine/transform/transform.h"

namespace engine::rt {

class RtError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// An axis-aligned box in world space.
struct WorldBounds {
  glm::vec3 min{0.0f}, max{0.0f};
};

struct InstanceRecord {
  ecs::Entity entity;
  std::uint32_t mesh = 0;
  transform::Similarity to_world;
  bool active = false;
  WorldBounds bounds;  // the mesh's bounds carried to world space
};

struct RtStats {
  std::size_t blas_builds = 0;        // mesh scenes built so far
  std::size_t instances_added = 0;
  std::size_t instances_moved = 0;
  std::size_t instances_removed = 0;
  std::size_t top_level_commits = 0;
};

class RtScene {
 public:
  RtScene();
  ~RtScene();
  RtScene(const RtScene&) = delete;
  RtScene& operator=(const RtScene&) = delete;

  // Mirror maintenance (called by the sync system; not thread-safe).
  // The assets must outlive their use here; a different pointer or
  // generation drops every instance and mesh scene.
  void set_assets(const scene::SceneAssets* assets);
  void upsert_instance(ecs::Entity e, std::uint32_t mesh, const transform::Similarity& to_world);
  void remove_instance(ecs::Entity e);
  void commit();

  // Queries.
  bool intersect(const Ray& ray, Hit& hit) const;
  bool occluded(const Ray& ray) const;
  // Packets of up to 16 rays (Embree's 16-wide queries). Same answers as the
  // single-ray queries; coherent rays (a tile of camera rays, shadow rays to
  // one light) traverse together and run several times faster. Invalid rays
  // are counted as rejected and report no hit / not occluded.
  void intersect16(const Ray* rays, int n, Hit* hits, bool* found) const;
  // The same with Embree's coherent (frustum) traversal, for rays from one
  // point through a small solid angle: a tile of camera rays (a quarter
  // less traversal time than the incoherent kernel on Bitterli's Living
  // Room). Only there: on shadow packets the coherent kernel of Embree
  // 3.13.5 has looped forever (occluded16).
  void intersect16_coherent(const Ray* rays, int n, Hit* hits, bool* found) const;
  void occluded16(const Ray* rays, int n, bool* blocked) const;

  [[nodiscard]] const InstanceRecord* instance(std::uint32_t id) const;
  // Ids run from 0 below this; instance(id) is null for the removed ones.
  [[nodiscard]] std::uint32_t instance_id_end() const { return static_cast<std::uint32_t>(instances_.size()); }
  // Calls fn(const InstanceRecord&) for every live instance, in id order.
  template <class Fn>
  void for_each_instance(Fn&& fn) const {
    for (const InstanceRecord& r : instances_)
      if (r.active) fn(r);
  }
  [[nodiscard]] const InstanceRecord* instance_of(ecs::Entity e) const;
  // The record of the instance a query hit: by its index when the hit carries
  // one (no hashing), else by entity.
  [[nodiscard]] const InstanceRecord* instance_of(const Hit& hit) const;
  [[nodiscard]] const scene::SceneAssets* assets() const { return assets_; }
  [[nodiscard]] const RtStats& stats() const { return stats_; }
  [[nodiscard]] std::uint64_t rejected_rays() const { return rejected_.load(std::memory_order_relaxed); }
  [[nodiscard]] bool empty() const { return entity_to_id_.empty(); }
  // Where the geometry changed in the last commit that had changes: for
  // each instance moved, added or removed, its old and new bounds merged.
  // Read it when top_level_commits moved (caches that follow geometry,
  // such as light probes, re-light those regions first).
  [[nodiscard]] const std::vector<WorldBounds>& changed_at_last_commit() const { return changed_at_commit_; }
  // World-space bounds of all instances (valid after commit()).
  [[nodiscard]] glm::vec3 bounds_min() const { return bounds_min_; }
  [[nodiscard]] glm::vec3 bounds_max() const { return bounds_max_; }
  // For offset_ray_origin: the largest coordinate's magnitude of the bounds,
  // clamped to [1e-6, 1] (1 for any scene of a metre or more).
  [[nodiscard]] float offset_scale() const { return offset_scale_; }

 private:
  void intersect16_with(const Ray* rays, int n, Hit* hits, bool* found, int flags) const;
  struct Impl;
  std::unique_ptr<Impl> impl_;
  const scene::SceneAssets* assets_ = nullptr;
  std::uint64_t generation_ = 0;
  std::vector<InstanceRecord> instances_;  // by top-level geometry id
  std::unordered_map<ecs::Entity, std::uint32_t> entity_to_id_;
  RtStats stats_;
  bool dirty_ = false;
  glm::vec3 bounds_min_{0.0f}, bounds_max_{0.0f};
  float offset_scale_ = 1.0f;
  std::vector<WorldBounds> changed_pending_, changed_at_commit_;
  mutable std::atomic<std::uint64_t> rejected_{0};
};

}  // namespace engine::rt
