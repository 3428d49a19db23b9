#include "probes/probe_map.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "engine/jobs/parallel_for.h"

namespace transgi::probes {

void ProbeMapState::reset(int texels, float depth_unit) {
  const auto n = static_cast<std::size_t>(texels);
  radiance.assign(n, HalfRgb{});
  radiance_scale = 1.0f;
  sampled.assign(n, 0);
  depth.reset(texels, depth_unit);
  noise_variance = 0.0f;
  noise_frames = 0;
  frames = 0;
  stable_frames = 0;
  depth_frames = 0;
  drift = 0.0f;
  device_stamp = 0;
}

void ProbeMapState::release() {
  const float unit = depth.unit;
  *this = ProbeMapState{};
  depth.unit = unit;
}

glm::vec3 ProbeMapState::radiance_at(std::size_t t) const {
  const HalfRgb& h = radiance[t];
  using engine::math::from_half;
  return glm::vec3(from_half(h.r), from_half(h.g), from_half(h.b)) * radiance_scale;
}

namespace {
std::uint16_t stored_half(float v, float scale) {
  return engine::math::to_half(std::clamp(v / scale, 0.0f, engine::math::kHalfMax));
}
}  // namespace

void ProbeMapState::set_radiance(std::size_t t, const glm::vec3& v) {
  radiance[t] = {stored_half(v.r, radiance_scale), stored_half(v.g, radiance_scale), stored_half(v.b, radiance_scale)};
}

float fitted_scale(float scale, float peak) {
  if (!(peak > 0) || !std::isfinite(peak)) return scale;
  const float stored = peak / scale;
  if (stored <= 16384.0f && stored >= 0.25f) return scale;
  return std::ldexp(1.0f, std::ilogb(peak) + 1 - 12);  // the peak lands in [2^11, 2^12)
}

namespace {
float luminance(const glm::vec3& c) { return 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b; }
}  // namespace

namespace {

// The history as floats in real units (one bulk conversion).
void load_history(const ProbeMapState& st, std::vector<glm::vec3>& out) {
  out.resize(st.radiance.size());
  engine::math::from_halves(&st.radiance.data()->r, &out.data()->x, 3 * out.size());
  for (glm::vec3& v : out) v *= st.radiance_scale;
}

// Stores `next` as the history. A blend step under half an ulp would round
// back to the old value forever and leave the history up to
// 2^-12 / (1 - h) off a steady light (0.5 % at h = 0.95); such a step moves
// one ulp instead. Values are non-negative halves, whose bit patterns order
// like their values. `old` is the history before the step, at the same scale.
void store_history(ProbeMapState& st, std::vector<glm::vec3>& next, const std::vector<glm::vec3>* old) {
  const float inv = 1.0f / st.radiance_scale;
  for (glm::vec3& v : next) v = glm::clamp(v * inv, glm::vec3(0.0f), glm::vec3(engine::math::kHalfMax));
  thread_local std::vector<HalfRgb> bits;
  bits.resize(next.size());
  engine::math::to_halves(&next.data()->x, &bits.data()->r, 3 * next.size());
  if (old) {
    const float* target = &next.data()->x;
    const float* before = &old->data()->x;
    const std::uint16_t* was = &st.radiance.data()->r;
    std::uint16_t* now = &bits.data()->r;
    for (std::size_t i = 0; i < 3 * next.size(); ++i) {
      const float b = before[i] * inv;
      if (now[i] == was[i] && target[i] != b)
        now[i] = target[i] > b ? static_cast<std::uint16_t>(std::min(now[i] + 1, 0x7bff))
                               : static_cast<std::uint16_t>(std::max(now[i] - 1, 0));
    }
  }
  st.radiance.swap(bits);
}

}  // namespace

bool accumulate(ProbeMapState& st, const FrameSamples& f, const AccumulationSettings& s) {
  thread_local std::vector<glm::vec3> history, next;
  load_history(st, history);
  // "The lighting changed" is decided once per probe, from the mean over
  // every texel sampled this frame, and only when the change is far outside
  // the probe's own frame-to-frame noise. A blend weight that depends on the
  // current (noisy) value biases the mean: deciding per texel measured 5 %
  // low, per probe without the noise test 5 % high on a lit floor
  // (tests/transgi/probe_field_test.cpp).
  //
  // The change is the median over kChangeGroups interleaved sets of texels,
  // not the change of their total: one firefly (a probe ray that catches the
  // sun's glint on a near-mirror) moves one set's sum, while a real change of
  // light (a sun that turns, a lamp) moves every set that sees its region.
  // Judged on the total, a firefly counted as a change got the fast blend,
  // ten times its weight, and the probe kept its light: on the Breakfast
  // Room the image's mean GI jumped 3.6x in one frame of a still scene and
  // crept 30 % up over 400 frames (docs/results.md, issue 16).
  constexpr int kChangeGroups = 8;
  std::array<double, kChangeGroups> old_group{}, new_group{};
  float peak = 0;
  for (std::size_t t = 0; t < history.size(); ++t) {
    const glm::vec3& old = history[t];
    peak = std::max(peak, std::max(old.r, std::max(old.g, old.b)));
    if (f.count[t] > 0) {
      const glm::vec3 mean = f.sum[t] / f.count[t];
      peak = std::max(peak, std::max(mean.r, std::max(mean.g, mean.b)));
      if (st.sampled[t] > 0) {
        old_group[t % kChangeGroups] += luminance(old);
        new_group[t % kChangeGroups] += luminance(mean);
      }
    }
  }
  double old_sum = 0;
  std::array<double, kChangeGroups> group_rel{};
  int groups = 0;
  for (int g = 0; g < kChangeGroups; ++g) {
    old_sum += old_group[g];
    if (old_group[g] > 0) group_rel[groups++] = (new_group[g] - old_group[g]) / std::max(old_group[g], 1e-6);
  }
  bool changed = false, drifting = false;
  // The noise is only measured once the cold start is over: the warm-up's
  // large frame-to-frame changes are convergence, not noise, and counting
  // them would hide real lighting changes for hundreds of frames.
  if (old_sum > 0 && st.frames >= s.warmup_frames) {
    for (int i = 1; i < groups; ++i)  // insertion sort of at most 8
      for (int j = i; j > 0 && group_rel[j - 1] > group_rel[j]; --j) std::swap(group_rel[j - 1], group_rel[j]);
    const double rel = groups % 2 ? group_rel[groups / 2] : 0.5 * (group_rel[groups / 2 - 1] + group_rel[groups / 2]);
    const bool noise_known = st.noise_frames >= 8;
    changed = noise_known && std::abs(rel) > s.change_threshold && rel * rel > s.change_sigmas * s.change_sigmas * st.noise_variance;
    if (!changed) {
      // Running mean of rel^2 under steady lighting (changes are excluded).
      const double w = st.noise_frames < 8 ? 1.0 / (st.noise_frames + 1) : 0.05;
      st.noise_variance = static_cast<float>((1 - w) * st.noise_variance + w * rel * rel);
      ++st.noise_frames;
    }
    // A history still converging (after a change too small to detect, or the
    // tail of a fast blend) moves the same way frame after frame; noise does
    // not. The drift is an exponential mean of the signed change, compared
    // with its own noise (an EMA of weight 0.1 keeps 0.1 / 1.9 of the variance).
    st.drift = static_cast<float>(0.9 * st.drift + 0.1 * rel);
    drifting = std::abs(st.drift) > std::max(0.5 * s.change_threshold, 3.0 * std::sqrt(st.noise_variance * 0.1 / 1.9));
  }
  float h = changed ? s.fast_hysteresis : s.hysteresis;
  if (st.frames < s.warmup_frames) {
    const float t = static_cast<float>(st.frames) / static_cast<float>(s.warmup_frames);
    h = std::min(h, s.fast_hysteresis + (s.hysteresis - s.fast_hysteresis) * t);
  }
  st.stable_frames = (changed || drifting || st.frames < s.warmup_frames) ? 0 : st.stable_frames + 1;
  ++st.frames;
  next = history;
  for (std::size_t t = 0; t < next.size(); ++t) {
    if (f.count[t] <= 0) {
      // Nothing new: keep the history, unless the lighting just changed, in
      // which case the history is wrong and the texel is refilled from
      // fresh neighbours until it is sampled again.
      if (changed) st.sampled[t] = 0;
      continue;
    }
    const glm::vec3 mean = f.sum[t] / f.count[t];
    if (st.sampled[t] == 0) {
      next[t] = mean;
      st.sampled[t] = 1;
      continue;
    }
    next[t] = h * history[t] + (1.0f - h) * mean;
  }
  // A new scale (a power of two: the old texels convert exactly) rewrites
  // every texel, so the ulp step is judged at the next frame.
  const float old_scale = st.radiance_scale;
  st.radiance_scale = fitted_scale(old_scale, peak);
  store_history(st, next, st.radiance_scale == old_scale ? &history : nullptr);
  return changed;
}

void update_own_depths(std::span<const int> batch, std::span<ProbeMapState* const> states,
                       const std::vector<std::vector<ShadedPoint>>& points, const MapLayout& layout,
                       const AccumulationSettings& settings) {
  engine::jobs::parallel_for(0, static_cast<int>(batch.size()), 8, [&](int b, int e) {
    for (int i = b; i < e; ++i) {
      const auto k = static_cast<std::size_t>(i);
      update_own_depth(*states[k], layout, points[static_cast<std::size_t>(batch[k])], settings);
    }
  });
}

float own_depth_blend(const ProbeMapState& st, const AccumulationSettings& s) {
  // Like the radiance, the depth starts (and restarts after the geometry
  // moved) with a fast blend, so visibility follows a moved wall in a few
  // frames rather than ~20 per texel hit.
  const float ramp = std::min(1.0f, static_cast<float>(st.depth_frames) / static_cast<float>(std::max(1, s.warmup_frames)));
  return std::min(s.hysteresis, s.fast_hysteresis + (s.hysteresis - s.fast_hysteresis) * ramp);
}

void update_own_depth(ProbeMapState& st, const MapLayout& layout, const std::vector<ShadedPoint>& own,
                      const AccumulationSettings& s) {
  // shaders/probe_own_depth.comp is the device's twin, bit for bit.
  const float h = own_depth_blend(st, s);
  ++st.depth_frames;
  for (const ShadedPoint& p : own) {
    if (!std::isfinite(p.distance)) continue;
    const auto t = static_cast<std::size_t>(layout.texel_of(p.direction));
    const float mean = st.depth.mean(t);
    if (std::isnan(mean)) {  // the texel's first own hit (distances are finite)
      st.depth.set(t, p.distance, 0.0f);
    } else {
      // The exponential mean of the distance and of its square, written as
      // mean and variance: var' = h var + h (1 - h) (d - mean)^2 is exactly
      // M2' - mean'^2 for M2' = h M2 + (1 - h) d^2.
      const float d = p.distance - mean;
      st.depth.set(t, mean + (1 - h) * d, h * st.depth.variance(t) + h * (1 - h) * d * d);
    }
  }
  st.depth.stamp_version();
}

std::vector<glm::vec3> filled_radiance(const ProbeMapState& st, const MapLayout& layout, int passes) {
  std::vector<glm::vec3> r;
  load_history(st, r);
  std::vector<std::uint8_t> known = st.sampled;
  const int w = layout.width, h = layout.height;
  // Each pass fills the holes next to known texels from the state before the
  // pass (a Jacobi step): fills are collected, then applied, so only the
  // holes are touched instead of copying both maps every pass.
  std::vector<std::pair<std::size_t, glm::vec3>> fills;
  for (int pass = 0; pass < passes; ++pass) {
    fills.clear();
    bool any_missing = false;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const std::size_t t = static_cast<std::size_t>(y * w + x);
        if (known[t] > 0) continue;
        glm::vec3 sum(0.0f);
        int n = 0;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const int yy = y + dy;
            if (yy < 0 || yy >= h) continue;
            const int xx = (x + dx + w) % w;  // u wraps around
            const std::size_t q = static_cast<std::size_t>(yy * w + xx);
            if (known[q] > 0) {
              sum += r[q];
              ++n;
            }
          }
        if (n > 0)
          fills.emplace_back(t, sum / static_cast<float>(n));
        else
          any_missing = true;
      }
    for (const auto& [t, value] : fills) {
      r[t] = value;
      known[t] = 1;
    }
    if (!any_missing) return r;
  }
  // What dilation could not reach gets the mean of everything known.
  glm::dvec3 sum(0.0);
  double wsum = 0;
  for (int t = 0; t < layout.texel_count(); ++t)
    if (known[static_cast<std::size_t>(t)] > 0) {
      sum += glm::dvec3(r[static_cast<std::size_t>(t)]) * layout.solid_angle(t);
      wsum += layout.solid_angle(t);
    }
  const glm::vec3 mean = wsum > 0 ? glm::vec3(sum / wsum) : glm::vec3(0.0f);
  for (std::size_t t = 0; t < r.size(); ++t)
    if (known[t] <= 0) r[t] = mean;
  return r;
}

}  // namespace transgi::probes
