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
  float sum = 0;
  std::array<float, 8> fallback{};
  for (std::size_t i = 0; i < 8; ++i) {
    const int q = cage.probes[i];
    const glm::vec3 to_probe = grid.position(q) - p;
    const float dist = glm::length(to_probe);
    const glm::vec3 dir = dist > 1e-6f ? to_probe / dist : n;
    // Fallback weight: nearer and more in front of the surface counts more.
    const bool holds_light = usable.empty() || usable[static_cast<std::size_t>(q)] != 0;
    fallback[i] = holds_light ? std::max(0.05f, 0.5f * (glm::dot(dir, n) + 1.0f)) / (dist * dist + 1e-4f) : 0.0f;
    bool keep = cage.weights[i] > 0 && holds_light;
    if (keep && s.prune_back_facing && glm::dot(dir, n) < 0) keep = false;
    if (keep && s.prune_occluded) {
      const glm::vec3 from_probe = biased - grid.position(q);
      const float d = glm::length(from_probe);
      if (d > 1e-6f) {
        const auto t = static_cast<std::size_t>(layout.texel_of(from_probe / d));
        const ProbeMapState& st = states[static_cast<std::size_t>(q)];
        if (chebyshev_visibility(st.depth.mean(t), st.depth.variance(t), d) < s.visibility_threshold) keep = false;
      }
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
