#include "probes/interpolation.h"

#include <algorithm>
#include <bit>
#include <cmath>

#include "engine/core/cpu_isa.h"

namespace transgi::probes {

float chebyshev_visibility(float mean, float variance_in, float distance) {
  if (!std::isfinite(mean) || distance <= mean) return 1.0f;
  const float variance = std::max(variance_in, 1e-6f * mean * mean + 1e-8f);
  const float d = distance - mean;
  return variance / (variance + d * d);
}

float visibility_weight(float visibility, const InterpolationSettings& s) {
  if (!(s.visibility_ramp > 0)) return visibility < s.visibility_threshold ? 0.0f : 1.0f;
  return std::clamp((visibility - s.visibility_threshold) / s.visibility_ramp, 0.0f, 1.0f);
}

namespace {
// The four texels around `at` and their bilinear weights (filtered_visibility).
struct Footprint {  // left uninitialised where weigh() does not test a corner
  std::array<int, 4> texel;
  std::array<float, 4> weight;
};
// A depth texel's two binary16 moments (DepthMap::Texel without its NaN
// initialiser: weigh() copies only the corners it tests).
struct TexelBits {
  std::uint16_t mean, variance;
};

Footprint footprint(const MapLayout& layout, glm::vec2 at) {
  const float px = at.x - 0.5f;
  const float py = std::clamp(at.y - 0.5f, 0.0f, static_cast<float>(layout.height - 1));
  const float fx = std::floor(px);
  const int y0 = std::min(static_cast<int>(py), layout.height - 1), y1 = std::min(y0 + 1, layout.height - 1);
  int x0 = static_cast<int>(fx) % layout.width;
  if (x0 < 0) x0 += layout.width;
  const int x1 = x0 + 1 == layout.width ? 0 : x0 + 1;
  const float ax = px - fx, ay = py - static_cast<float>(y0);
  Footprint f;
  f.texel = {y0 * layout.width + x0, y0 * layout.width + x1, y1 * layout.width + x0, y1 * layout.width + x1};
  f.weight = {(1 - ax) * (1 - ay), ax * (1 - ay), (1 - ax) * ay, ax * ay};
  return f;
}

// binary16 to float: one vcvtph2ps where the body is built for x86-64-v3 or
// v4, a library call in the scalar build; exact either way.
ENGINE_INLINE_BODY float half_to_float(std::uint16_t h) { return static_cast<float>(std::bit_cast<_Float16>(h)); }

ENGINE_INLINE_BODY float visibility_of(const std::array<TexelBits, 4>& texels, const Footprint& f, float unit,
                                       float distance) {
  float m1 = 0, m2 = 0, sum = 0;
  for (std::size_t k = 0; k < 4; ++k) {
    const float m = half_to_float(texels[k].mean);
    if (!std::isfinite(m) || !(f.weight[k] > 0)) continue;  // never hit
    m1 += f.weight[k] * m;
    m2 += f.weight[k] * (half_to_float(texels[k].variance) + m * m);
    sum += f.weight[k];
  }
  if (!(sum > 0)) return 1.0f;
  m1 /= sum;
  m2 /= sum;
  return chebyshev_visibility(m1 * unit, std::max(m2 - m1 * m1, 0.0f) * unit * unit, distance);
}
}  // namespace

float filtered_visibility(const DepthMap& depth, const MapLayout& layout, glm::vec2 at, float distance) {
  const Footprint f = footprint(layout, at);
  std::array<TexelBits, 4> texels;
  for (std::size_t k = 0; k < 4; ++k) {
    const DepthMap::Texel& t = depth.texels[static_cast<std::size_t>(f.texel[k])];
    texels[k] = {t.mean, t.variance};
  }
  return visibility_of(texels, f, depth.unit, distance);
}

namespace {

// What the weights need from each corner of the cage.
struct Corners {
  std::array<float, 8> facing{};     // cosine between the normal and the direction to the probe
  std::array<float, 8> dist{};       // point to probe
  std::array<float, 8> from_dist{};  // probe to the biased point
  std::array<int, 8> texel{};        // the probe's depth texel towards the biased point; -1 = none
  std::array<glm::vec2, 8> at{};     // where on its map (MapLayout::texel_position), where texel >= 0
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
    if (occlusion && c.from_dist[i] > 1e-6f) {
      c.at[i] = layout.texel_position(from_probe / c.from_dist[i]);
      c.texel[i] = layout.texel_of(from_probe / c.from_dist[i]);
    } else {
      c.texel[i] = -1;
    }
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
    c.at[static_cast<std::size_t>(i)] = glm::vec2(uw * w, v * h);
  }
  return c;
}
ENGINE_ISA_DISPATCH(Corners, corners, (const ProbeGrid::Cage& cage, const MapLayout& layout, const glm::vec3& p, const glm::vec3& n,
                   const glm::vec3& biased, bool occlusion),
                   (cage, layout, p, n, biased, occlusion))

InterpolationResult weigh(const ProbeGrid::Cage& cage, const Corners& c, const MapLayout& layout,
                          const std::vector<ProbeMapState>& states, const InterpolationSettings& s,
                          std::span<const std::uint8_t> usable);

}  // namespace

glm::vec3 visibility_test_point(const ProbeGrid& grid, const glm::vec3& p, const glm::vec3& n, const InterpolationSettings& s,
                                const glm::vec3* viewer) {
  glm::vec3 biased = p + n * (s.normal_bias * grid.min_spacing());
  if (viewer && s.view_bias > 0) {
    const glm::vec3 to_viewer = *viewer - p;
    const float d = glm::length(to_viewer);
    if (d > 1e-6f) biased += to_viewer * (s.view_bias * grid.min_spacing() / d);
  }
  return biased;
}

InterpolationResult interpolate_probes(const ProbeGrid& grid, const MapLayout& layout,
                                       const std::vector<ProbeMapState>& states, const glm::vec3& p, const glm::vec3& n,
                                       const InterpolationSettings& s, std::span<const std::uint8_t> usable,
                                       const glm::vec3* viewer) {
  const ProbeGrid::Cage cage = grid.cage(p);
  const glm::vec3 biased = visibility_test_point(grid, p, n, s, viewer);
  return weigh(cage, corners(cage, layout, p, n, biased, s.prune_occluded), layout, states, s, usable);
}

void interpolate_probes_many(const ProbeGrid& grid, const MapLayout& layout, const std::vector<ProbeMapState>& states,
                             std::span<const glm::vec3> position, std::span<const glm::vec3> normal,
                             const InterpolationSettings& s, std::span<const std::uint8_t> usable,
                             std::span<InterpolationResult> out, const glm::vec3* viewer) {
  constexpr std::size_t kBatch = 16;
  std::array<ProbeGrid::Cage, kBatch> cages;
  std::array<Corners, kBatch> corner;
  for (std::size_t b = 0; b < position.size(); b += kBatch) {
    const std::size_t n = std::min(kBatch, position.size() - b);
    for (std::size_t j = 0; j < n; ++j) {
      const glm::vec3& p = position[b + j];
      const glm::vec3& nrm = normal[b + j];
      cages[j] = grid.cage(p);
      corner[j] = corners(cages[j], layout, p, nrm, visibility_test_point(grid, p, nrm, s, viewer), s.prune_occluded);
      for (std::size_t i = 0; i < 8; ++i)
        if (corner[j].texel[i] >= 0 && cages[j].weights[i] > 0 && !(s.prune_back_facing && corner[j].facing[i] < 0)) {
          // The filtered read takes this texel's row and the next.
          const DepthMap::Texel* texels = states[static_cast<std::size_t>(cages[j].probes[i])].depth.texels.data();
          __builtin_prefetch(texels + corner[j].texel[i]);
          if (corner[j].texel[i] + layout.width < layout.texel_count()) __builtin_prefetch(texels + corner[j].texel[i] + layout.width);
        }
    }
    for (std::size_t j = 0; j < n; ++j) out[b + j] = weigh(cages[j], corner[j], layout, states, s, usable);
  }
}

InterpolationResult interpolate_probes_reference(const ProbeGrid& grid, const MapLayout& layout,
                                                 const std::vector<ProbeMapState>& states, const glm::vec3& p,
                                                 const glm::vec3& n, const InterpolationSettings& s,
                                                 std::span<const std::uint8_t> usable, const glm::vec3* viewer) {
  const ProbeGrid::Cage cage = grid.cage(p);
  const glm::vec3 biased = visibility_test_point(grid, p, n, s, viewer);
  return weigh(cage, corners_reference(cage, layout, p, n, biased, s.prune_occluded), layout, states, s, usable);
}

namespace {

ENGINE_INLINE_BODY InterpolationResult weigh_body(const ProbeGrid::Cage& cage, const Corners& c, const MapLayout& layout,
                                                  const std::vector<ProbeMapState>& states, const InterpolationSettings& s,
                                                  std::span<const std::uint8_t> usable) {
  InterpolationResult r;
  r.probes = cage.probes;
  const auto& facing = c.facing;
  const auto& dist = c.dist;
  const auto& from_dist = c.from_dist;
  // Which corners the geometry keeps; only theirs need the depth test.
  std::array<bool, 8> keep{};
  std::array<float, 8> fallback{};
  for (std::size_t i = 0; i < 8; ++i) {
    // Fallback weight: nearer and more in front of the surface counts more.
    const bool holds_light = usable.empty() || usable[static_cast<std::size_t>(cage.probes[i])] != 0;
    fallback[i] = holds_light ? std::max(0.05f, 0.5f * (facing[i] + 1.0f)) / (dist[i] * dist[i] + 1e-4f) : 0.0f;
    keep[i] = cage.weights[i] > 0 && holds_light && !(s.prune_back_facing && facing[i] < 0);
  }
  // The depth reads (often cache misses) are issued together, so they overlap.
  std::array<Footprint, 8> foot;
  std::array<std::array<TexelBits, 4>, 8> depth;
  const bool test_depth = s.prune_occluded;
  for (std::size_t i = 0; i < 8; ++i)
    if (keep[i] && test_depth && c.texel[i] >= 0) {
      foot[i] = footprint(layout, c.at[i]);
      const std::vector<DepthMap::Texel>& texels = states[static_cast<std::size_t>(cage.probes[i])].depth.texels;
      for (std::size_t k = 0; k < 4; ++k) {
        const DepthMap::Texel& t = texels[static_cast<std::size_t>(foot[i].texel[k])];
        depth[i][k] = {t.mean, t.variance};
      }
    }
  float sum = 0;
  for (std::size_t i = 0; i < 8; ++i) {
    float seen = 1.0f;
    if (keep[i] && test_depth && c.texel[i] >= 0) {
      seen = visibility_weight(
          visibility_of(depth[i], foot[i], states[static_cast<std::size_t>(cage.probes[i])].depth.unit, from_dist[i]), s);
      if (seen <= 0) keep[i] = false;
    }
    if (!keep[i] && cage.weights[i] > 0) ++r.pruned;
    r.weights[i] = keep[i] ? cage.weights[i] * seen : 0.0f;
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
ENGINE_ISA_DISPATCH(InterpolationResult, weigh, (const ProbeGrid::Cage& cage, const Corners& c, const MapLayout& layout,
                   const std::vector<ProbeMapState>& states, const InterpolationSettings& s, std::span<const std::uint8_t> usable),
                   (cage, c, layout, states, s, usable))

}  // namespace

}  // namespace transgi::probes
