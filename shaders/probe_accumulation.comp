#version 460
// TransGI's accumulation for a batch of probes, one workgroup each
// (probes::accumulate, then probes::filled_radiance): this frame's samples
// blended into the binary16 history with the adaptive hysteresis (a change
// of light detected from the median of eight interleaved texel groups
// against the probe's own noise), the history's power-of-two scale refitted,
// then the never-sampled texels filled from sampled neighbours (Jacobi
// passes) and the map's solid-angle-weighted mean, ready for the SH
// projection. The CPU sums the change groups in double, this in float, so a
// change within rounding of its threshold can be judged otherwise.
#extension GL_GOOGLE_include_directive : require
#include "probe_accumulation_shared.h"

layout(local_size_x = kAccumulateGroupSize) in;
layout(std430, set = 0, binding = 0) buffer States { ProbeAccumulationGpu states[]; };
layout(std430, set = 0, binding = 1) buffer History { uint history[]; };  // per texel: r | g << 16, then b
layout(std430, set = 0, binding = 2) buffer Sampled { uint sampled[]; };  // per texel: 1 once sampled
layout(std430, set = 0, binding = 3) readonly buffer Frame { vec4 frame[]; };  // per texel: this frame's sum (rgb) and count
layout(std430, set = 0, binding = 4) writeonly buffer Filled { float filled[]; };  // per texel: rgb to project
layout(std430, set = 0, binding = 5) readonly buffer SolidAngle { float solid_angle[]; };  // per texel of the layout
layout(std430, set = 0, binding = 6) buffer KnownPass { uint known_pass[]; };  // scratch: the fill pass a texel became known in
// Per probe of the batch: which map of Frame holds its samples (the raster
// writes one map per probe of the grid, the batch is the updated ones).
layout(std430, set = 0, binding = 7) readonly buffer FrameProbe { uint frame_probe[]; };
// Per probe of the batch: which map of History and Sampled is its own (its
// slot in a field's resident maps, or its place in the batch).
layout(std430, set = 0, binding = 8) readonly buffer MapSlot { uint map_slot[]; };
layout(push_constant) uniform PushBlock { AccumulatePush p; };

#include "half_bits.glsl"

const uint kUnknown = 0xffffffffu;

shared float s_peak[kAccumulateGroupSize];
shared float s_old[kAccumulateGroupSize * kAccumulateChangeGroups];
shared float s_new[kAccumulateGroupSize * kAccumulateChangeGroups];
shared vec4 s_mean[kAccumulateGroupSize];
shared float s_h, s_old_scale, s_new_scale;
shared uint s_changed, s_missing;

float luminance(vec3 c) { return 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b; }
float max3(vec3 v) { return max(v.r, max(v.g, v.b)); }

vec3 history_at(uint at, float scale) {
  const uint rg = history[2u * at], b = history[2u * at + 1u];
  return vec3(from_half_bits(rg), from_half_bits(rg >> 16), from_half_bits(b)) * scale;
}

// probes::fitted_scale.
float fitted_scale(float scale, float peak) {
  if (!(peak > 0.0) || isinf(peak) || isnan(peak)) return scale;
  const float stored = peak / scale;
  if (stored <= 16384.0 && stored >= 0.25) return scale;
  int e;
  frexp(peak, e);  // peak = m 2^e, m in [0.5, 1): ilogb(peak) = e - 1
  return ldexp(1.0, e - 12);
}

// The lighting-change decision and the probe's scalar state (lane 0).
void decide(uint q) {
  ProbeAccumulationGpu st = states[q];
  float peak = 0.0;
  float old_group[kAccumulateChangeGroups], new_group[kAccumulateChangeGroups];
  for (uint g = 0u; g < kAccumulateChangeGroups; ++g) old_group[g] = new_group[g] = 0.0;
  for (uint l = 0u; l < kAccumulateGroupSize; ++l) {
    peak = max(peak, s_peak[l]);
    for (uint g = 0u; g < kAccumulateChangeGroups; ++g) {
      old_group[g] += s_old[l * kAccumulateChangeGroups + g];
      new_group[g] += s_new[l * kAccumulateChangeGroups + g];
    }
  }
  float old_sum = 0.0;
  float rel[kAccumulateChangeGroups];
  int groups = 0;
  for (uint g = 0u; g < kAccumulateChangeGroups; ++g) {
    old_sum += old_group[g];
    if (old_group[g] > 0.0) rel[groups++] = (new_group[g] - old_group[g]) / max(old_group[g], 1e-6);
  }
  bool changed = false, drifting = false;
  if (old_sum > 0.0 && st.frames >= p.warmup_frames) {
    for (int i = 1; i < groups; ++i)
      for (int j = i; j > 0 && rel[j - 1] > rel[j]; --j) {
        const float t = rel[j - 1];
        rel[j - 1] = rel[j];
        rel[j] = t;
      }
    const float r = (groups % 2) != 0 ? rel[groups / 2] : 0.5 * (rel[groups / 2 - 1] + rel[groups / 2]);
    const bool noise_known = st.noise_frames >= 8;
    changed = noise_known && abs(r) > p.change_threshold && r * r > p.change_sigmas * p.change_sigmas * st.noise_variance;
    if (!changed) {
      const float w = st.noise_frames < 8 ? 1.0 / float(st.noise_frames + 1) : 0.05;
      st.noise_variance = (1.0 - w) * st.noise_variance + w * r * r;
      ++st.noise_frames;
    }
    st.drift = 0.9 * st.drift + 0.1 * r;
    drifting = abs(st.drift) > max(0.5 * p.change_threshold, 3.0 * sqrt(st.noise_variance * 0.1 / 1.9));
  }
  float h = changed ? p.fast_hysteresis : p.hysteresis;
  if (st.frames < p.warmup_frames) {
    const float t = float(st.frames) / float(p.warmup_frames);
    h = min(h, p.fast_hysteresis + (p.hysteresis - p.fast_hysteresis) * t);
  }
  st.stable_frames = (changed || drifting || st.frames < p.warmup_frames) ? 0 : st.stable_frames + 1;
  ++st.frames;
  s_old_scale = st.radiance_scale;
  s_new_scale = fitted_scale(st.radiance_scale, peak);
  st.radiance_scale = s_new_scale;
  st.changed = changed ? 1u : 0u;
  states[q] = st;
  s_h = h;
  s_changed = st.changed;
}

// store_history's rounding: a blend step under half an ulp moves one ulp.
uint stored_bits(float target, float before, uint was, bool same_scale) {
  const uint now = to_half_bits(target);
  if (same_scale && now == was && target != before)
    return target > before ? min(now + 1u, 0x7bffu) : (now > 0u ? now - 1u : 0u);
  return now;
}

void main() {
  const uint q = gl_WorkGroupID.x, lane = gl_LocalInvocationID.x;
  if (q >= p.probes) return;
  // base: this batch's scratch (Filled, KnownPass); map_base: the maps.
  const uint base = q * p.texels, map_base = map_slot[q] * p.texels, frame_base = frame_probe[q] * p.texels;

  // 1. The peak and the change groups over this frame's sampled texels.
  {
    const float scale = states[q].radiance_scale;
    float peak = 0.0;
    float og[kAccumulateChangeGroups], ng[kAccumulateChangeGroups];
    for (uint g = 0u; g < kAccumulateChangeGroups; ++g) og[g] = ng[g] = 0.0;
    for (uint t = lane; t < p.texels; t += kAccumulateGroupSize) {
      const vec3 old = history_at(map_base + t, scale);
      peak = max(peak, max3(old));
      const vec4 f = frame[frame_base + t];
      if (f.w > 0.0) {
        const vec3 mean = f.rgb / f.w;
        peak = max(peak, max3(mean));
        if (sampled[map_base + t] > 0u) {
          og[t % kAccumulateChangeGroups] += luminance(old);
          ng[t % kAccumulateChangeGroups] += luminance(mean);
        }
      }
    }
    s_peak[lane] = peak;
    for (uint g = 0u; g < kAccumulateChangeGroups; ++g) {
      s_old[lane * kAccumulateChangeGroups + g] = og[g];
      s_new[lane * kAccumulateChangeGroups + g] = ng[g];
    }
  }
  barrier();
  if (lane == 0u) decide(q);
  barrier();

  // 2. The blend, stored as binary16 at the (refitted) scale.
  const float h = s_h, old_scale = s_old_scale, new_scale = s_new_scale, inv = 1.0 / new_scale;
  const bool changed = s_changed != 0u, same_scale = new_scale == old_scale;
  for (uint t = lane; t < p.texels; t += kAccumulateGroupSize) {
    const uint at = map_base + t, out_at = base + t;
    const uint rg = history[2u * at], b = history[2u * at + 1u];
    const vec3 old = vec3(from_half_bits(rg), from_half_bits(rg >> 16), from_half_bits(b)) * old_scale;
    vec3 next = old;
    uint was_sampled = sampled[at];
    const vec4 f = frame[frame_base + t];
    if (f.w <= 0.0) {
      if (changed) was_sampled = 0u;
    } else {
      const vec3 mean = f.rgb / f.w;
      if (was_sampled == 0u) {
        next = mean;
        was_sampled = 1u;
      } else {
        next = h * old + (1.0 - h) * mean;
      }
    }
    const vec3 target = clamp(next * inv, vec3(0.0), vec3(65504.0));
    const vec3 before = old * inv;
    const uint r_bits = stored_bits(target.r, before.r, rg & 0xffffu, same_scale);
    const uint g_bits = stored_bits(target.g, before.g, rg >> 16, same_scale);
    const uint b_bits = stored_bits(target.b, before.b, b & 0xffffu, same_scale);
    history[2u * at] = r_bits | (g_bits << 16);
    history[2u * at + 1u] = b_bits;
    sampled[at] = was_sampled;
    const vec3 stored = vec3(from_half_bits(r_bits), from_half_bits(g_bits), from_half_bits(b_bits)) * new_scale;
    filled[3u * out_at] = stored.r;
    filled[3u * out_at + 1u] = stored.g;
    filled[3u * out_at + 2u] = stored.b;
    known_pass[out_at] = was_sampled > 0u ? 0u : kUnknown;
  }
  memoryBarrierBuffer();
  barrier();

  // 3. Holes filled from the texels known before each pass (u wraps around).
  const int w = int(p.width), hgt = int(p.height);
  bool missing = true;
  for (int pass = 0; pass < p.fill_passes && missing; ++pass) {
    if (lane == 0u) s_missing = 0u;
    barrier();
    for (uint t = lane; t < p.texels; t += kAccumulateGroupSize) {
      if (known_pass[base + t] != kUnknown) continue;
      const int x = int(t) % w, y = int(t) / w;
      vec3 sum = vec3(0.0);
      int n = 0;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int yy = y + dy;
          if (yy < 0 || yy >= hgt) continue;
          const int xx = (x + dx + w) % w;
          const uint nb = base + uint(yy * w + xx);
          if (known_pass[nb] <= uint(pass)) {
            sum += vec3(filled[3u * nb], filled[3u * nb + 1u], filled[3u * nb + 2u]);
            ++n;
          }
        }
      if (n > 0) {
        const vec3 v = sum / float(n);
        filled[3u * (base + t)] = v.r;
        filled[3u * (base + t) + 1u] = v.g;
        filled[3u * (base + t) + 2u] = v.b;
        known_pass[base + t] = uint(pass) + 1u;
      } else {
        atomicOr(s_missing, 1u);
      }
    }
    memoryBarrierBuffer();
    barrier();
    missing = s_missing != 0u;
    barrier();
  }
  if (!missing) return;

  // 4. What the dilation did not reach: the solid-angle-weighted mean of the known texels.
  vec4 acc = vec4(0.0);
  for (uint t = lane; t < p.texels; t += kAccumulateGroupSize)
    if (known_pass[base + t] != kUnknown) {
      const float a = solid_angle[t];
      acc += vec4(vec3(filled[3u * (base + t)], filled[3u * (base + t) + 1u], filled[3u * (base + t) + 2u]) * a, a);
    }
  s_mean[lane] = acc;
  barrier();
  vec4 total = vec4(0.0);
  for (uint l = 0u; l < kAccumulateGroupSize; ++l) total += s_mean[l];
  const vec3 mean = total.w > 0.0 ? total.rgb / total.w : vec3(0.0);
  for (uint t = lane; t < p.texels; t += kAccumulateGroupSize)
    if (known_pass[base + t] == kUnknown) {
      filled[3u * (base + t)] = mean.r;
      filled[3u * (base + t) + 1u] = mean.g;
      filled[3u * (base + t) + 2u] = mean.b;
    }
}
