#pragma once
// The SH light probes of one volume, updated frame by frame (paper Section 5):
//
//  1. scatter: every probe shoots M rays, a spherical Fibonacci set under a
//     new random rotation each frame; each hit is shaded with the radiance
//     leaving it towards the probe: direct light (next-event estimation over
//     the LightSet) plus indirect light from the previous frame's probes
//     (their interpolated irradiance times the diffuse albedo, as DDGI does).
//     Rays that hit an emitter or escape record zero: the probes hold
//     indirect light only. What those rays saw (the environment, residual
//     if the sun is split out, and emitters) is a second SH per probe, the
//     direct sky and emitter light: the real-time path's direct light from
//     everything but punctual lights and the sun. The sky part is each
//     direction cell's escaped fraction times the sky's exact projection
//     (sky_visibility.h); emitters are a running mean over `direct_history`
//     frames of the projection of what the rays hit.
//  2. raster: radiance sharing across each probe's 26 neighbours.
//  3. accumulate over frames (adaptive hysteresis), fill holes, project to
//     SH (optionally windowed against ringing).
//
// Work the scene does not need is skipped (ProbeSkipSettings): probes
// buried in geometry or far from every surface are classified inactive
// whenever the geometry moves, and in a static scene a probe that has gone
// `settle_frames` without a detected change stops updating until the
// scene changes again (notify_scene_changed).
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "engine/math/rng.h"
#include "engine/render/light_set.h"
#include "engine/rt/rt_scene.h"
#include "probes/interpolation.h"
#include "probes/open_space.h"
#include "probes/probe_map.h"
#include "probes/probe_kernels.h"
#include "probes/sky_visibility.h"

namespace transgi::probes {

enum class ProbeState : std::uint8_t {
  Active,     // traced, shared, accumulated and projected every frame
  Converged,  // static scene, settled: keeps its SH, does no work
  Buried,     // inside closed geometry: holds no light, does no work
  Far,        // no surface within a cell diagonal: lights nothing, does no work
};

struct ProbeSkipSettings {
  // Classify probes as buried or far whenever the geometry moves (RTXGI's
  // probe classification). On = less work and no light from inside walls,
  // at the cost of one frame tracing every probe after each move.
  bool classify = true;
  // A probe whose rays hit back faces (of single-sided materials) more often
  // than this is buried. Higher = fewer probes counted buried, at the cost
  // of more light leaking from probes that sit inside walls.
  float buried_backface_fraction = 0.25f;
  // A probe that no chain of clear probe-to-probe segments links to light is
  // buried (open_space.h): the winding-proof test for double-sided content.
  // On = probes inside walls and closed furniture hold no light, at the cost
  // of 13 segment tests per probe on classification frames.
  bool open_space = true;
  // Probes that the open-space test finds unlinked are moved out of the
  // geometry where a linked neighbour shows the way (open_space.h).
  RelocationSettings relocation;
  // A probe whose nearest hit is beyond this many cell diagonals is far.
  // Higher = fewer probes skipped, at the cost of tracing empty space.
  float far_cells = 1.0f;
  // Stop updating probes that have settled while the scene is static.
  // On = less work per frame, at the cost of freezing the last frames' noise.
  bool skip_converged = true;
  // Frames after the warm-up without a detected lighting change before a
  // probe counts as converged. Higher = a better settled estimate before it
  // freezes, at the cost of more frames of work.
  int settle_frames = 64;

  bool operator==(const ProbeSkipSettings&) const = default;
};

struct ProbeFieldSettings {
  ProbeGrid grid;
  MapLayout map;
  // Rays per probe per frame (the paper's M = 100). Higher = less noise per
  // frame, at the cost of ray-tracing and shading time.
  int rays_per_probe = 100;
  SharingSettings sharing;
  AccumulationSettings accumulation;
  InterpolationSettings interpolation;
  // Hanning window on the projected SH. On = less ringing of sharp light
  // (tests/transgi/probes_test.cpp), at the cost of blurrier, dimmer
  // lighting. Off by default: on the sample level it raised the GI error
  // (RMSE 0.0237 vs 0.0216 at 128 frames) and lost 5 % of the light
  // (docs/runtime.md).
  bool window = false;
  ProbeSkipSettings skip;
  // Probes updated per frame; 0 = every active probe. The stalest go first
  // (round-robin); after geometry moves, buried and far probes rejoin the
  // queue to be classified again from their own rays. Lower = a shorter
  // frame, at the cost of each probe refreshing only every active/budget
  // frames, so lighting responds that many times slower.
  int update_budget = 0;
  // With a budget: the probes updated a frame once no light has changed for
  // skip.settle_frames frames (objects may still move: the probes by a moved
  // object go first, notify_region_changed). A light that changes gets
  // update_budget back at once. 0 = update_budget always. Lower = a shorter
  // frame while only objects move, at the cost of the bounce light far from
  // a moved object following it that much later.
  int steady_light_budget = 0;
  // With a budget: the field's first settle_frames updates trace every
  // active probe, as a loading screen would, so a level starts with its
  // multi-bounce light converged (each update of a probe adds a bounce)
  // instead of reaching it over hundreds of budgeted frames. Higher = a
  // better-settled start, at the cost of that many slow first frames.
  int settle_frames = 0;
  // With a budget: a probe whose last update detected a lighting change (a
  // sun that moved, a lamp switched) goes before the merely stale, so the
  // budget follows the change. On = GI settles sooner after a light moves,
  // at the cost of unchanged probes refreshing less often meanwhile.
  bool changed_first = false;
  // Frames the direct emitter SH averages over (a running mean, restarted
  // when an emitter changes, shortened near a moved object). Higher = less
  // noise, at the cost of a slower response to geometry that moves near a
  // lamp.
  int direct_history = 64;
  // Light samples a traced probe takes of the emissive triangles a frame
  // (a point by emitted power, one shadow ray each) for its direct emitter
  // SH. A small lamp is one ray in hundreds of the probe's own, so without
  // them each probe saw it a few times and neighbours disagreed: patches on
  // every wall it lights. Higher = smoother lamp light, at the cost of that
  // many shadow rays per probe. 0 = the probe rays that hit emitters.
  int emitter_samples = 8;
  // How the probes see the sky: escaped fractions per direction cell.
  SkyVisibilitySettings sky;
  // Hanning window on the direct sky and emitter SH. On = no ringing around
  // small bright emitters, at the cost of a blurrier sky.
  bool direct_window = true;
  // Fixed patterns instead of seeded randomness: ray sets rotate by a Halton
  // sequence of rotations and hit sampling ignores `seed`, so the probes
  // (and a real-time image) are a function of the scene and the frame count
  // alone. On = no seed-to-seed difference and evenly spread rotations, at
  // the cost of estimates that are not independent across seeds (eval's
  // seed studies use off).
  bool fixed_pattern = false;
  std::uint64_t seed = 1;
  // Where several fields hold a point (cascades, authored volumes;
  // cascades.h), the band inside this grid's faces across which it hands
  // the point over to the next field, in cells. Higher = smoother seams, at
  // the cost of two interpolations over more of the screen. 0 = a hard edge.
  float blend_cells = 0.0f;
  // How far past its outermost probes this field holds points before the
  // next field takes them, in cells. A grid fitted to a region stands half a
  // cell inside its faces (ProbeGrid::centred_in) and holds all of it: 0.5,
  // so the far field beyond a fitted building does not light the building's
  // own walls. Cascades: 0.
  float hold_cells = 0.0f;

  bool operator==(const ProbeFieldSettings&) const = default;
};

struct ProbeFrameStats {
  std::size_t rays = 0, hits = 0, shared_accepted = 0, shared_rejected = 0;
  int traced = 0;  // probes that traced rays this frame
  // Probe states after this frame.
  int active = 0, converged = 0, buried = 0, far = 0;
  int relocated = 0;  // probes standing off their grid points
  bool classified = false;  // this frame traced every probe to classify them
  // Non-finite values replaced at the probes' boundaries this frame: ray
  // radiance or emission set to zero, and probes whose projected SH came out
  // non-finite, emptied and started afresh (issue 13's NaN containment).
  std::size_t nonfinite_rays = 0;
  int nonfinite_probes = 0;
  double scatter_ms = 0, raster_ms = 0, project_ms = 0;

  // Sums over volumes (counts and times add; `classified` if any was).
  ProbeFrameStats& operator+=(const ProbeFrameStats& o) {
    rays += o.rays;
    hits += o.hits;
    shared_accepted += o.shared_accepted;
    shared_rejected += o.shared_rejected;
    traced += o.traced;
    active += o.active;
    converged += o.converged;
    buried += o.buried;
    far += o.far;
    relocated += o.relocated;
    classified = classified || o.classified;
    nonfinite_rays += o.nonfinite_rays;
    nonfinite_probes += o.nonfinite_probes;
    scatter_ms += o.scatter_ms;
    raster_ms += o.raster_ms;
    project_ms += o.project_ms;
    return *this;
  }
};

// Every probe's data, one entry a probe (75 floats a probe for the SH),
// sized together by resize so that no per-probe array falls out of step.
struct ProbeSet {
  std::vector<ProbeMapState> maps;           // radiance and depth maps
  std::vector<ProbeState> state;
  std::vector<std::uint8_t> usable;          // 1 unless buried or far (read by interpolation)
  std::vector<std::uint8_t> saw_light;       // from its latest traced frame (open_space.h)
  // Budgeted updates: the frame each probe last traced, and whether it
  // must be classified again when next traced.
  std::vector<std::uint64_t> last_traced;
  std::vector<std::uint8_t> needs_classify;
  std::vector<std::uint8_t> urgent;          // in a changed region, not yet traced since
  std::vector<std::uint8_t> changed;         // its last update detected a lighting change (changed_first)
  std::vector<float> sh;                     // x 75: indirect light
  std::vector<float> direct_mean, direct_sh;  // x 75: the emitters' running mean, and that plus the sky, windowed
  std::vector<std::uint32_t> direct_frames;  // frames in each probe's running mean
  std::vector<SkyCell> sky;                  // x sky cells: the escaped fractions (sky_visibility.h)
  std::size_t sky_cells = 0;
  [[nodiscard]] SkyCell* sky_of(std::size_t q) { return sky.data() + q * sky_cells; }

  // count probes, active and usable, holding nothing.
  void resize(std::size_t count, std::size_t cells_per_probe) {
    maps.resize(count);
    sky_cells = cells_per_probe;
    sky.assign(count * cells_per_probe, SkyCell{});
    state.assign(count, ProbeState::Active);
    usable.assign(count, 1);
    saw_light.assign(count, 0);
    last_traced.assign(count, 0);
    needs_classify.assign(count, 0);
    urgent.assign(count, 0);
    changed.assign(count, 0);
    sh.assign(count * 75, 0.0f);
    direct_mean.assign(count * 75, 0.0f);
    direct_sh.assign(count * 75, 0.0f);
    direct_frames.assign(count, 0);
  }
  [[nodiscard]] std::size_t count() const { return state.size(); }
};

class ProbeField {
 public:
  explicit ProbeField(ProbeFieldSettings settings);

  // `outer` (the next coarser cascade, cascades.h) lights the probe rays'
  // hits outside this grid's box, which this field would only clamp.
  ProbeFrameStats update(const engine::rt::RtScene& scene, const engine::render::LightSet& lights,
                         const ProbeField* outer = nullptr);

  // What changed since the last update.
  struct SceneChange {
    bool geometry_moved = false;  // an object moved, appeared or left
    bool light_changed = false;   // a light, the sun or the sky changed
    bool emitters_changed = false;  // an emissive mesh moved, changed or came or went
  };
  // The scene changed since the last update: converged probes wake up; if
  // the geometry moved the probes are classified again and their depth
  // re-converges quickly; if a light changed the full update_budget returns
  // (steady_light_budget); if the emitters changed, their mean in the direct
  // SH restarts short (the sky's part follows the sky by itself).
  void notify_scene_changed(SceneChange change);
  // What changed lies in [min, max] (a moved object's old and new bounds):
  // with a budget, the probes within one cell of it are updated before any
  // other, so a moving object re-lights its neighbourhood first.
  void notify_region_changed(const glm::vec3& min, const glm::vec3& max);

  // The grid moved by whole cells (a camera-centred cascade following the
  // camera, cascades.h): probes still inside keep their light and history;
  // the slab that entered starts afresh, queued first for the budget and for
  // classification, its SH seeded from `seed` (the next coarser field; null =
  // black) until its own first trace. Returns how many probes entered.
  int scroll(glm::ivec3 cells, const ProbeField* seed);
  // With a budget, probes equally stale are refreshed nearest to `p` first
  // (the camera) instead of round-robin.
  void set_focus(const glm::vec3& p) { focus_ = p; has_focus_ = true; }
  // Where the shaded points are seen from (the camera): interpolate() and
  // interpolation_weights() move their visibility test towards it
  // (InterpolationSettings::view_bias). Lookups at the hits of reflection
  // and contact rays take it too, a bias of a tenth of a cell that there
  // points the camera's way rather than the ray's. The probes' own bounce
  // light (feedback_source) takes none.
  void set_viewer(const glm::vec3& p) { viewer_ = p; has_viewer_ = true; }
  [[nodiscard]] const glm::vec3* viewer() const { return has_viewer_ ? &viewer_ : nullptr; }
  // Trilinear light at a point with no surface (no pruning, buried and far
  // probes excluded): the indirect and the direct sky SH, 75 each.
  void light_at_point(const glm::vec3& p, float* out75, float* out_direct75) const;

  // Error decomposition: every probe that holds light gets its radiance map
  // path-traced instead (`rays_per_texel` paths per texel, stratified, each
  // the radiance leaving its first hit towards the probe, emission excluded:
  // what the probes hold), its depth moments from the same first hits, and
  // the same SH projection. What is left of the error is interpolation, SH
  // truncation and everything that is not the probes.
  void replace_with_oracle(const engine::rt::RtScene& scene, const engine::render::LightSet& lights, int rays_per_texel,
                           std::uint64_t seed);

  // 75 SH coefficients of probe i, [c * 25 + k], world space.
  [[nodiscard]] const float* light_sh(int probe) const { return probes_.sh.data() + static_cast<std::size_t>(probe) * 75; }
  // Interpolated SH light at a surface point (pruned trilinear). Each
  // overload returns whether probes that hold light and see the point
  // weighed in: false where every probe around p is buried or far (out all
  // zero) or pruned (out is the distance-weighted fallback), which tells a
  // caller with several fields to ask the next one (cascades.h): a fine
  // cascade's fallback is often a probe behind a wall, in other light.
  bool interpolate(const glm::vec3& position, const glm::vec3& normal, float* out75) const;
  // One set of weights applied to two probe SH arrays (the indirect and the
  // direct light, possibly rotated): half the cost of two calls.
  bool interpolate(const glm::vec3& position, const glm::vec3& normal, const float* sh_a, float* out_a, const float* sh_b,
                   float* out_b) const;
  // The weights of interpolate() for many points at once (interpolate_probes_many),
  // then one point's two blends with them: together exactly interpolate()
  // with two SH arrays, returning the same.
  void interpolation_weights(std::span<const glm::vec3> position, std::span<const glm::vec3> normal,
                             std::span<InterpolationResult> out) const;
  static bool blend(const InterpolationResult& weights, const float* sh_a, float* out_a, const float* sh_b, float* out_b);
  // The mean SH light (75, world space) of the probes that hold light, as of
  // the last update: the ambient term for points no probe lights (beyond the
  // coarsest cascade's reach, cascades.h). Zero before any update.
  [[nodiscard]] const float* mean_light_sh() const { return mean_sh_.data(); }
  [[nodiscard]] const float* mean_direct_sh() const { return mean_direct_sh_.data(); }
  // The direct sky and emitter light of every probe, probes x 75, world space.
  [[nodiscard]] const std::vector<float>& direct_sh_all() const { return probes_.direct_sh; }
  // The same weights applied to another copy of the probes' SH (probes x 75,
  // e.g. rotated into an object's frame: interpolation is linear, so rotating
  // the probes once equals rotating every interpolated result).
  bool interpolate(const glm::vec3& position, const glm::vec3& normal, const float* probe_sh, float* out75) const;
  // All probes' SH, probes x 75, world space.
  [[nodiscard]] const std::vector<float>& light_sh_all() const { return probes_.sh; }
  // Irradiance from the interpolated SH (clamped-cosine convolution).
  [[nodiscard]] glm::vec3 irradiance(const glm::vec3& position, const glm::vec3& normal) const;

  // Runs every stage of the next updates through `kernels` (the Vulkan
  // backend, or the CPU's: the default, and what null selects). Shared: one
  // backend serves every field of a scene.
  void set_kernels(std::shared_ptr<ProbeKernels> kernels);
  // A device backend keeps the probes' radiance maps on its device between
  // updates (ProbeMapStore): this copies them into states() for readers on
  // the host. The CPU backend's maps are always there.
  void read_back_maps();
  // This field as its own and finer cascades' probe rays read its light.
  [[nodiscard]] ProbeFeedbackSource feedback_source() const;

  [[nodiscard]] const ProbeFieldSettings& settings() const { return settings_; }
  // The grid as placed (settings().grid), before relocation (cascade_follow.h).
  [[nodiscard]] const ProbeGrid& placement() const { return settings_.grid; }
  // settings().grid with each probe where relocation moved it.
  [[nodiscard]] const ProbeGrid& grid() const { return grid_; }
  [[nodiscard]] std::uint64_t frame() const { return frame_; }
  // Each probe's maps: the radiance and sampled maps only as of the last
  // read_back_maps() where a device backend holds them (the depth maps and
  // the scalars are always current).
  [[nodiscard]] const std::vector<ProbeMapState>& states() const { return probes_.maps; }
  [[nodiscard]] ProbeState state(int probe) const { return probes_.state[static_cast<std::size_t>(probe)]; }
  // Per probe, 1 unless buried or far: what interpolation weighs.
  [[nodiscard]] const std::vector<std::uint8_t>& usable() const { return probes_.usable; }
  // The frame probe last traced rays (budgeted fields; 0 before it ever did).
  [[nodiscard]] std::uint64_t last_traced(int probe) const {
    return static_cast<std::size_t>(probe) < probes_.last_traced.size() ? probes_.last_traced[static_cast<std::size_t>(probe)] : 0;
  }
  // Bytes held by the probes' maps, depth moments and SH.
  [[nodiscard]] std::size_t memory_bytes() const;

 private:
  // Clears probe q's maps, SH and direct-light history.
  void forget_light(int probe);
  // Probe q's direct SH from its emitter mean and its view of the sky.
  void finish_direct_sh(std::size_t q);
  // Marks the probes this frame's budget updates (update_budget > 0).
  void select_within_budget(std::vector<std::uint8_t>& traced) const;
  // The probes this frame may update: update_budget, or steady_light_budget
  // once the lights have held for skip.settle_frames.
  [[nodiscard]] int budget_this_frame() const;

  // update()'s stages, in order, over one frame's scratch. After each:
  //  plan_update: which probes trace, this frame's ray set;
  //  trace_and_shade: every tracing probe's shaded points, hit counts and
  //    the sky it saw (and the emitters, without emitter_samples);
  //  queue_open_space_segments: where the frame searches for open space and
  //    the backend's tracer takes a later batch, the search's segments
  //    queued to go with the probe rays;
  //  queue_emitter_samples: every tracing probe's light samples of the
  //    emitters (emitter_samples) made, and where the backend's tracer takes
  //    a later batch, their shadow rays queued to go with the probe rays;
  //  sample_emitters: those samples traced (unless queued) and projected;
  //  classify_traced (classification and budgeted frames): buried, far and
  //    relocated probes marked, their light forgotten; on a budgeted frame
  //    after the light stage below, which then went with the rays
  //    (batch_known_before_rays), so its changes count from the next frame;
  //  share_accumulate_project: each updating probe's depth from its own
  //    rays, this frame's samples from its own and its neighbours' points
  //    accumulated into its maps, its SH and direct-light mean; counts the
  //    probes whose light came out non-finite (reset);
  //  update_means_and_counts: the ambient means and the state counts.
  struct UpdateWork;
  void plan_update(UpdateWork& w);
  struct LightBatch;
  // With `light`, the light stage too (ProbeKernels::shade_and_light), its
  // result in light->result.sharing.
  void trace_and_shade(const engine::rt::RtScene& scene, const engine::render::LightSet& lights, const ProbeField* outer,
                       UpdateWork& w, LightBatch* light = nullptr);
  void queue_emitter_samples(const engine::rt::RtScene& scene, const engine::render::LightSet& lights, UpdateWork& w);
  void sample_emitters(const engine::rt::RtScene& scene, const engine::render::LightSet& lights, UpdateWork& w);
  // Probe q's draws for its emitter samples this frame.
  [[nodiscard]] engine::math::Pcg32 emitter_rng(const UpdateWork& w, int q) const;
  // Whether classify_traced searches for open space this frame (plan_update
  // keeps the answer in the frame's work).
  [[nodiscard]] bool searches_open_space(const UpdateWork& w) const;
  // Where the backend's tracer takes a later batch and this frame searches
  // for open space: the search's segments queued to go with the probe rays.
  void queue_open_space_segments(const engine::rt::RtScene& scene, UpdateWork& w);
  void classify_traced(const engine::rt::RtScene& scene, UpdateWork& w);
  struct LightIntoProbes {
    SharingStats sharing;
    ShareAccumulateTimes times;
    int nonfinite_probes = 0;
  };
  LightIntoProbes share_accumulate_project(UpdateWork& w);
  // share_accumulate_project in parts: the batch and its buffers, the
  // backend's request over them, and what follows the backend's stage
  // (each batch probe's convergence, direct light, SH and finiteness).
  struct LightBatch {
    std::vector<const DepthMap*> depth;
    std::vector<int> batch;
    std::vector<ProbeMapState*> states;
    std::vector<std::uint8_t> changed;
    std::vector<float> projected;
    LightIntoProbes result;
  };
  LightBatch light_batch(const UpdateWork& w);
  ProbeLightRequest light_request(const UpdateWork& w, LightBatch& b);
  void finish_light(const UpdateWork& w, LightBatch& b);
  // Whether the batch is known before this frame's rays are traced: every
  // frame but a classification frame (a budgeted frame's classification
  // takes effect from the next frame).
  [[nodiscard]] bool batch_known_before_rays(const UpdateWork& w) const;
  void update_means_and_counts(ProbeFrameStats& stats);
  // Whether probe q's maps take this frame (untraced probes, outside the
  // budget, and relocated ones keep their state).
  [[nodiscard]] bool takes_frame(const UpdateWork& w, int q) const;

  ProbeFieldSettings settings_;
  std::shared_ptr<ProbeKernels> kernels_;
  // kernels_'s store of the radiance maps (null for the CPU's); declared
  // after kernels_, so destroyed before the backend it belongs to.
  std::unique_ptr<ProbeMapStore> map_store_;
  ProbeGrid grid_;  // settings_.grid, relocated
  MapProjector projector_;
  // The length probe depths are stored in units of (ProbeMapState::reset).
  [[nodiscard]] float depth_unit() const { return grid_.min_spacing() > 0 ? grid_.min_spacing() : 1.0f; }
  ProbeSet probes_;
  SkyProjection sky_;
  bool classify_pending_ = true;
  std::vector<float> mean_sh_ = std::vector<float>(75, 0.0f), mean_direct_sh_ = std::vector<float>(75, 0.0f);
  std::vector<glm::vec3> fibonacci_;
  std::uint64_t frame_ = 0;
  // The frame of the last light change; none yet = the lights have held
  // since the field began (its own settle_frames cover the start).
  std::optional<std::uint64_t> light_changed_at_;
  glm::vec3 focus_{0.0f};
  bool has_focus_ = false;
  glm::vec3 viewer_{0.0f};
  bool has_viewer_ = false;
};

}  // namespace transgi::probes
