#include "ddgi/ddgi_volume.h"

#include "ddgi/ddgi_blend.h"
#include "ddgi/cpu_ddgi_kernels.h"
#include "ddgi/ddgi_kernels.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>

#include "engine/jobs/parallel_for.h"
#include "engine/math/rng.h"
#include "engine/math/sampling.h"
#include "probes/open_space.h"
#include "probes/probe_rays.h"

namespace transgi::ddgi {

namespace {
using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

// RTXGI records missed rays at its default maximum ray distance.
constexpr float kMissDistance = 1e27f;
// Backface hits are stored negative and shortened (RTXGI's ProbeTraceRGS).
constexpr float kBackfaceDistanceScale = -0.2f;

// x^(gamma / 2): a stored texel (gamma-encoded) re-encoded with gamma 2.
// RTXGI's gamma 5 is x^2 sqrt(x), which costs a square root where pow costs
// a fifth of the whole lookup.
glm::vec3 to_gamma_two(const glm::vec3& x, float gamma) {
  if (gamma == 5.0f) return x * x * glm::sqrt(x);
  return glm::pow(x, glm::vec3(0.5f * gamma));
}

}  // namespace

DdgiVolume::DdgiVolume(const probes::ProbeGrid& grid, const DdgiSettings& settings)
    : kernels_(cpu_ddgi_kernels()), grid_(grid), placed_(grid), settings_(settings), directions_(probes::spherical_fibonacci(settings.rays_per_probe)) {
  const auto count = static_cast<std::size_t>(grid.count());
  irradiance_.assign(count, OctahedralMap<glm::vec3>(settings.irradiance_texels, glm::vec3(0.0f)));
  // Until measured, distances read as "far": nothing is occluded.
  distance_.assign(count, OctahedralMap<glm::vec2>(settings.distance_texels, glm::vec2(0.0f)));
  if (settings.emitted_maps) emitted_.assign(count, OctahedralMap<glm::vec3>(settings.irradiance_texels, glm::vec3(0.0f)));
  active_.assign(count, 1);
}

std::size_t DdgiVolume::memory_bytes() const {
  std::size_t b = 0;
  for (const auto& m : irradiance_) b += m.texels.size() * sizeof(glm::vec3);
  for (const auto& m : distance_) b += m.texels.size() * sizeof(glm::vec2);
  for (const auto& m : emitted_) b += m.texels.size() * sizeof(glm::vec3);
  return b;
}

void DdgiVolume::set_kernels(std::shared_ptr<DdgiKernels> kernels) {
  kernels_ = kernels ? std::move(kernels) : cpu_ddgi_kernels();
}

int DdgiVolume::scroll(glm::ivec3 cells, const DdgiVolume* seed) {
  if (cells == glm::ivec3(0)) return 0;
  emitted_view_.reset();  // its maps are about to move
  grid_.scroll_by(cells);
  placed_.scroll_by(cells);
  int entered = 0;
  for (int q = 0; q < grid_.count(); ++q) {
    if (!grid_.entered_by_scroll(q, cells)) continue;
    ++entered;
    const auto i = static_cast<std::size_t>(q);
    if (!placed_.offsets.empty()) placed_.offsets[i] = glm::vec3(0.0f);
    active_[i] = 1;
    OctahedralMap<glm::vec3>& irr = irradiance_[i];
    std::fill(irr.texels.begin(), irr.texels.end(), glm::vec3(0.0f));
    if (seed) {
      // What the coarser cascade says a surface here facing each texel's
      // direction receives, stored as the maps store it.
      const glm::vec3 p = grid_.grid_point(q);
      for (int y = 0; y < irr.interior; ++y)
        for (int x = 0; x < irr.interior; ++x) {
          const glm::vec3 d = texel_direction(x, y, irr.interior);
          const glm::vec3 e = seed->irradiance(p, d, -d) / engine::math::kTwoPi;
          irr.at(x + 1, y + 1) = glm::pow(glm::max(e, glm::vec3(0.0f)), glm::vec3(1.0f / settings_.irradiance_gamma));
        }
      update_border(irr);
    }
    std::fill(distance_[i].texels.begin(), distance_[i].texels.end(), glm::vec2(0.0f));
    if (!emitted_.empty()) std::fill(emitted_[i].texels.begin(), emitted_[i].texels.end(), glm::vec3(0.0f));
  }
  // Entered probes may stand inside walls: classify again (per cascade).
  if (settings_.classification) classified_ = false;
  return entered;
}

std::vector<int> DdgiVolume::probes_to_trace(bool all) {
  std::vector<int> active;
  for (int q = 0; q < grid_.count(); ++q)
    if (active_[static_cast<std::size_t>(q)]) active.push_back(q);
  const auto budget = static_cast<std::size_t>(std::max(settings_.probes_per_update, 0));
  if (all || budget == 0 || active.size() <= budget) return active;
  // Every stride-th active probe from this turn's offset: after `stride`
  // updates each active probe has been traced once.
  const std::size_t stride = (active.size() + budget - 1) / budget;
  const std::size_t offset = budget_turn_++ % stride;
  std::vector<int> turn;
  for (std::size_t i = offset; i < active.size(); i += stride) turn.push_back(active[i]);
  return turn;
}

// The probe rays of this update (all active probes, or this turn's share),
// traced and shaded: one record per ray and probe, and with emitted maps
// what each ray met straight from emitters and the sky.
DdgiVolume::UpdateRays DdgiVolume::trace(const engine::rt::RtScene& scene, const engine::render::LightSet& lights,
                                         const engine::scene::Environment* sky, const DdgiVolume* outer, bool all) {
  using namespace engine;
  const int probes = grid_.count(), M = settings_.rays_per_probe;
  math::Pcg32 frame_rng = math::make_rng(settings_.seed, 0xDD61, frame_);
  const glm::quat rotation = probes::random_rotation(frame_rng);
  UpdateRays u;
  u.records.resize(static_cast<std::size_t>(probes));
  u.emitted.resize(emitted_.empty() ? 0 : static_cast<std::size_t>(probes));
  u.saw_light.assign(static_cast<std::size_t>(probes), 0);
  // The bounce light from the last update's maps: the next coarser
  // cascade's outside this grid's box.
  const ProbeRayBounce bounce = [&](const glm::vec3& p, const glm::vec3& n, const glm::vec3& towards_probe) {
    if (outer && (glm::any(glm::lessThan(p, grid_.held_min(settings_.hold_cells))) ||
                  glm::any(glm::greaterThan(p, grid_.held_max(settings_.hold_cells)))))
      return outer->irradiance(p, n, -towards_probe);
    return frame_ > 0 ? irradiance(p, n, -towards_probe) : glm::vec3(0.0f);
  };
  std::vector<glm::vec3> ray_directions(static_cast<std::size_t>(M));
  for (int i = 0; i < M; ++i) ray_directions[static_cast<std::size_t>(i)] = glm::normalize(rotation * directions_[static_cast<std::size_t>(i)]);
  const std::vector<int> tracing = probes_to_trace(all);
  for (int q : tracing) {
    u.records[static_cast<std::size_t>(q)].resize(static_cast<std::size_t>(M));
    if (!emitted_.empty()) u.emitted[static_cast<std::size_t>(q)].resize(static_cast<std::size_t>(M));
  }
  std::vector<glm::vec3> origins;
  origins.reserve(tracing.size());
  for (const int q : tracing) origins.push_back(placed_.position(q));
  // What each ray found, recorded by the probe that shot it.
  const auto record = [&](int q, int i, const probes::ProbeRayHit& h) {
    if (h.saw_light) u.saw_light[static_cast<std::size_t>(q)] = 1;
    const glm::vec3& dir = ray_directions[static_cast<std::size_t>(i)];
    RayRecord& r = u.records[static_cast<std::size_t>(q)][static_cast<std::size_t>(i)];
    r.direction = dir;
    if (!h.hit) {
      r.radiance = settings_.escaped == EscapedRays::Environment && sky ? sky->radiance(dir) : glm::vec3(0.0f);
      r.distance = kMissDistance;
    } else if (h.back_face) {
      r.radiance = glm::vec3(0.0f);
      r.distance = kBackfaceDistanceScale * h.distance;
    } else {
      r.radiance = h.radiance;
      r.distance = h.distance;
    }
    if (!emitted_.empty())
      u.emitted[static_cast<std::size_t>(q)][static_cast<std::size_t>(i)] = {dir, h.back_face ? glm::vec3(0.0f) : h.emitted,
                                                                            r.distance};
  };
  if (!tracing.empty())
    kernels_->shade_probe_rays(scene, lights, origins, tracing, ray_directions, settings_.seed, frame_ + 1, bounce,
                               [&](int j, int i, const probes::ProbeRayHit& h) { record(tracing[static_cast<std::size_t>(j)], i, h); });
  u.rays = tracing.size() * static_cast<std::size_t>(M);
  return u;
}

// Back faces (single-sided materials only) as RTXGI counts them, and the
// winding-proof link to light for double-sided content (open_space.h).
void DdgiVolume::classify(const engine::rt::RtScene& scene, UpdateRays& u) {
  const int probes = grid_.count(), M = settings_.rays_per_probe;
  const probes::OpenSpace open =
      probes::find_open_space(scene, grid_, u.saw_light, settings_.relocation, kernels_->tracer());
  placed_.offsets.assign(static_cast<std::size_t>(probes), glm::vec3(0.0f));
  for (int q = 0; q < probes; ++q) {
    const auto i = static_cast<std::size_t>(q);
    int backfaces = 0;
    for (const RayRecord& r : u.records[i]) backfaces += r.distance < 0 ? 1 : 0;
    active_[i] = static_cast<float>(backfaces) <= settings_.fixed_ray_backface_threshold * static_cast<float>(M) && open.open[i];
    if (active_[i]) placed_.offsets[i] = open.offsets[i];
    // A moved probe's rays this frame left from its old place.
    if (!active_[i] || placed_.offsets[i] != glm::vec3(0.0f)) {
      u.records[i].clear();
      if (!emitted_.empty()) u.emitted[i].clear();
    }
  }
  classified_ = true;
}

// The records into the maps with hysteresis h: irradiance and distance
// through the backend, then the emitted maps.
void DdgiVolume::blend(UpdateRays& u, float h, bool warming) {
  const int probes = grid_.count();
  const float max_distance = 1.5f * glm::length(grid_.spacing());
  for (int q = 0; q < probes; ++q)
    if (!active_[static_cast<std::size_t>(q)]) u.records[static_cast<std::size_t>(q)].clear();
  kernels_->blend(irradiance_, distance_, u.records, settings_, h, !warming, max_distance);
  if (emitted_.empty()) return;
  // A small emitter is met by a ray now and then: a bright texel one
  // update, dark the next. RTXGI's running mean of gamma-encoded texels,
  // its brightness clamp and its faster darkening all bias that towards
  // black (they made a ceiling lamp's light vanish); a plain running mean
  // of linear values keeps it.
  DdgiSettings plain = settings_;
  plain.irradiance_gamma = 1.0f;
  plain.irradiance_threshold = std::numeric_limits<float>::infinity();
  engine::jobs::parallel_for(0, probes, 1, [&](int b, int e) {
    for (int q = b; q < e; ++q) {
      const auto& rec = u.emitted[static_cast<std::size_t>(q)];
      if (rec.empty() || !active_[static_cast<std::size_t>(q)]) continue;
      blend_irradiance(emitted_[static_cast<std::size_t>(q)], rec, plain, h, false);
    }
  });
}

DdgiFrameStats DdgiVolume::update(const engine::rt::RtScene& scene, const engine::render::LightSet& lights,
                                  const engine::scene::Environment* sky, const DdgiVolume* outer) {
  DdgiFrameStats stats;
  const bool classify_now = settings_.classification && !classified_;
  const bool warming = frame_ < static_cast<std::uint64_t>(settings_.warmup_frames);
  auto t0 = Clock::now();
  UpdateRays u = trace(scene, lights, sky, outer, warming || classify_now);
  stats.rays = u.rays;
  stats.trace_ms = ms_since(t0);
  if (classify_now) classify(scene, u);
  t0 = Clock::now();
  // The cold start: hysteresis rising from 0.5 over the warm-up.
  const float h = warming ? std::min(settings_.hysteresis, 0.5f + (settings_.hysteresis - 0.5f) * static_cast<float>(frame_) /
                                                                       static_cast<float>(settings_.warmup_frames))
                          : settings_.hysteresis;
  blend(u, h, warming);
  stats.blend_ms = ms_since(t0);
  for (std::uint8_t a : active_) stats.inactive += a ? 0 : 1;
  ++frame_;
  return stats;
}

const DdgiVolume& DdgiVolume::emitted_view() const {
  if (emitted_.empty()) throw std::logic_error("DdgiVolume::emitted_view: the volume has no emitted maps");
  if (!emitted_view_ || emitted_view_frame_ != frame_) {
    make_emitted_view();
    emitted_view_frame_ = frame_;
  }
  return *emitted_view_;
}

void DdgiVolume::make_emitted_view() const {
  DdgiSettings linear = settings_;
  linear.emitted_maps = false;
  linear.irradiance_gamma = 1.0f;
  auto view = std::make_shared<DdgiVolume>(grid_, linear);
  view->placed_ = placed_;
  view->irradiance_ = emitted_;
  view->distance_ = distance_;
  view->active_ = active_;
  view->classified_ = classified_;
  view->frame_ = frame_;
  view->kernels_ = kernels_;
  emitted_view_ = std::move(view);
}

glm::vec2 DdgiVolume::biases() const {
  const float cap = 0.4f * grid_.min_spacing();
  return {std::min(settings_.normal_bias, cap), std::min(settings_.view_bias, cap)};
}

glm::vec3 DdgiVolume::irradiance(const glm::vec3& position, const glm::vec3& n, const glm::vec3& view_dir, bool* lit,
                                  glm::vec3* emitted) const {
  if (lit) *lit = false;
  if (emitted) *emitted = glm::vec3(0.0f);
  const bool with_emitted = emitted && !emitted_.empty();
  glm::vec3 emitted_sum(0.0f);
  const glm::vec2 b = biases();
  const glm::vec3 bias = n * b.x - view_dir * b.y;
  const glm::vec3 biased = position + bias;
  const glm::vec3 spacing = grid_.spacing();
  glm::ivec3 base(0);
  glm::vec3 alpha(0.0f);
  for (int a = 0; a < 3; ++a) {
    if (grid_.dims[a] < 2 || spacing[a] <= 0) continue;
    const float rel = (biased[a] - grid_.min[a]) / spacing[a];
    base[a] = std::clamp(static_cast<int>(std::floor(rel)), 0, grid_.dims[a] - 1);
    alpha[a] = std::clamp(rel - static_cast<float>(base[a]), 0.0f, 1.0f);
  }
  const glm::vec2 normal_oct = octahedral_coordinates(n);  // the same texel position in every probe's map
  glm::vec3 sum(0.0f);
  float weights = 0.0f;
  for (int i = 0; i < 8; ++i) {
    const glm::ivec3 offset(i & 1, (i >> 1) & 1, (i >> 2) & 1);
    const glm::ivec3 c = glm::clamp(base + offset, glm::ivec3(0), grid_.dims - 1);
    const int q = grid_.index(c);
    if (!active_[static_cast<std::size_t>(q)]) continue;
    const glm::vec3 probe = placed_.position(q);
    const glm::vec3 to_probe = glm::normalize(probe - position);
    const glm::vec3 biased_to_probe = probe - biased;
    const float biased_dist = glm::length(biased_to_probe);
    const glm::vec3 trilinear3 = glm::max(glm::vec3(0.001f), glm::mix(glm::vec3(1.0f) - alpha, alpha, glm::vec3(offset)));
    const float trilinear = trilinear3.x * trilinear3.y * trilinear3.z;
    // Wrap shading instead of a hard back-face cut, so small details inside
    // a room keep some probe with mutual visibility.
    const float wrap = 0.5f * (glm::dot(to_probe, n) + 1.0f);
    float w = wrap * wrap + 0.2f;
    const glm::vec2 moments = biased_dist > 0 ? sample_bilinear(distance_[static_cast<std::size_t>(q)], -biased_to_probe / biased_dist)
                                              : glm::vec2(0.0f);
    float chebyshev = 1.0f;
    if (biased_dist > moments.x) {
      const float variance = std::abs(moments.x * moments.x - moments.y);
      const float v = biased_dist - moments.x;
      chebyshev = variance / (variance + v * v);
      chebyshev = std::max(chebyshev * chebyshev * chebyshev, 0.0f);
    }
    w *= std::max(0.05f, chebyshev);
    w = std::max(0.000001f, w);
    constexpr float kCrush = 0.2f;  // perceptually, a little light is a lot: crush tiny weights
    if (w < kCrush) w *= w * w / (kCrush * kCrush);
    w *= trilinear;
    // Undo the tone curve but keep gamma 2, to blend in a perceptual space.
    const glm::vec3 e = to_gamma_two(glm::max(sample_bilinear_at(irradiance_[static_cast<std::size_t>(q)], normal_oct), glm::vec3(0.0f)),
                                     settings_.irradiance_gamma);
    sum += w * e;
    weights += w;
    if (with_emitted)
      emitted_sum += w * glm::sqrt(glm::max(sample_bilinear_at(emitted_[static_cast<std::size_t>(q)], normal_oct), glm::vec3(0.0f)));
  }
  if (weights <= 0) return glm::vec3(0.0f);
  if (lit) *lit = true;
  if (with_emitted) {
    const glm::vec3 em = emitted_sum / weights;
    *emitted = em * em * engine::math::kTwoPi;
  }
  glm::vec3 e = sum / weights;
  return e * e * engine::math::kTwoPi;
}

}  // namespace transgi::ddgi
