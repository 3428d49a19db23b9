#include "probes/interpolation.h"

#include <algorithm>
#include <cmath>

namespace transgi::probes {

float chebyshev_visibility(float mean, float variance_in, float distance) {
  if (!std::isfinite(mean) || distance <= mean) return 1.0f;
  const float variance = std::max(variance_in, 1e-6f * mean * mean + 1e-8f);
  const float d = distance - mean;
  return variance / (variance + d * d);
}

InterpolationResult interpolate_probes(const ProbeGrid& grid, const MapLayout& layout,
                                       const std::vector<ProbeMapState>& states, const glm::vec3& p, const glm::vec3& n,
                                       const InterpolationSettings& s, std::span<const std::uint8_t> usable) {
  const ProbeGrid::Cage cage = grid.cage(p);
  InterpolationResult r;
  r.probes = cage.probes;
  const float bias = s.normal_bias * grid.min_spacing();
  const glm::vec3 biased = p + n * bias;
  // Two passes: first every probe's geometry and its depth texel's address,
  // then the loads together, so the eight (often cache-missing) depth reads
  // overlap instead of waiting one after another behind each probe's math.
  std::array<float, 8> facing{}, dist{}, from_dist{};
  std::array<const DepthMap::Texel*, 8> texel{};
  for (std::size_t i = 0; i < 8; ++i) {
    const int q = cage.probes[i];
    const glm::vec3& at = cage.positions[i];
    const glm::vec3 to_probe = at - p;
    dist[i] = glm::length(to_probe);
    facing[i] = dist[i] > 1e-6f ? glm::dot(to_probe / dist[i], n) : 1.0f;  // dir = n when the point is at the probe
    const glm::vec3 from_probe = biased - at;
    from_dist[i] = glm::length(from_probe);
    texel[i] = s.prune_occluded && from_dist[i] > 1e-6f ? &states[static_cast<std::size_t>(q)].depth.texels[static_cast<std::size_t>(layout.texel_of(from_probe / from_dist[i]))]
                                    : nullptr;
  }
  std::array<DepthMap::Texel, 8> depth{};
  for (std::size_t i = 0; i < 8; ++i)
    if (texel[i]) depth[i] = *texel[i];
  float sum = 0;
  std::array<float, 8> fallback{};
  for (std::size_t i = 0; i < 8; ++i) {
    const int q = cage.probes[i];
    // Fallback weight: nearer and more in front of the surface counts more.
    const bool holds_light = usable.empty() || usable[static_cast<std::size_t>(q)] != 0;
    fallback[i] = holds_light ? std::max(0.05f, 0.5f * (facing[i] + 1.0f)) / (dist[i] * dist[i] + 1e-4f) : 0.0f;
    bool keep = cage.weights[i] > 0 && holds_light;
    if (keep && s.prune_back_facing && facing[i] < 0) keep = false;
    if (keep && s.prune_occluded && texel[i]) {
      const DepthMap& dm = states[static_cast<std::size_t>(q)].depth;
      const float mean = engine::math::from_half(depth[i].mean) * dm.unit;
      const float variance = engine::math::from_half(depth[i].variance) * dm.unit * dm.unit;
      if (chebyshev_visibility(mean, variance, from_dist[i]) < s.visibility_threshold) keep = false;
    }
    if (!keep && cage.weights[i] > 0) ++r.pruned;
    r.weights[i] = keep ? cage.weights[i] : 0.0f;
    sum += r.weights[i];
  }
  if (sum > 1e-6f) {
    for (float& w : r.weights) w /= sum;
    return r;
  }
  r.fallback = true;
  float fsum = 0;
  for (float w : fallback) fsum += w;
  for (std::size_t i = 0; i < 8; ++i) r.weights[i] = fsum > 0 ? fallback[i] / fsum : 0.0f;
  return r;
}

}  // namespace transgi::probes
