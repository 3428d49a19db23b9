#include "probes/interpolation.h"

#include <algorithm>
#include <cmath>

#include "engine/core/cpu_isa.h"

namespace transgi::probes {

float chebyshev_visibility(float mean, float variance_in, float distance) {
  if (!std::isfinite(mean) || distance <= mean) return 1.0f;
  const float variance = std::max(variance_in, 1e-6f * mean * mean + 1e-8f);
  const float d = distance - mean;
  return variance / (variance + d * d);
}

namespace {

// What the weights need from each corner of the cage.
struct Corners {
  std::array<float, 8> facing{};     // cosine between the normal and the direction to the probe
  std::array<float, 8> dist{};       // point to probe
  std::array<float, 8> from_dist{};  // probe to the biased point
  std::array<int, 8> texel{};        // the probe's depth texel towards the biased point; -1 = none
};

// The plain statement: one corner at a time through MapLayout::texel_of.
Corners corners_reference(const ProbeGrid::Cage& cage, const MapLayout& layout, const glm::vec3& p, const glm::vec3& n,
                          const glm::vec3& biased, bool occlusion) {
  Corners c;
  for (std::size_t i = 0; i < 8; ++i) {
    const glm::vec3 to_probe = cage.positions[i] - p;
    c.dist[i] = glm::length(to_probe);
    c.facing[i] = c.dist[i] > 1e-6f ? glm::dot(to_probe / c.dist[i], n) : 1.0f;  // dir = n when the point is at the probe
    const glm::vec3 from_probe = biased - cage.positions[i];
    c.from_dist[i] = glm::length(from_probe);
    c.texel[i] = occlusion && c.from_dist[i] > 1e-6f ? layout.texel_of(from_probe / c.from_dist[i]) : -1;
  }
  return c;
}

// The same arithmetic in the same order, as structure-of-arrays loops over the
// eight corners that the compiler turns into 8-lane vectors (this file is
// built without FMA contraction, so every lane rounds as the reference does:
// the results are bit-identical, tested).
ENGINE_INLINE_BODY Corners corners_body(
    const ProbeGrid::Cage& cage, const MapLayout& layout, const glm::vec3& p, const glm::vec3& n, const glm::vec3& biased,
    bool occlusion) {
  Corners c;
  float px[8], py[8], pz[8];
  for (int i = 0; i < 8; ++i) {
    px[i] = cage.positions[static_cast<std::size_t>(i)].x;
    py[i] = cage.positions[static_cast<std::size_t>(i)].y;
    pz[i] = cage.positions[static_cast<std::size_t>(i)].z;
  }
  const float w = static_cast<float>(layout.width), h = static_cast<float>(layout.height);
  for (int i = 0; i < 8; ++i) {
    const float tx = px[i] - p.x, ty = py[i] - p.y, tz = pz[i] - p.z;
    const float dist = std::sqrt(tx * tx + ty * ty + tz * tz);
    const float facing = (tx / dist) * n.x + (ty / dist) * n.y + (tz / dist) * n.z;
    c.dist[static_cast<std::size_t>(i)] = dist;
    c.facing[static_cast<std::size_t>(i)] = dist > 1e-6f ? facing : 1.0f;
    const float fx = biased.x - px[i], fy = biased.y - py[i], fz = biased.z - pz[i];
    const float from = std::sqrt(fx * fx + fy * fy + fz * fz);
    c.from_dist[static_cast<std::size_t>(i)] = from;
    const float unit = from > 1e-6f ? from : 1.0f;  // keeps unused lanes finite
    const float dx = fx / unit, dy = fy / unit, dz = fz / unit;
    const float u = fast_atan2(dx, -dz) * 0.15915494f, v = fast_acos(dy) * 0.31830989f;
    const float uw = u < 0 ? u + 1.0f : u;
    const int x = std::min(layout.width - 1, std::max(0, static_cast<int>(uw * w)));
    const int y = std::min(layout.height - 1, std::max(0, static_cast<int>(v * h)));
    c.texel[static_cast<std::size_t>(i)] = occlusion && from > 1e-6f ? y * layout.width + x : -1;
  }
  return c;
}
ENGINE_ISA_DISPATCH(Corners, corners, (const ProbeGrid::Cage& cage, const MapLayout& layout, const glm::vec3& p, const glm::vec3& n,
                   const glm::vec3& biased, bool occlusion),
                   (cage, layout, p, n, biased, occlusion))

InterpolationResult weigh(const ProbeGrid::Cage& cage, const Corners& c, const std::vector<ProbeMapState>& states,
                          const InterpolationSettings& s, std::span<const std::uint8_t> usable);

}  // namespace

InterpolationResult interpolate_probes(const ProbeGrid& grid, const MapLayout& layout,
                                       const std::vector<ProbeMapState>& states, const glm::vec3& p, const glm::vec3& n,
                                       const InterpolationSettings& s, std::span<const std::uint8_t> usable) {
  const ProbeGrid::Cage cage = grid.cage(p);
  const glm::vec3 biased = p + n * (s.normal_bias * grid.min_spacing());
  return weigh(cage, corners(cage, layout, p, n, biased, s.prune_occluded), states, s, usable);
}

void interpolate_probes_many(const ProbeGrid& grid, const MapLayout& layout, const std::vector<ProbeMapState>& states,
                             std::span<const glm::vec3> position, std::span<const glm::vec3> normal,
                             const InterpolationSettings& s, std::span<const std::uint8_t> usable,
                             std::span<InterpolationResult> out) {
  constexpr std::size_t kBatch = 16;
  std::array<ProbeGrid::Cage, kBatch> cages;
  std::array<Corners, kBatch> corner;
  for (std::size_t b = 0; b < position.size(); b += kBatch) {
    const std::size_t n = std::min(kBatch, position.size() - b);
    for (std::size_t j = 0; j < n; ++j) {
      const glm::vec3& p = position[b + j];
      const glm::vec3& nrm = normal[b + j];
      cages[j] = grid.cage(p);
      corner[j] = corners(cages[j], layout, p, nrm, p + nrm * (s.normal_bias * grid.min_spacing()), s.prune_occluded);
      for (std::size_t i = 0; i < 8; ++i)
        if (corner[j].texel[i] >= 0)
          __builtin_prefetch(states[static_cast<std::size_t>(cages[j].probes[i])].depth.texels.data() + corner[j].texel[i]);
    }
    for (std::size_t j = 0; j < n; ++j) out[b + j] = weigh(cages[j], corner[j], states, s, usable);
  }
}

InterpolationResult interpolate_probes_reference(const ProbeGrid& grid, const MapLayout& layout,
                                                 const std::vector<ProbeMapState>& states, const glm::vec3& p,
                                                 const glm::vec3& n, const InterpolationSettings& s,
                                                 std::span<const std::uint8_t> usable) {
  const ProbeGrid::Cage cage = grid.cage(p);
  const glm::vec3 biased = p + n * (s.normal_bias * grid.min_spacing());
  return weigh(cage, corners_reference(cage, layout, p, n, biased, s.prune_occluded), states, s, usable);
}

namespace {

InterpolationResult weigh(const ProbeGrid::Cage& cage, const Corners& c, const std::vector<ProbeMapState>& states,
                          const InterpolationSettings& s, std::span<const std::uint8_t> usable) {
  InterpolationResult r;
  r.probes = cage.probes;
  // The eight depth reads (often cache misses) are issued together, after
  // the geometry, so they overlap.
  std::array<DepthMap::Texel, 8> depth{};
  for (std::size_t i = 0; i < 8; ++i)
    if (c.texel[i] >= 0 && (usable.empty() || usable[static_cast<std::size_t>(cage.probes[i])]))  // unusable: maps released
      depth[i] = states[static_cast<std::size_t>(cage.probes[i])].depth.texels[static_cast<std::size_t>(c.texel[i])];
  const auto& facing = c.facing;
  const auto& dist = c.dist;
  const auto& from_dist = c.from_dist;
  float sum = 0;
  std::array<float, 8> fallback{};
  for (std::size_t i = 0; i < 8; ++i) {
    const int q = cage.probes[i];
    // Fallback weight: nearer and more in front of the surface counts more.
    const bool holds_light = usable.empty() || usable[static_cast<std::size_t>(q)] != 0;
    fallback[i] = holds_light ? std::max(0.05f, 0.5f * (facing[i] + 1.0f)) / (dist[i] * dist[i] + 1e-4f) : 0.0f;
    bool keep = cage.weights[i] > 0 && holds_light;
    if (keep && s.prune_back_facing && facing[i] < 0) keep = false;
    if (keep && s.prune_occluded && c.texel[i] >= 0) {
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

}  // namespace

}  // namespace transgi::probes
