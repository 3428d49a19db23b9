#include "probes/cascades.h"

#include <algorithm>
#include <cmath>

#include "probes/cascade_follow.h"
#include "probes/probe_field.h"

namespace transgi::probes {

float cascade_cell(const CascadeSettings& s, int k) { return std::ldexp(s.finest_cell, k); }

glm::ivec3 cascade_origin(const CascadeSettings& s, int k, const glm::vec3& eye) {
  const glm::ivec3 camera_cell(glm::floor(eye / cascade_cell(s, k)));
  return camera_cell - s.dims / 2;
}

glm::ivec3 cascade_origin(const CascadeSettings& s, int k, const glm::vec3& eye, const glm::vec3& forward) {
  const glm::vec3 half_extent = 0.5f * glm::vec3(s.dims) * cascade_cell(s, k);
  return cascade_origin(s, k, eye + s.look_ahead * half_extent * forward);
}

ProbeGrid cascade_grid(const CascadeSettings& s, int k, const glm::ivec3& origin) {
  const float cell = cascade_cell(s, k);
  ProbeGrid g;
  g.dims = glm::max(s.dims, glm::ivec3(1));
  g.min = (glm::vec3(origin) + 0.5f) * cell;
  g.max = g.min + glm::vec3(g.dims - 1) * cell;
  return g;
}

CascadeViewer CascadeViewer::sanitised() const {
  CascadeViewer v = *this;
  if (!std::isfinite(v.eye.x) || !std::isfinite(v.eye.y) || !std::isfinite(v.eye.z)) v.eye = glm::vec3(0.0f);
  v.eye = glm::clamp(v.eye, glm::vec3(-1e6f), glm::vec3(1e6f));
  const float len2 = glm::dot(v.forward, v.forward);
  v.forward = len2 > 0.5f && len2 < 2.0f ? v.forward / std::sqrt(len2) : glm::vec3(0.0f);
  return v;
}

bool fits_one_grid(const CascadeSettings& c, const glm::vec3& lo, const glm::vec3& hi) {
  const glm::vec3 extent = hi - lo;
  const float cell = std::max({extent.x, extent.y, extent.z}) / static_cast<float>(std::max({c.dims.x, c.dims.y, c.dims.z, 1}));
  return c.fit_scene_cell > 0 && std::isfinite(cell) && cell <= c.fit_scene_cell;
}

bool needs_far_field(const CascadeSettings& s, const glm::vec3& lo, const glm::vec3& hi) {
  const glm::vec3 extent = hi - lo;
  const float reach = cascade_cell(s, std::max(1, s.count) - 1) * static_cast<float>(std::min({s.dims.x, s.dims.y, s.dims.z}));
  return std::isfinite(extent.x + extent.y + extent.z) && std::max({extent.x, extent.y, extent.z}) > reach;
}

SceneBox geometry_core(std::span<const SceneBox> boxes) {
  const auto join = [](SceneBox a, const SceneBox& b) {
    if (b.empty()) return a;
    if (a.empty()) return b;
    a.lo = glm::min(a.lo, b.lo);
    a.hi = glm::max(a.hi, b.hi);
    return a;
  };
  const auto largest_side = [](const SceneBox& b) { return b.empty() ? 0.0f : std::max({b.hi.x - b.lo.x, b.hi.y - b.lo.y, b.hi.z - b.lo.z}); };
  const auto flat = [&](const SceneBox& b) {
    const glm::vec3 e = b.hi - b.lo;
    return !b.empty() && std::min({e.x, e.y, e.z}) < kFlatRatio * largest_side(b);
  };
  // Every box but box i, from the unions before and after it.
  const std::size_t n = boxes.size();
  std::vector<SceneBox> after(n + 1);
  for (std::size_t i = n; i-- > 0;) after[i] = join(after[i + 1], boxes[i]);
  SceneBox before, core;
  for (std::size_t i = 0; i < n; ++i) {
    const SceneBox others = join(before, after[i + 1]);
    const bool ground = flat(boxes[i]) && !others.empty() && largest_side(boxes[i]) > kGroundReach * largest_side(others);
    if (!ground) core = join(core, boxes[i]);
    before = join(before, boxes[i]);
  }
  return core.empty() ? before : core;
}

SceneBox geometry_core(const engine::rt::RtScene& rt) {
  std::vector<SceneBox> boxes;
  rt.for_each_instance([&](const engine::rt::InstanceRecord& r) { boxes.push_back(SceneBox{r.bounds.min, r.bounds.max}); });
  return geometry_core(boxes);
}

namespace {
// How far p lies inside [lo, hi] (its nearest face), negative outside.
float depth_inside(const BlendBox& b, const glm::vec3& p) {
  const glm::vec3 d = glm::min(p - b.lo, b.hi - p);
  return std::min({d.x, d.y, d.z});
}
}  // namespace

BoxMix blend_boxes(std::span<const BlendBox> all, const glm::vec3& p) {
  // The fallbacks come last; the blend runs over the boxes before them.
  std::size_t end = all.size();
  while (end > 0 && all[end - 1].fallback) --end;
  if (end < all.size()) {
    BoxMix m;
    for (std::size_t i = 0; i < end; ++i)
      if (depth_inside(all[i], p) >= 0) return blend_boxes(all.first(end), p);
    m.box = {static_cast<int>(all.size()) - 1, 0};  // held by none: the fallback holding p, else the last, clamped
    for (std::size_t i = end; i < all.size(); ++i)
      if (depth_inside(all[i], p) >= 0) {
        m.box[0] = static_cast<int>(i);
        break;
      }
    return m;
  }
  const std::span<const BlendBox> boxes = all;
  BoxMix m;
  m.box = {static_cast<int>(boxes.size()) - 1, 0};
  std::size_t i = 0;
  for (; i < boxes.size(); ++i)
    if (depth_inside(boxes[i], p) >= 0) break;
  if (i == boxes.size()) return m;  // outside all: the last one, clamped
  const float depth = depth_inside(boxes[i], p);
  const float w = boxes[i].band > 0 ? std::clamp(depth / boxes[i].band, 0.0f, 1.0f) : 1.0f;
  m.box[0] = static_cast<int>(i);
  if (w >= 1.0f) return m;
  std::size_t j = i + 1;
  for (; j < boxes.size(); ++j)
    if (depth_inside(boxes[j], p) >= 0) break;
  if (j == boxes.size()) {
    // Nothing beyond holds p: the fading box keeps it all, unless a later
    // box exists to clamp into (the coarsest cascade).
    if (i + 1 == boxes.size()) return m;
    j = boxes.size() - 1;
  }
  m.box[1] = static_cast<int>(j);
  m.weight = {w, 1.0f - w};
  m.count = 2;
  return m;
}

void interpolate_fields(std::span<const ProbeField* const> fields, const glm::vec3& p, const glm::vec3& n, float* out) {
  interpolate_fields_with(
      fields, p, n, [](const ProbeField* f) { return f->light_sh_all().data(); },
      [](const ProbeField* f) { return f->direct_sh_all().data(); }, out, nullptr);
}

}  // namespace transgi::probes
