// Probe interpolation with pruning (the GPU twin of
// probes::interpolate_probes, paper Section 5.3): the 8 probes of a point's
// cage with trilinear weights, minus back-facing probes, each weighed by a
// ramp on its Chebyshev visibility bound (on its own hit-distance moments
// toward the point, read bilinearly); a distance-and-cosine average when all
// are pruned. The includer declares `depth` (probes x texels, half2(mean,
// variance)) and `probes` (ProbeGpu) buffers; a field's probes start at
// probe_base and its depth texels at depth_base in them, so one kernel can
// read several fields.
#include "map_texel.glsl"
#include "probe_grid.glsl"

float chebyshev_visibility(float mean, float variance_in, float distance) {
  if (isnan(mean) || isinf(mean) || distance <= mean) return 1.0;
  const float variance = max(variance_in, 1e-6 * mean * mean + 1e-8);
  const float d = distance - mean;
  return variance / (variance + d * d);
}

// probes::visibility_weight.
float visibility_weight(float visibility, float threshold, float ramp) {
  if (!(ramp > 0.0)) return visibility < threshold ? 0.0 : 1.0;
  return clamp((visibility - threshold) / ramp, 0.0, 1.0);
}

// probes::filtered_visibility for the probe whose depth texels start at
// `first` (depth in units of `unit`): the moments of the four texel centres
// around `at`, bilinearly, leaving out texels never hit (1 if all are).
float filtered_visibility(uint first, vec2 at, uint width, uint height, float unit, float distance) {
  const float px = at.x - 0.5;
  const float py = clamp(at.y - 0.5, 0.0, float(height - 1u));
  const float fx = floor(px);
  const int y0 = min(int(py), int(height) - 1), y1 = min(y0 + 1, int(height) - 1);
  int x0 = int(fx) % int(width);
  if (x0 < 0) x0 += int(width);
  const int x1 = x0 + 1 == int(width) ? 0 : x0 + 1;
  const float ax = px - fx, ay = py - float(y0);
  const int texel[4] = int[4](y0 * int(width) + x0, y0 * int(width) + x1, y1 * int(width) + x0, y1 * int(width) + x1);
  const float weight[4] = float[4]((1.0 - ax) * (1.0 - ay), ax * (1.0 - ay), (1.0 - ax) * ay, ax * ay);
  float m1 = 0.0, m2 = 0.0, sum = 0.0;
  for (int k = 0; k < 4; ++k) {
    const vec2 m = unpackHalf2x16(depth[first + uint(texel[k])]);
    if (isnan(m.x) || isinf(m.x) || !(weight[k] > 0.0)) continue;
    m1 += weight[k] * m.x;
    m2 += weight[k] * (m.y + m.x * m.x);
    sum += weight[k];
  }
  if (!(sum > 0.0)) return 1.0;
  m1 /= sum;
  m2 /= sum;
  return chebyshev_visibility(m1 * unit, max(m2 - m1 * m1, 0.0) * unit * unit, distance);
}

// Probe indices in the result are the field's own (add probe_base to read).
InterpolationGpu interpolate_probes_at(InterpolatePush p, uint probe_base, uint depth_base, vec3 x, vec3 n) {
  const ivec3 dims = grid_dims(p.grid);
  const vec3 lo = grid_min(p.grid), s = grid_spacing(p.grid);

  // ProbeGrid::cage: the cell, clamped to the grid.
  vec3 g = vec3(0.0);
  for (int a = 0; a < 3; ++a)
    if (dims[a] > 1 && s[a] > 0.0) g[a] = clamp((x[a] - lo[a]) / s[a], 0.0, float(dims[a] - 1));
  const ivec3 base = min(ivec3(floor(g)), max(dims - 2, ivec3(0)));
  const vec3 f = clamp(g - vec3(base), vec3(0.0), vec3(1.0));
  // probes::visibility_test_point.
  vec3 biased = x + n * p.bias_length;
  if (p.view_bias_length > 0.0) {
    const vec3 to_viewer = vec3(p.viewer_x, p.viewer_y, p.viewer_z) - x;
    const float d = length(to_viewer);
    if (d > 1e-6) biased += to_viewer * (p.view_bias_length / d);
  }

  InterpolationGpu r;
  float fallback[8];
  float sum = 0.0;
  uint pruned = 0u;
  for (int c = 0; c < 8; ++c) {
    const ivec3 o = ivec3(c & 1, (c >> 1) & 1, (c >> 2) & 1);
    const ivec3 q = min(base + o, dims - 1);
    const int at = grid_index(p.grid, q);
    const float w = (o.x != 0 ? f.x : 1.0 - f.x) * (o.y != 0 ? f.y : 1.0 - f.y) * (o.z != 0 ? f.z : 1.0 - f.z);
    const ProbeGpu probe = probes[probe_base + uint(at)];
    vec3 pos = lo + vec3(q) * s;
    if ((p.flags & kInterpolateHasOffsets) != 0u) pos += vec3(probe.offset_x, probe.offset_y, probe.offset_z);

    const vec3 to_probe = pos - x;
    const float dist = length(to_probe);
    const float facing = dist > 1e-6 ? dot(to_probe / dist, n) : 1.0;
    const vec3 from_probe = biased - pos;
    const float from_dist = length(from_probe);
    const bool occlusion = (p.flags & kInterpolatePruneOccluded) != 0u;
    const bool tested = occlusion && from_dist > 1e-6;

    const bool holds_light = probe.usable != 0u;
    fallback[c] = holds_light ? max(0.05, 0.5 * (facing + 1.0)) / (dist * dist + 1e-4) : 0.0;
    bool keep = w > 0.0 && holds_light;
    if (keep && (p.flags & kInterpolatePruneBackFacing) != 0u && facing < 0.0) keep = false;
    float seen = 1.0;
    if (keep && tested) {
      const float visibility =
          filtered_visibility(depth_base + uint(at) * p.texels, map_texel_position(from_probe / from_dist, p.map_width, p.map_height),
                              p.map_width, p.map_height, probe.depth_unit, from_dist);
      seen = visibility_weight(visibility, p.visibility_threshold, p.visibility_ramp);
      if (seen <= 0.0) keep = false;
    }
    if (!keep && w > 0.0) ++pruned;
    r.probes[c] = at;
    r.weights[c] = keep ? w * seen : 0.0;
    sum += r.weights[c];
  }
  r.pruned = pruned;
  r.fallback = 0u;
  if (sum > 1e-6) {
    for (int c = 0; c < 8; ++c) r.weights[c] /= sum;
  } else {
    r.fallback = 1u;
    float fsum = 0.0;
    for (int c = 0; c < 8; ++c) fsum += fallback[c];
    for (int c = 0; c < 8; ++c) r.weights[c] = fsum > 0.0 ? fallback[c] / fsum : 0.0;
  }
  r.pad0 = 0u;
  r.pad1 = 0u;
  return r;
}
