#pragma once
// The probe field's data-parallel stages (ray tracing and hit shading,
// raster, accumulation and SH projection) behind one interface with two
// complete implementations (pbrt's split of interface and backend): the CPU
// backend (cpu_probe_kernels.h, the oracle) and the Vulkan backend
// (gpu/vulkan_probe_kernels.h). A field always runs every stage through the
// one backend it holds; a backend never hands a stage back. A device that
// cannot run a stage is refused when the backend is made, and a scene it
// cannot hold throws engine::gpu::GpuError: the owner then swaps the whole
// backend for the CPU's.
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <vector>

#include "engine/render/light_set.h"
#include "engine/rt/ray_batch_tracer.h"
#include "engine/rt/rt_scene.h"
#include "probes/interpolation.h"
#include "probes/probe_map.h"
#include "probes/probe_rays.h"
#include "probes/radiance_map.h"
#include "probes/radiance_sharing.h"

namespace transgi::probes {

// A probe field as the bounce light of probe rays reads it
// (ProbeField::irradiance): its relocated grid, maps, SH and usable flags.
class ProbeMapStore;

struct ProbeFeedbackSource {
  const ProbeGrid* grid = nullptr;
  MapLayout layout;
  const std::vector<ProbeMapState>* states = nullptr;
  std::span<const float> sh;                // probes x 75
  std::span<const std::uint8_t> usable;     // probes
  InterpolationSettings interpolation;
  // Whether the SH hold light yet (a field's first frame has none to give).
  bool lit = true;
  // How far past its outermost probes it holds points, in cells
  // (ProbeFieldSettings::hold_cells); past them a probe ray's hit takes the
  // outer field's light.
  float hold_cells = 0.0f;
  // The field's store on the backend's device (ProbeField's), which keeps
  // a copy of its depth maps too; null: the maps are sent from `states`.
  ProbeMapStore* maps = nullptr;
  [[nodiscard]] glm::vec3 held_min() const { return grid->held_min(hold_cells); }
  [[nodiscard]] glm::vec3 held_max() const { return grid->held_max(hold_cells); }
};

// ProbeField::irradiance of the field `source` describes: the pruned
// interpolation of its SH at p, convolved with the clamped cosine about n.
glm::vec3 probe_irradiance(const ProbeFeedbackSource& source, const glm::vec3& p, const glm::vec3& n);
// The bounce light at a probe ray's hit p (normal n): from `outer` (the next
// coarser cascade) outside self's grid box, else from self; 0 from a field
// that is not lit yet.
glm::vec3 bounce_irradiance(const ProbeFeedbackSource& self, const ProbeFeedbackSource* outer, const glm::vec3& p,
                            const glm::vec3& n);

// Why a frame that asked for a device runs on the CPU backend instead.
enum class BackendFallback : std::uint8_t {
  None,                   // the backend asked for runs
  NoDevice,               // no Vulkan device could be had (driver, loader, device name)
  MissingCapability,      // the device lacks a feature a stage needs (e.g. shaderInt64)
  KernelBuildFailed,      // a stage's kernel did not compile or link on the device
  SceneTooLarge,          // the device could not hold the scene (memory, buffer size)
};
// "none", "no device", "missing capability", "kernel build failed", "scene too large".
const char* to_string(BackendFallback reason);

// Host milliseconds of ProbeKernels::share_accumulate_project's parts (the
// frame's "probe raster" and "probe accumulation + projection" times). A
// backend that submits both parts at once counts the writing of its inputs
// as sharing and the submission and the read-back as the rest.
struct ShareAccumulateTimes {
  double share_ms = 0.0, accumulate_ms = 0.0;
};

// Where a device backend keeps a field's maps between frames, so that they
// do not cross the bus every update (issue 36): slot q holds probe q's
// radiance and sampled maps once an update has sent them up, and the
// device's accumulation updates them in place; and a copy of its depth map
// (updated on the host), sent again only when its DepthMap::version
// changed. Made by the backend (ProbeKernels::make_map_store), owned by the
// field.
class ProbeMapStore {
 public:
  virtual ~ProbeMapStore() = default;
  // The maps this store holds, copied into states[q] for every probe q
  // whose device_stamp it gave (their stamps zeroed: the host's maps are
  // current again). For the host's readers: a backend switch, tools, tests.
  virtual void read_back(std::span<ProbeMapState> states) = 0;
};

// Takes ray i of the j-th listed probe. A probe's rays come in order, on one
// thread, so it may write that probe's data without locks.
using ProbeRayConsumer = std::function<void(int j, int i, const ProbeRayHit& hit)>;

// shade_probe_rays's arguments, for shade_and_light.
struct ProbeRayRequest {
  const engine::rt::RtScene* scene = nullptr;
  const engine::render::LightSet* lights = nullptr;
  std::span<const glm::vec3> origins;
  std::span<const int> probe_ids;
  std::span<const glm::vec3> directions;
  std::uint64_t seed = 0, sample = 0;
  const ProbeFeedbackSource* self = nullptr;
  const ProbeFeedbackSource* outer = nullptr;
  // Whether the consumer reads each hit's emission (ProbeRayHit::emitted);
  // false: it may be left zero (a field that samples its emitters instead).
  bool emission = true;
};

// share_accumulate_project's arguments, for shade_and_light (`points` is
// what the rays' consumer fills).
struct ProbeLightRequest {
  const ProbeGrid* grid = nullptr;
  const MapProjector* projector = nullptr;
  const std::vector<std::vector<ShadedPoint>>* points = nullptr;
  const std::vector<const DepthMap*>* own_depth = nullptr;
  const SharingSettings* sharing = nullptr;
  std::span<const int> batch;
  std::span<ProbeMapState* const> states;
  ProbeMapStore* store = nullptr;
  const AccumulationSettings* accumulation = nullptr;
  std::span<std::uint8_t> changed;
  std::span<float> sh;
  ShareAccumulateTimes* times = nullptr;
};

class ProbeKernels {
 public:
  virtual ~ProbeKernels() = default;
  // Traces and shades the rays of probes origins[j] (index probe_ids[j])
  // along each of `directions` as trace_probe_ray does, ray i of probe q
  // drawing from make_rng(seed, q * 4096 + i, sample), the bounce light as
  // bounce_irradiance(self, outer, ...), each handed to `consume` (the CPU
  // streams them as they are shaded, a device hands them over after its
  // batch).
  virtual void shade_probe_rays(const engine::rt::RtScene& scene, const engine::render::LightSet& lights,
                                std::span<const glm::vec3> origins, std::span<const int> probe_ids,
                                std::span<const glm::vec3> directions, std::uint64_t seed, std::uint64_t sample,
                                const ProbeFeedbackSource& self, const ProbeFeedbackSource* outer,
                                const ProbeRayConsumer& consume) = 0;
  // This frame's light into the probes of `batch`, in one stage so that a
  // device keeps its intermediate maps: each batch probe's own depth from
  // its own points (update_own_depth of *states[i] from points[batch[i]];
  // own_depth[batch[i]] is that state's map, read after the update), then
  // its samples from its own and its neighbours' points (rasterize_shared
  // with the batch as its targets), accumulated into *states[i] (accumulate; its result in
  // changed[i]), filled (filled_radiance with accumulation.fill_passes) and
  // projected as projector.project into sh[i * 75, i * 75 + 75). `times`
  // gets the host time of the sharing and of the rest. `store`: this
  // backend's store of the field's maps (make_map_store), whose slot
  // batch[i] holds states[i]'s; null: the states' maps are read and written
  // on the host (a device sends them up and back). Throws std::logic_error
  // for a state whose maps another store holds (read them back first).
  virtual SharingStats share_accumulate_project(const ProbeGrid& grid, const MapProjector& projector,
                                                const std::vector<std::vector<ShadedPoint>>& points,
                                                const std::vector<const DepthMap*>& own_depth,
                                                const SharingSettings& sharing, std::span<const int> batch,
                                                std::span<ProbeMapState* const> states, ProbeMapStore* store,
                                                const AccumulationSettings& accumulation, std::span<std::uint8_t> changed,
                                                std::span<float> sh, ShareAccumulateTimes& times) = 0;
  // shade_probe_rays (`consume` filling *light.points: every traced probe's
  // rays, in order, no other points), then share_accumulate_project, as one
  // stage: for a frame whose batch does not depend on what its rays find
  // (no classification between them), so that a device traces, shades,
  // rasterises, accumulates and projects in one submission. The CPU runs
  // the two in turn.
  virtual SharingStats shade_and_light(const ProbeRayRequest& rays, const ProbeRayConsumer& consume, const ProbeLightRequest& light) {
    shade_probe_rays(*rays.scene, *rays.lights, rays.origins, rays.probe_ids, rays.directions, rays.seed, rays.sample, *rays.self,
                     rays.outer, consume);
    return share_accumulate_project(*light.grid, *light.projector, *light.points, *light.own_depth, *light.sharing, light.batch,
                                    light.states, light.store, *light.accumulation, light.changed, light.sh, *light.times);
  }
  // A store for the maps of a field of `probes` probes laid out as
  // `layout`, kept on this backend's device; null where the maps live in
  // the ProbeMapStates themselves (the CPU).
  [[nodiscard]] virtual std::unique_ptr<ProbeMapStore> make_map_store(const MapLayout& layout, int probes) = 0;
  // The backend's ray tracer for the probes' relocation rays (and the
  // G-buffer's camera rays); null = the RtScene's own (Embree) queries.
  virtual engine::rt::RayBatchTracer* tracer() = 0;
  [[nodiscard]] virtual const char* name() const = 0;
};

}  // namespace transgi::probes
