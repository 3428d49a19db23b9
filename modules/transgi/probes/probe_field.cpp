#include "probes/probe_field.h"

#include <algorithm>
#include <tuple>
#include <atomic>
#include <chrono>
#include <exception>
#include <limits>
#include <optional>
#include <cmath>

#include <glm/gtc/quaternion.hpp>

#include "engine/core/cpu_isa.h"
#include "engine/jobs/parallel_for.h"
#include "engine/math/rng.h"
#include "engine/math/sampling.h"
#include "engine/math/sh.h"
#include "probes/cpu_probe_kernels.h"
#include "probes/open_space.h"
#include "probes/probe_rays.h"
#include "probes/radiance_map.h"

namespace transgi::probes {

namespace {
using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

// sh75 += the SH projection of radiance arriving from direction dir
// (already weighted by its estimator: solid angle, or 1 / pdf).
void add_radiance_sh(float* sh75, const glm::vec3& dir, const glm::vec3& weighted) {
  const engine::math::ShBasis y = engine::math::sh_eval(dir);
  for (int c = 0; c < 3; ++c)
    for (int k = 0; k < 25; ++k) sh75[c * 25 + k] += weighted[c] * y[static_cast<std::size_t>(k)];
}
}  // namespace


ProbeField::ProbeField(ProbeFieldSettings s)
    : settings_(s), kernels_(cpu_probe_kernels()), grid_(s.grid), projector_(s.map), fibonacci_(spherical_fibonacci(s.rays_per_probe)) {
  probes_.resize(static_cast<std::size_t>(s.grid.count()), static_cast<std::size_t>(s.sky.cells.count()));
  for (auto& st : probes_.maps) st.reset(s.map.texel_count(), depth_unit());
}

bool ProbeField::interpolate(const glm::vec3& p, const glm::vec3& n, float* out) const { return interpolate(p, n, probes_.sh.data(), out); }

bool ProbeField::interpolate(const glm::vec3& p, const glm::vec3& n, const float* probe_sh, float* out) const {
  const InterpolationResult r = interpolate_probes(grid_, settings_.map, probes_.maps, p, n, settings_.interpolation, probes_.usable, viewer());
  for (int k = 0; k < 75; ++k) out[k] = 0.0f;
  bool lit = false;
  for (std::size_t i = 0; i < 8; ++i) {
    if (r.weights[i] == 0.0f) continue;
    lit = true;
    const float* L = probe_sh + static_cast<std::size_t>(r.probes[i]) * 75;
    for (int k = 0; k < 75; ++k) out[k] += r.weights[i] * L[k];
  }
  return lit && !r.fallback;
}

namespace {
// out_a/out_b = sum of weights x the weighted probes' 75 values, vectorised per ISA.
ENGINE_INLINE_BODY void blend_two_body(
    const InterpolationResult& r, const float* __restrict sh_a, float* __restrict out_a, const float* __restrict sh_b,
    float* __restrict out_b) {
  for (int k = 0; k < 75; ++k) out_a[k] = out_b[k] = 0.0f;
  for (std::size_t i = 0; i < 8; ++i) {
    const float w = r.weights[i];
    if (w == 0.0f) continue;
    const float* a = sh_a + static_cast<std::size_t>(r.probes[i]) * 75;
    const float* b = sh_b + static_cast<std::size_t>(r.probes[i]) * 75;
    for (int k = 0; k < 75; ++k) out_a[k] += w * a[k];
    for (int k = 0; k < 75; ++k) out_b[k] += w * b[k];
  }
}
ENGINE_ISA_DISPATCH(void, blend_two, (const InterpolationResult& r, const float* __restrict sh_a, float* __restrict out_a,
                   const float* __restrict sh_b, float* __restrict out_b),
                   (r, sh_a, out_a, sh_b, out_b))
}  // namespace

bool ProbeField::interpolate(const glm::vec3& p, const glm::vec3& n, const float* sh_a, float* out_a, const float* sh_b,
                             float* out_b) const {
  return blend(interpolate_probes(grid_, settings_.map, probes_.maps, p, n, settings_.interpolation, probes_.usable, viewer()), sh_a, out_a,
               sh_b, out_b);
}

void ProbeField::interpolation_weights(std::span<const glm::vec3> position, std::span<const glm::vec3> normal,
                                       std::span<InterpolationResult> out) const {
  interpolate_probes_many(grid_, settings_.map, probes_.maps, position, normal, settings_.interpolation, probes_.usable, out, viewer());
}

bool ProbeField::blend(const InterpolationResult& r, const float* sh_a, float* out_a, const float* sh_b, float* out_b) {
  blend_two(r, sh_a, out_a, sh_b, out_b);
  if (r.fallback) return false;
  for (float w : r.weights)
    if (w != 0.0f) return true;
  return false;
}

glm::vec3 ProbeField::irradiance(const glm::vec3& p, const glm::vec3& n) const {
  ProbeFeedbackSource self = feedback_source();
  self.lit = true;
  return probe_irradiance(self, p, n);
}

void ProbeField::set_kernels(std::shared_ptr<ProbeKernels> kernels) {
  if (!kernels) kernels = cpu_probe_kernels();
  if (kernels == kernels_) return;  // set every frame by the plugin: the store stays
  try {
    read_back_maps();  // what the old backend's device holds, before its store goes
  } catch (const std::exception&) {
    // The device failed with the maps on it: those probes start afresh.
    for (std::size_t q = 0; q < probes_.maps.size(); ++q)
      if (probes_.maps[q].device_stamp != 0) forget_light(static_cast<int>(q));
  }
  map_store_.reset();
  kernels_ = std::move(kernels);
  map_store_ = kernels_->make_map_store(settings_.map, grid_.count());
}

void ProbeField::read_back_maps() {
  if (map_store_) map_store_->read_back(probes_.maps);
}

std::size_t ProbeField::memory_bytes() const {
  std::size_t b = (probes_.sh.size() + probes_.direct_mean.size() + probes_.direct_sh.size()) * sizeof(float) +
                  probes_.direct_frames.size() * sizeof(std::uint32_t) + probes_.sky.size() * sizeof(SkyCell);
  for (const ProbeMapState& st : probes_.maps)
    b += st.radiance.size() * sizeof(HalfRgb) + st.sampled.size() * sizeof(std::uint8_t) +
         st.depth.texels.size() * sizeof(DepthMap::Texel);
  return b;
}

void ProbeField::notify_scene_changed(SceneChange change) {
  const bool geometry_moved = change.geometry_moved;
  if (change.light_changed) light_changed_at_ = frame_;
  for (std::size_t q = 0; q < probes_.maps.size(); ++q) {
    if (probes_.state[q] == ProbeState::Converged) probes_.state[q] = ProbeState::Active;
    probes_.maps[q].stable_frames = 0;
    if (geometry_moved) probes_.maps[q].depth_frames = 0;
    // A changed lamp: the emitters' mean starts again from the next update's
    // light samples, which alone are a fair estimate (a moved object only
    // shortens the history of the probes near it, notify_region_changed; the
    // sky needs no restart, sky_visibility.h).
    if (change.emitters_changed) probes_.direct_frames[q] = 0;
  }
  if (geometry_moved && settings_.skip.classify) {
    if (settings_.update_budget > 0 && !classify_pending_)
      std::fill(probes_.needs_classify.begin(), probes_.needs_classify.end(), std::uint8_t{1});
    else
      classify_pending_ = true;
  }
}

void ProbeField::notify_region_changed(const glm::vec3& lo, const glm::vec3& hi) {
  const ProbeGrid& grid = grid_;
  const glm::vec3 margin = grid.spacing();
  for (int q = 0; q < grid.count(); ++q) {
    const glm::vec3 p = grid.position(q);
    if (glm::all(glm::greaterThanEqual(p, lo - margin)) && glm::all(glm::lessThanEqual(p, hi + margin))) {
      probes_.urgent[static_cast<std::size_t>(q)] = 1;
      // Its view of the sky may have changed in part of a cell (a cell
      // wholly covered or uncovered restarts by itself).
      shorten_sky_history(probes_.sky_of(static_cast<std::size_t>(q)), settings_.sky, 4);
      probes_.direct_frames[static_cast<std::size_t>(q)] = std::min<std::uint32_t>(probes_.direct_frames[static_cast<std::size_t>(q)], 4);
    }
  }
}

void ProbeField::select_within_budget(std::vector<std::uint8_t>& traced) const {
  // Candidates: active probes and those queued for classification; those in
  // a changed region first, then the stalest, ties broken by a rotating
  // offset (round-robin).
  const int budget = budget_this_frame();
  const std::size_t n = traced.size(), offset = frame_ * static_cast<std::size_t>(budget) % n;
  // With a focus (the camera), ties go nearest-first instead of by turn.
  // With changed_first, probes whose light just changed count as urgent.
  std::vector<std::tuple<int, std::uint64_t, float, std::size_t, std::size_t>> order;  // (not urgent, last traced, distance^2, turn, probe)
  for (std::size_t q = 0; q < n; ++q) {
    traced[q] = 0;
    const bool changed = settings_.changed_first && probes_.changed[q];
    const int not_urgent = probes_.urgent[q] || changed ? 0 : 1;
    if (probes_.state[q] == ProbeState::Active || probes_.needs_classify[q]) {
      const glm::vec3 d = has_focus_ ? grid_.grid_point(static_cast<int>(q)) - focus_ : glm::vec3(0.0f);
      order.emplace_back(not_urgent, probes_.last_traced[q], glm::dot(d, d), (q + n - offset) % n, q);
    }
  }
  const std::size_t k = std::min(order.size(), static_cast<std::size_t>(budget));
  std::partial_sort(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(k), order.end());
  for (std::size_t i = 0; i < k; ++i) traced[std::get<4>(order[i])] = 1;
}

int ProbeField::budget_this_frame() const {
  if (settings_.steady_light_budget <= 0) return settings_.update_budget;
  const bool lights_held =
      !light_changed_at_ || frame_ - *light_changed_at_ >= static_cast<std::uint64_t>(std::max(0, settings_.skip.settle_frames));
  return lights_held ? settings_.steady_light_budget : settings_.update_budget;
}

void ProbeField::forget_light(int probe) {
  const auto q = static_cast<std::size_t>(probe);
  probes_.maps[q].reset(settings_.map.texel_count(), depth_unit());
  std::fill_n(probes_.sh.data() + q * 75, 75, 0.0f);
  std::fill_n(probes_.direct_mean.data() + q * 75, 75, 0.0f);
  std::fill_n(probes_.direct_sh.data() + q * 75, 75, 0.0f);
  probes_.direct_frames[q] = 0;
  std::fill_n(probes_.sky_of(q), probes_.sky_cells, SkyCell{});
}

void ProbeField::finish_direct_sh(std::size_t q) {
  float* out = probes_.direct_sh.data() + q * 75;
  std::copy_n(probes_.direct_mean.data() + q * 75, 75, out);
  sky_.add_sky_light(probes_.sky_of(q), out);
  if (settings_.direct_window) apply_hanning_window(out);
}

int ProbeField::scroll(glm::ivec3 cells, const ProbeField* seed) {
  if (cells == glm::ivec3(0)) return 0;
  settings_.grid.scroll_by(cells);
  grid_.scroll_by(cells);
  const std::size_t n = probes_.maps.size();
  int entered = 0;
  for (std::size_t q = 0; q < n; ++q) {
    if (!grid_.entered_by_scroll(static_cast<int>(q), cells)) continue;
    ++entered;
    forget_light(static_cast<int>(q));
    if (!grid_.offsets.empty()) grid_.offsets[q] = glm::vec3(0.0f);
    probes_.state[q] = ProbeState::Active;
    probes_.usable[q] = 1;
    probes_.saw_light[q] = 0;
    probes_.needs_classify[q] = settings_.skip.classify ? 1 : 0;
    probes_.urgent[q] = 1;
    probes_.last_traced[q] = 0;
    if (seed) seed->light_at_point(grid_.grid_point(static_cast<int>(q)), probes_.sh.data() + q * 75, probes_.direct_sh.data() + q * 75);
  }
  // Without a budget only a classification frame classifies: make the next one.
  if (settings_.skip.classify && settings_.update_budget <= 0) classify_pending_ = true;
  return entered;
}

void ProbeField::light_at_point(const glm::vec3& p, float* out, float* out_direct) const {
  const ProbeGrid::Cage cage = grid_.cage(p);
  std::fill_n(out, 75, 0.0f);
  std::fill_n(out_direct, 75, 0.0f);
  float sum = 0;
  for (std::size_t i = 0; i < 8; ++i) sum += probes_.usable[static_cast<std::size_t>(cage.probes[i])] ? cage.weights[i] : 0.0f;
  if (!(sum > 0)) return;
  for (std::size_t i = 0; i < 8; ++i) {
    const auto q = static_cast<std::size_t>(cage.probes[i]);
    if (!probes_.usable[q] || cage.weights[i] == 0.0f) continue;
    const float w = cage.weights[i] / sum;
    for (int k = 0; k < 75; ++k) {
      out[k] += w * probes_.sh[q * 75 + static_cast<std::size_t>(k)];
      out_direct[k] += w * probes_.direct_sh[q * 75 + static_cast<std::size_t>(k)];
    }
  }
}

// One update's per-probe scratch, handed from stage to stage.
struct ProbeField::UpdateWork {
  std::uint64_t seed = 0;
  bool classify = false;  // a classification frame: every probe traces
  bool budgeted = false;  // only the budget's probes trace
  std::vector<std::uint8_t> traced;                // per probe: it traces this frame
  std::vector<int> tracing;                        // the probes that trace
  std::vector<glm::vec3> directions;               // this frame's ray set
  std::vector<int> sky_cells;                      // each direction's sky cell (sky_visibility.h)
  std::vector<std::vector<ShadedPoint>> points;    // per probe: what its rays found
  std::vector<int> backfaces, hits;                // per probe: of its rays
  std::vector<float> nearest;                      // per probe: its nearest hit
  std::vector<float> direct_frame;                 // probes x 75: the sky and emitters its rays saw
  std::atomic<std::size_t> nonfinite_rays{0};      // rare
  std::vector<std::uint8_t> skip_this_frame;       // per probe: relocated, its rays left from elsewhere
  // The emitters' light samples (tracing probe j's at j * emitter_samples)
  // and their shadow rays, when the backend's tracer takes them along with
  // the probe rays (queue_emitter_samples).
  std::vector<engine::rt::Ray> emitter_rays;
  std::vector<engine::render::LightSample> emitter_samples;
  bool emitters_queued = false;
  // Whether classify_traced searches for open space this frame (plan_update),
  // and its segments, queued on the backend's tracer to go with the probe
  // rays (queue_open_space_segments).
  bool searches_open_space = false;
  std::optional<OpenSpaceSegments> open_space_ahead;
};

bool ProbeField::takes_frame(const UpdateWork& w, int q) const {
  const auto i = static_cast<std::size_t>(q);
  return probes_.state[i] == ProbeState::Active && (!w.budgeted || w.traced[i]) && !w.skip_this_frame[i];
}

void ProbeField::plan_update(UpdateWork& w) {
  using namespace engine;
  const int probes = grid_.count(), M = settings_.rays_per_probe;
  w.seed = settings_.fixed_pattern ? 0x5EEDu : settings_.seed;
  math::Pcg32 frame_rng = math::make_rng(w.seed, 0xF00D, frame_);
  const glm::quat rotation = settings_.fixed_pattern ? low_discrepancy_rotation(frame_) : random_rotation(frame_rng);
  w.classify = settings_.skip.classify && classify_pending_;
  // A classification frame traces every probe, as buried and far probes may
  // have become useful; otherwise only the active ones do any work.
  w.traced.resize(static_cast<std::size_t>(probes));
  for (std::size_t q = 0; q < w.traced.size(); ++q)
    w.traced[q] = w.classify || !settings_.skip.classify || probes_.state[q] == ProbeState::Active;
  const bool settling = frame_ < static_cast<std::uint64_t>(std::max(0, settings_.settle_frames));
  w.budgeted = settings_.update_budget > 0 && !w.classify && !settling;
  if (w.budgeted) select_within_budget(w.traced);
  w.directions.resize(static_cast<std::size_t>(M));
  w.sky_cells.resize(static_cast<std::size_t>(M));
  for (int i = 0; i < M; ++i) {
    w.directions[static_cast<std::size_t>(i)] = glm::normalize(rotation * fibonacci_[static_cast<std::size_t>(i)]);
    w.sky_cells[static_cast<std::size_t>(i)] = settings_.sky.cells.cell_of(w.directions[static_cast<std::size_t>(i)]);
  }
  w.points.resize(static_cast<std::size_t>(probes));
  w.backfaces.assign(static_cast<std::size_t>(probes), 0);
  w.hits.assign(static_cast<std::size_t>(probes), 0);
  w.nearest.assign(static_cast<std::size_t>(probes), std::numeric_limits<float>::infinity());
  w.direct_frame.assign(static_cast<std::size_t>(probes) * 75, 0.0f);
  w.skip_this_frame.assign(static_cast<std::size_t>(probes), 0);
  for (int q = 0; q < probes; ++q)
    if (w.traced[static_cast<std::size_t>(q)]) {
      w.tracing.push_back(q);
      w.points[static_cast<std::size_t>(q)].reserve(static_cast<std::size_t>(M));
      probes_.saw_light[static_cast<std::size_t>(q)] = 0;
    }
  w.searches_open_space = searches_open_space(w);
}

ProbeFeedbackSource ProbeField::feedback_source() const {
  return ProbeFeedbackSource{&grid_,
                             settings_.map,
                             &probes_.maps,
                             probes_.sh,
                             probes_.usable,
                             settings_.interpolation,
                             frame_ > 0,
                             settings_.hold_cells,
                             map_store_.get()};
}

void ProbeField::trace_and_shade(const engine::rt::RtScene& scene, const engine::render::LightSet& lights,
                                 const ProbeField* outer, UpdateWork& w, LightBatch* light) {
  using namespace engine;
  const int M = settings_.rays_per_probe;
  // Emitters are light-sampled instead (sample_emitters).
  const bool emitters_sampled = settings_.emitter_samples > 0 && lights.emissive_triangle_count() > 0;
  const bool with_sky = sky_.has_sky();
  const int sky_history = std::clamp(settings_.sky.history_rays, 1, 255);
  // What each ray found, kept by the probe that shot it.
  const auto consume = [&](int q, int i, const ProbeRayHit& h) {
    const auto qi = static_cast<std::size_t>(q);
    const glm::vec3& dir = w.directions[static_cast<std::size_t>(i)];
    // The sky: which way the probe sees out (its exact radiance is the sky
    // projection's); emitters: a Monte Carlo projection, below.
    if (with_sky) record_sky_ray(probes_.sky_of(qi)[w.sky_cells[static_cast<std::size_t>(i)]], !h.hit, sky_history);
    if (h.hit && h.emitted != glm::vec3(0.0f) && !emitters_sampled) {
      // Monte Carlo projection over a near-uniform set: 4 pi / M per ray.
      add_radiance_sh(w.direct_frame.data() + qi * 75, dir, h.emitted * (4.0f * math::kPi / static_cast<float>(M)));
    }
    ShadedPoint sp;
    sp.direction = dir;
    sp.distance = h.distance;
    sp.position = h.position;
    sp.radiance = h.radiance;
    sp.normal = h.normal;
    if (h.replaced_non_finite) w.nonfinite_rays.fetch_add(1, std::memory_order_relaxed);
    if (h.hit) {
      ++w.hits[qi];
      w.backfaces[qi] += h.back_face ? 1 : 0;
      w.nearest[qi] = std::min(w.nearest[qi], h.distance);
    }
    if (h.saw_light) probes_.saw_light[qi] = 1;
    w.points[qi].push_back(sp);
  };
  if (w.tracing.empty()) return;
  std::vector<glm::vec3> origins;
  origins.reserve(w.tracing.size());
  for (const int q : w.tracing) origins.push_back(grid_.position(q));
  // The bounce light reads last frame's SH (multi-bounce feedback): this
  // field's inside its box, the next coarser cascade's beyond it.
  const ProbeFeedbackSource self_source = feedback_source();
  const ProbeFeedbackSource outer_source = outer ? outer->feedback_source() : ProbeFeedbackSource{};
  // One probe's rays on one thread, in order: consume writes its data unlocked.
  const ProbeRayConsumer by_probe = [&](int j, int i, const ProbeRayHit& h) { consume(w.tracing[static_cast<std::size_t>(j)], i, h); };
  if (!light) {
    kernels_->shade_probe_rays(scene, lights, origins, w.tracing, w.directions, w.seed, frame_ + 1, self_source,
                               outer ? &outer_source : nullptr, by_probe);
    return;
  }
  ProbeRayRequest rays;
  rays.scene = &scene;
  rays.lights = &lights;
  rays.origins = origins;
  rays.probe_ids = w.tracing;
  rays.directions = w.directions;
  rays.seed = w.seed;
  rays.sample = frame_ + 1;
  rays.self = &self_source;
  rays.outer = outer ? &outer_source : nullptr;
  rays.emission = !emitters_sampled;
  light->result.sharing = kernels_->shade_and_light(rays, by_probe, light_request(w, *light));
}

namespace {

// Probe j's K light samples of the emitters from `origin`, stratified in the
// triangle-selection dimension, and their shadow rays; a failed sample gets
// pdf 0 and an empty segment.
void make_emitter_samples(const engine::render::LightSet& lights, const glm::vec3& origin, engine::math::Pcg32 rng, int K,
                          engine::rt::Ray* rays, engine::render::LightSample* samples) {
  using namespace engine;
  for (int k = 0; k < K; ++k) {
    const glm::vec2 u{(static_cast<float>(k) + rng.next_float()) / static_cast<float>(K), rng.next_float()};
    render::LightSample& ls = samples[k];
    if (!lights.sample_area_light(origin, glm::min(u, glm::vec2(0.99999994f)), ls) || !(ls.pdf > 0) ||
        ls.radiance == glm::vec3(0.0f)) {
      ls.pdf = 0;
      rays[k] = rt::Ray{origin, glm::vec3(0, 0, 1), 0.0f, 0.0f};
      continue;
    }
    rays[k] = rt::Ray{origin, ls.direction, 0.0f, ls.distance * (1.0f - 1e-4f)};
  }
}

// The unblocked of K samples into a probe's direct SH.
void project_emitter_samples(const engine::render::LightSample* samples, const std::uint8_t* blocked, int K, float* direct) {
  for (int k = 0; k < K; ++k) {
    const engine::render::LightSample& ls = samples[k];
    if (!(ls.pdf > 0) || blocked[k]) continue;
    const glm::vec3 light = ls.radiance / (ls.pdf * static_cast<float>(K));
    if (std::isfinite(light.r + light.g + light.b)) add_radiance_sh(direct, ls.direction, light);
  }
}

}  // namespace

engine::math::Pcg32 ProbeField::emitter_rng(const UpdateWork& w, int q) const {
  return engine::math::make_rng(w.seed ^ 0xE317u, static_cast<std::uint64_t>(q), frame_);
}

void ProbeField::queue_emitter_samples(const engine::rt::RtScene& scene, const engine::render::LightSet& lights, UpdateWork& w) {
  const int K = settings_.emitter_samples;
  w.emitters_queued = false;
  engine::rt::RayBatchTracer* tracer = kernels_->tracer();
  if (K <= 0 || lights.emissive_triangle_count() == 0 || w.tracing.empty() || !tracer) return;
  const std::size_t k_per_probe = static_cast<std::size_t>(K), n = w.tracing.size() * k_per_probe;
  w.emitter_rays.resize(n);
  w.emitter_samples.resize(n);
  engine::jobs::parallel_for<std::size_t>(0, w.tracing.size(), 32, [&](std::size_t b, std::size_t e) {
    for (std::size_t j = b; j < e; ++j) {
      const int q = w.tracing[j];
      make_emitter_samples(lights, grid_.position(q), emitter_rng(w, q), K, w.emitter_rays.data() + j * k_per_probe,
                           w.emitter_samples.data() + j * k_per_probe);
    }
  });
  tracer->occluded_later(scene, w.emitter_rays);
  w.emitters_queued = true;
}

void ProbeField::sample_emitters(const engine::rt::RtScene& scene, const engine::render::LightSet& lights, UpdateWork& w) {
  using namespace engine;
  const int K = settings_.emitter_samples;
  if (K <= 0 || lights.emissive_triangle_count() == 0 || w.tracing.empty()) return;
  const std::size_t k_per_probe = static_cast<std::size_t>(K), n = w.tracing.size() * k_per_probe;
  const auto project_all = [&](const std::vector<std::uint8_t>& blocked) {
    for (std::size_t j = 0; j < w.tracing.size(); ++j)
      project_emitter_samples(w.emitter_samples.data() + j * k_per_probe, blocked.data() + j * k_per_probe, K,
                              w.direct_frame.data() + static_cast<std::size_t>(w.tracing[j]) * 75);
  };
  // The backend's tracer took them with the probe rays (queue_emitter_samples).
  if (w.emitters_queued) {
    std::vector<std::uint8_t> blocked(n, 1);
    kernels_->tracer()->take_occluded(blocked);
    project_all(blocked);
    return;
  }
  // Without one, each probe's samples are made, traced and projected in one pass.
  jobs::parallel_for<std::size_t>(0, w.tracing.size(), 8, [&](std::size_t b, std::size_t e) {
    std::vector<rt::Ray> rays(k_per_probe);
    std::vector<render::LightSample> samples(k_per_probe);
    std::vector<std::uint8_t> blocked(k_per_probe);
    for (std::size_t j = b; j < e; ++j) {
      const int q = w.tracing[j];
      make_emitter_samples(lights, grid_.position(q), emitter_rng(w, q), K, rays.data(), samples.data());
      for (std::size_t k = 0; k < k_per_probe; ++k) blocked[k] = samples[k].pdf > 0 && scene.occluded(rays[k]) ? 1 : 0;
      project_emitter_samples(samples.data(), blocked.data(), K, w.direct_frame.data() + static_cast<std::size_t>(q) * 75);
    }
  });
}

bool ProbeField::searches_open_space(const UpdateWork& w) const {
  // A classification frame, or a budgeted one where a traced probe is queued
  // for classification.
  if (!settings_.skip.open_space || !(w.classify || w.budgeted)) return false;
  bool any_pending = w.classify;
  for (std::size_t q = 0; q < probes_.state.size() && !any_pending; ++q) any_pending = w.traced[q] && probes_.needs_classify[q];
  return any_pending;
}

void ProbeField::queue_open_space_segments(const engine::rt::RtScene& scene, UpdateWork& w) {
  engine::rt::RayBatchTracer* tracer = kernels_->tracer();
  if (!tracer || !w.searches_open_space) return;
  // The search's segments do not depend on this frame's rays; which
  // relocation segments it traces depends on which probes no chain reaches,
  // guessed from the last search (buried or moved probes) and from where the
  // geometry changed (urgent probes: notify_region_changed).
  std::vector<std::uint8_t> expected_unlinked(probes_.state.size(), 0);
  for (std::size_t q = 0; q < expected_unlinked.size(); ++q)
    expected_unlinked[q] = probes_.state[q] == ProbeState::Buried || probes_.urgent[q] ||
                           (!grid_.offsets.empty() && grid_.offsets[q] != glm::vec3(0.0f));
  w.open_space_ahead = open_space_segments(grid_, expected_unlinked);
  tracer->distances_later(scene, w.open_space_ahead->rays);
}

void ProbeField::classify_traced(const engine::rt::RtScene& scene, UpdateWork& w) {
  const int M = settings_.rays_per_probe;
  const float far = settings_.skip.far_cells * glm::length(grid_.spacing());
  if (w.open_space_ahead) {
    OpenSpaceSegments& ahead = *w.open_space_ahead;
    ahead.hit_t.resize(ahead.rays.size());
    kernels_->tracer()->take_distances(ahead.hit_t);
  }
  const OpenSpace open = w.searches_open_space ? find_open_space(scene, grid_, probes_.saw_light, settings_.skip.relocation,
                                                                  kernels_->tracer(), w.open_space_ahead ? &*w.open_space_ahead : nullptr)
                                                : OpenSpace{};
  if (!open.open.empty() && grid_.offsets.empty()) grid_.offsets.assign(probes_.state.size(), glm::vec3(0.0f));
  for (std::size_t q = 0; q < probes_.state.size(); ++q) {
    if (w.traced[q]) {
      probes_.last_traced[q] = frame_;
      probes_.urgent[q] = 0;
    }
    // Budgeted frames classify only the probes queued for it.
    if (!w.classify && !(w.traced[q] && probes_.needs_classify[q])) continue;
    probes_.needs_classify[q] = 0;
    const bool buried = static_cast<float>(w.backfaces[q]) > settings_.skip.buried_backface_fraction * static_cast<float>(M) ||
                        (!open.open.empty() && !open.open[q]);
    bool moved = false;
    if (!open.open.empty() && !buried && open.offsets[q] != grid_.offsets[q]) {
      // This frame's rays left from where the probe stood: it starts afresh
      // from its new place next frame.
      grid_.offsets[q] = open.offsets[q];
      moved = true;
    }
    const bool relocated = !grid_.offsets.empty() && grid_.offsets[q] != glm::vec3(0.0f);
    probes_.state[q] = buried ? ProbeState::Buried : w.nearest[q] > far && !relocated ? ProbeState::Far : ProbeState::Active;
    if (moved) w.skip_this_frame[q] = 1;
    probes_.usable[q] = probes_.state[q] == ProbeState::Active ? 1 : 0;
    // Holds no light (and starts afresh if it becomes active again), or its
    // light was gathered where it no longer stands.
    if (moved || !probes_.usable[q]) {
      forget_light(static_cast<int>(q));
      w.points[q].clear();
    } else if (!probes_.maps[q].held()) {
      // Active again: fresh maps (as forget_light left them when it was
      // released); this frame's rays count.
      probes_.maps[q].reset(settings_.map.texel_count(), depth_unit());
    }
    // No light, no maps.
    if (!probes_.usable[q]) probes_.maps[q].release();
  }
  classify_pending_ = false;
}

ProbeField::LightBatch ProbeField::light_batch(const UpdateWork& w) {
  const int probes = grid_.count();
  LightBatch b;
  // The backend updates each batch probe's depth from its own rays first.
  b.depth.resize(static_cast<std::size_t>(probes));
  for (int q = 0; q < probes; ++q) b.depth[static_cast<std::size_t>(q)] = &probes_.maps[static_cast<std::size_t>(q)].depth;
  // Every updated probe in one batch for the backend.
  for (int q = 0; q < probes; ++q)
    if (takes_frame(w, q)) b.batch.push_back(q);
  for (const int q : b.batch) b.states.push_back(&probes_.maps[static_cast<std::size_t>(q)]);
  b.changed.assign(b.batch.size(), 0);
  b.projected.assign(b.batch.size() * 75, 0.0f);
  return b;
}

ProbeLightRequest ProbeField::light_request(const UpdateWork& w, LightBatch& b) {
  ProbeLightRequest r;
  r.grid = &grid_;
  r.projector = &projector_;
  r.points = &w.points;
  r.own_depth = &b.depth;
  r.sharing = &settings_.sharing;
  r.batch = b.batch;
  r.states = b.states;
  r.store = map_store_.get();
  r.accumulation = &settings_.accumulation;
  r.changed = b.changed;
  r.sh = b.projected;
  r.times = &b.result.times;
  return r;
}

ProbeField::LightIntoProbes ProbeField::share_accumulate_project(UpdateWork& w) {
  LightBatch b = light_batch(w);
  const ProbeLightRequest r = light_request(w, b);
  b.result.sharing = kernels_->share_accumulate_project(*r.grid, *r.projector, *r.points, *r.own_depth, *r.sharing, r.batch, r.states,
                                                        r.store, *r.accumulation, r.changed, r.sh, *r.times);
  finish_light(w, b);
  return b.result;
}

void ProbeField::finish_light(const UpdateWork& w, LightBatch& b) {
  using namespace engine;
  std::atomic<int> bad_probes{0};
  // After probe q's map took its frame (changed: it detected a change of
  // light): its convergence and its direct-light mean.
  auto after_accumulation = [&](int q, bool changed) {
    const ProbeMapState& st = probes_.maps[static_cast<std::size_t>(q)];
    probes_.changed[static_cast<std::size_t>(q)] = changed ? 1 : 0;
    if (settings_.skip.skip_converged && st.stable_frames >= settings_.skip.settle_frames)
      probes_.state[static_cast<std::size_t>(q)] = ProbeState::Converged;
    const std::size_t at = static_cast<std::size_t>(q) * 75;
    const std::uint32_t frames = probes_.direct_frames[static_cast<std::size_t>(q)] =
        std::min<std::uint32_t>(probes_.direct_frames[static_cast<std::size_t>(q)] + 1, static_cast<std::uint32_t>(std::max(1, settings_.direct_history)));
    for (int k = 0; k < 75; ++k)
      probes_.direct_mean[at + k] += (w.direct_frame[at + k] - probes_.direct_mean[at + k]) / static_cast<float>(frames);
    finish_direct_sh(static_cast<std::size_t>(q));
  };
  // After probe q's SH is projected into probes_.sh.
  auto finish_probe = [&](int q) {
    const std::size_t at = static_cast<std::size_t>(q) * 75;
    float* out = probes_.sh.data() + at;
    if (settings_.window) apply_hanning_window(out);
    bool finite = true;
    for (int k = 0; k < 75; ++k)
      finite = finite && std::isfinite(out[k]) && std::isfinite(probes_.direct_sh[at + k]) && std::isfinite(probes_.direct_mean[at + k]);
    if (!finite) {
      // A value that got past the ray guards (an overflowing sum): this
      // probe's light is unusable, so it starts afresh rather than spread it.
      forget_light(q);
      bad_probes.fetch_add(1, std::memory_order_relaxed);
    }
  };
  const auto t0 = Clock::now();
  jobs::parallel_for(0, static_cast<int>(b.batch.size()), 1, [&](int lo, int hi) {
    for (int i = lo; i < hi; ++i) {
      const int q = b.batch[static_cast<std::size_t>(i)];
      after_accumulation(q, b.changed[static_cast<std::size_t>(i)] != 0);
      std::copy_n(b.projected.data() + static_cast<std::size_t>(i) * 75, 75, probes_.sh.data() + static_cast<std::size_t>(q) * 75);
      finish_probe(q);
    }
  });
  b.result.times.accumulate_ms += ms_since(t0);
  b.result.nonfinite_probes = bad_probes.load();
}

bool ProbeField::batch_known_before_rays(const UpdateWork& w) const {
  // A classification frame decides every probe's state from its rays before
  // any takes light (the first frame's buried probes must not leak into
  // their neighbours). A budgeted frame classifies only the few probes
  // queued for it (a moved object's neighbourhood) and they take the change
  // from the next frame: the light goes with the rays.
  return !w.classify;
}

void ProbeField::update_means_and_counts(ProbeFrameStats& stats) {
  // The ambient term: the mean of the probes that hold light.
  std::fill(mean_sh_.begin(), mean_sh_.end(), 0.0f);
  std::fill(mean_direct_sh_.begin(), mean_direct_sh_.end(), 0.0f);
  std::size_t lit = 0;
  for (std::size_t q = 0; q < probes_.state.size(); ++q) {
    if (!probes_.usable[q]) continue;
    ++lit;
    for (std::size_t k = 0; k < 75; ++k) {
      mean_sh_[k] += probes_.sh[q * 75 + k];
      mean_direct_sh_[k] += probes_.direct_sh[q * 75 + k];
    }
  }
  for (std::size_t k = 0; k < 75 && lit > 0; ++k) {
    mean_sh_[k] /= static_cast<float>(lit);
    mean_direct_sh_[k] /= static_cast<float>(lit);
  }
  for (std::size_t q = 0; q < probes_.state.size(); ++q) {
    stats.active += probes_.state[q] == ProbeState::Active;
    stats.converged += probes_.state[q] == ProbeState::Converged;
    stats.buried += probes_.state[q] == ProbeState::Buried;
    stats.far += probes_.state[q] == ProbeState::Far;
    stats.relocated += !grid_.offsets.empty() && grid_.offsets[q] != glm::vec3(0.0f) && probes_.state[q] != ProbeState::Buried;
  }
}

ProbeFrameStats ProbeField::update(const engine::rt::RtScene& scene, const engine::render::LightSet& lights,
                                   const ProbeField* outer) {
  ProbeFrameStats stats;
  UpdateWork w;
  // A changed sky (map, orientation or strength) re-lights every probe from
  // what it knows of its view, now, whether or not it traces this frame.
  const bool sky_changed = sky_.refresh(lights.environment(), settings_.sky);
  plan_update(w);
  stats.classified = w.classify;

  // 1. Scatter and shade (reads the previous frame's SH for the feedback
  // bounce), then classify what traced.
  // Where no classification waits on the rays, the batch is known now and
  // the backend takes the rays and the light as one stage (on a device, one
  // submission); the light's set-up and read-back then count as sharing
  // and projection, the rest as scattering.
  auto t0 = Clock::now();
  std::optional<LightBatch> together;
  if (!w.tracing.empty() && batch_known_before_rays(w)) together = light_batch(w);
  queue_open_space_segments(scene, w);
  queue_emitter_samples(scene, lights, w);
  trace_and_shade(scene, lights, outer, w, together ? &*together : nullptr);
  sample_emitters(scene, lights, w);
  for (std::uint8_t t : w.traced) stats.traced += t;
  stats.rays = static_cast<std::size_t>(stats.traced) * static_cast<std::size_t>(settings_.rays_per_probe);
  stats.hits = 0;
  for (const int n : w.hits) stats.hits += static_cast<std::size_t>(n);
  stats.nonfinite_rays = w.nonfinite_rays.load();
  // The light that went with the rays is kept before this frame's
  // classification, which may forget some of it.
  if (together) finish_light(w, *together);
  if (w.classify || w.budgeted) classify_traced(scene, w);
  stats.scatter_ms = ms_since(t0);

  // 2. Share, accumulate, fill, project.
  t0 = Clock::now();
  LightIntoProbes light;
  if (together) {
    // Its light stage and what followed it ran inside the scattering's time.
    stats.scatter_ms -= together->result.times.share_ms + together->result.times.accumulate_ms;
    light = together->result;
  } else {
    light = share_accumulate_project(w);
  }
  stats.shared_accepted = light.sharing.accepted;
  stats.shared_rejected = light.sharing.rejected_by_guard;
  stats.nonfinite_probes = light.nonfinite_probes;
  // The own depth maps' update and the batch's set-up count as sharing.
  stats.project_ms = light.times.accumulate_ms;
  stats.raster_ms = together ? light.times.share_ms : ms_since(t0) - stats.project_ms;
  if (sky_changed)
    engine::jobs::parallel_for(0, grid_.count(), 64, [&](int b, int e) {
      for (int q = b; q < e; ++q)
        if (probes_.usable[static_cast<std::size_t>(q)] && !takes_frame(w, q)) finish_direct_sh(static_cast<std::size_t>(q));
    });
  update_means_and_counts(stats);
  ++frame_;
  return stats;
}

}  // namespace transgi::probes
