#pragma once
// Probes where the viewer is: camera-centred cascades of probe grids, and
// the blend that hands a shading point from one probe field to the next.
// Shared by both probe plugins (TransGI's ProbeField and DDGI's volume): a
// cascade is a ProbeGrid, placed here, scrolled by whole cells
// (ProbeGrid::scroll_by) by whoever owns its probes.
//
// Cascade k refreshes budget / 2^k probes a frame (at least one) when the
// run-time settings give a budget (ProbeFieldSettings::update_budget), nearest
// the camera and stalest first: coarse cascades, whose probes light what is
// far away, update less often.
//
// Cascade k has the same dims as the others and cells 2^k times the finest
// one, centred on the camera and snapped to whole cells of its own size: its
// probes sit at cell centres, (origin + c + 0.5) x cell, so no probe ever
// lies on a plane through the world origin (a ground plane at y = 0).
#include <algorithm>
#include <array>
#include <span>
#include <vector>

#include "probes/probe_field.h"

#include <glm/glm.hpp>

#include "probes/probe_grid.h"

namespace transgi::probes {


struct CascadeSettings {
  // Cascades, each covering twice the extent of the one before. Higher = GI
  // reaches further from the camera, at the cost of dims^3 more probes each
  // (memory, and rays when they update).
  int count = 4;
  // Probe spacing of the finest cascade, in metres. Lower = finer lighting
  // near the camera, at the cost of reach: the coarsest cascade spans
  // dims x finest_cell x 2^(count - 1).
  float finest_cell = 0.5f;
  glm::ivec3 dims{8};
  // Width of the band inside each cascade's faces across which it hands over
  // to the next coarser one, in its own cells. Higher = smoother
  // transitions, at the cost of two interpolations over more of the screen.
  float blend_cells = 1.0f;
  // How far ahead of the camera each cascade's centre sits, as a fraction of
  // its half extent along the view direction (0 = centred on the camera, 1 =
  // the camera at its back face). Higher = more of each cascade's probes in
  // view, where they are seen, at the cost of more probes entering (and
  // starting from their coarser cascade's light) when the camera turns.
  float look_ahead = 0.0f;
  // A scene small enough that one dims grid over its geometry (less its
  // ground planes: geometry_core, the far field over those) has cells no
  // larger than this (metres) gets that grid instead of cascades, fitted once
  // (a closed room: on the sample level GI RMSE 0.0109 against 0.0216 for
  // cascades, docs/results.md). Higher = more scenes lit by one fitted grid,
  // at the cost of coarser probes in big ones; 0 = always cascades.
  float fit_scene_cell = 2.0f;
  // Where the scene reaches beyond the coarsest cascade, one more grid of
  // `dims` probes over the scene's bounds (the far field, fitted once) lights
  // what no cascade holds, as Lumen's far field does: a room 5 km across is
  // lit as one 5 m across. Off = beyond the coarsest cascade only its clamped
  // light, whose probes are far from every surface there (inactive): dark.
  // Costs one grid of probes, refreshed at the budget one cascade coarser
  // than the last would get.
  bool far_field = true;
  // Radiance map width of the cascades' probes on the real-time path
  // (height half of it; 0 = the run-time settings' map). Higher = finer
  // angular detail before the SH-4 projection, at the cost of 11 bytes per
  // texel per probe: with 32 (512 texels) four 8^3 cascades hold 7.1 MB on
  // the Breakfast Room on a ground plane against 14.9 MB with the real-time
  // preset's 50 x 25, for GI RMSE 0.130 against 0.125 (docs/results.md). The
  // quality path keeps no memory target and uses the run-time settings' map
  // (100 x 50: 54 MB there, and mean GI 0.91x of the reference against 0.95x
  // at 32 x 16, whose coarse texels still come out 1.06x their oracle).
  int map_width = 32;

  bool operator==(const CascadeSettings&) const = default;
};

// Whether the scene's bounds reach beyond the coarsest cascade's extent on
// some axis (then a far field is added, if asked).
[[nodiscard]] bool needs_far_field(const CascadeSettings& s, const glm::vec3& lo, const glm::vec3& hi);

// An axis-aligned box of world space; empty when lo > hi.
struct SceneBox {
  glm::vec3 lo{1.0f}, hi{-1.0f};
  [[nodiscard]] bool empty() const { return glm::any(glm::greaterThan(lo, hi)); }
  bool operator==(const SceneBox&) const = default;
};
// The box of the scene's geometry less its ground planes: a box (one per
// instance) that is flat (smallest side under kFlatRatio of its largest) and
// whose largest side is more than kGroundReach times that of all the other
// boxes together. Why: a building on a 200 m ground plane has the plane's
// bounds, so the fitted grid's rule (CascadeSettings::fit_scene_cell) sent it
// to the camera's cascades, whose coarse cells put probes outside its thin
// walls and lit its rooms with the sky (docs/image-quality.md, 2026-11-27,
// evening). A room's walls and floor, even as single quads, are each no
// larger than the room the others make, so they stay. Returns the union of
// every box when nothing is left out; empty when there are no boxes.
inline constexpr float kFlatRatio = 0.01f;
inline constexpr float kGroundReach = 4.0f;
[[nodiscard]] SceneBox geometry_core(std::span<const SceneBox> instance_boxes);
// The same over the scene's live instances.
[[nodiscard]] SceneBox geometry_core(const engine::rt::RtScene& rt);
// Cell size of cascade k.
[[nodiscard]] float cascade_cell(const CascadeSettings& s, int k);
// Grid coordinates (in cascade k's cells, world-anchored) of probe (0,0,0)
// for a camera at `eye`: the camera lies within half a cell of probe dims/2 on
// each axis.
[[nodiscard]] glm::ivec3 cascade_origin(const CascadeSettings& s, int k, const glm::vec3& eye);
// The same with the look-ahead: centred at eye + look_ahead x half extent x
// forward (a unit view direction).
[[nodiscard]] glm::ivec3 cascade_origin(const CascadeSettings& s, int k, const glm::vec3& eye, const glm::vec3& forward);
// Cascade k's grid for an origin from cascade_origin (scroll 0).
[[nodiscard]] ProbeGrid cascade_grid(const CascadeSettings& s, int k, const glm::ivec3& origin);

// How much of a point's light each box gives: boxes in priority order (an
// authored volume before the cascades, finest cascade first), each the
// probes' extent [lo, hi] with a band width (world units, 0 = hard edge).
// The first box holding p takes w = clamp(depth / band, 0, 1), where depth is
// p's distance inside its nearest face; the rest, 1 - w, goes to the next box
// holding p, whole. If no box holds p the last box takes it all (clamped
// interpolation, as a single grid does). Weights sum to 1.
struct BlendBox {
  glm::vec3 lo{0.0f}, hi{0.0f};
  float band = 0.0f;
  // A fallback (the far field; boxes after every other): it lights only what
  // no other box holds, and no other box fades into it, so the cascades'
  // light is the same with it as without wherever they reach.
  bool fallback = false;
};
// A field whose settings' blend_cells is this is a fallback box (the far field).
inline constexpr float kFallbackBlendCells = -1.0f;
struct BoxMix {
  std::array<int, 2> box{0, 0};
  std::array<float, 2> weight{1.0f, 0.0f};
  int count = 1;
};
[[nodiscard]] BoxMix blend_boxes(std::span<const BlendBox> boxes, const glm::vec3& p);

// The same over probe fields of either plugin (ProbeField, DdgiVolume: a
// Field has placement() and settings().blend_cells), each box its grid's
// extent and band (blend_cells x its smallest spacing). fields must not be
// empty; a single field takes everything, whatever p.
template <class Field>
struct FieldMixOf {
  std::array<const Field*, 2> field{};
  std::array<float, 2> weight{1.0f, 0.0f};
  int count = 1;
};
template <class Field>
[[nodiscard]] FieldMixOf<Field> mix_at(std::span<const Field* const> fields, const glm::vec3& p) {
  FieldMixOf<Field> m;
  m.field[0] = fields.front();
  if (fields.size() == 1) return m;  // the usual case, asked once per decoded pixel
  // On the stack for the usual few fields (authored volumes and four cascades).
  std::array<BlendBox, 16> local{};
  std::vector<BlendBox> many;
  BlendBox* boxes = local.data();
  if (fields.size() > local.size()) {
    many.resize(fields.size());
    boxes = many.data();
  }
  for (std::size_t i = 0; i < fields.size(); ++i) {
    const ProbeGrid& g = fields[i]->placement();
    const float cells = fields[i]->settings().blend_cells;
    const float hold = fields[i]->settings().hold_cells;
    boxes[i] = {g.held_min(hold), g.held_max(hold), cells == kFallbackBlendCells ? 0.0f : cells * g.min_spacing(), cells == kFallbackBlendCells};
  }
  const BoxMix b = blend_boxes(std::span<const BlendBox>(boxes, fields.size()), p);
  m.count = b.count;
  for (std::size_t k = 0; k < static_cast<std::size_t>(b.count); ++k) {
    m.field[k] = fields[static_cast<std::size_t>(b.box[k])];
    m.weight[k] = b.weight[k];
  }
  return m;
}
// The first field after `after` whose grid holds p, else the last field,
// else null (after is the last, or not in fields).
template <class Field>
[[nodiscard]] const Field* next_holding(std::span<const Field* const> fields, const Field* after, const glm::vec3& p) {
  std::size_t i = 0;
  while (i < fields.size() && fields[i] != after) ++i;
  if (i + 1 >= fields.size()) return nullptr;
  for (std::size_t j = i + 1; j < fields.size(); ++j) {
    const ProbeGrid& g = fields[j]->placement();
    const float hold = fields[j]->settings().hold_cells;
    if (glm::all(glm::greaterThanEqual(p, g.held_min(hold))) && glm::all(glm::lessThanEqual(p, g.held_max(hold)))) return fields[j];
  }
  return fields.back();
}

using FieldMix = FieldMixOf<ProbeField>;
[[nodiscard]] inline FieldMix fields_at(std::span<const ProbeField* const> fields, const glm::vec3& p) { return mix_at(fields, p); }

// Interpolated SH light at a surface point from the fields, blended as
// fields_at says. A field with no probe that holds light and sees p (all
// buried, far or pruned: a fine cascade in open space, or whose only lit
// probes stand behind the wall) hands its whole weight to the next field
// holding p; if every field does, the last one asked gives its fallback. indirect(f) and direct(f) give field f's SH arrays
// (world or rotated, probes x 75); out_direct null = indirect only. With one
// field this is exactly that field's ProbeField::interpolate.
template <class IndirectOf, class DirectOf>
void interpolate_fields_with(std::span<const ProbeField* const> fields, const glm::vec3& p, const glm::vec3& n,
                             IndirectOf indirect, DirectOf direct, float* out, float* out_direct) {
  const auto one = [&](const ProbeField* f, float* o, float* od) {
    return od ? f->interpolate(p, n, indirect(f), o, direct(f), od) : f->interpolate(p, n, indirect(f), o);
  };
  const FieldMix m = fields_at(fields, p);
  const ProbeField* first = m.field[0];
  // An unlit field passes the point on; a lit one ends the search.
  while (!one(first, out, out_direct)) {
    first = next_holding(fields, first, p);
    if (first) continue;
    // No field has a lit probe around p (past the coarsest cascade's reach):
    // rather than black, the last field's mean light, where the arrays are
    // its world-space ones (a rotated copy keeps what it got).
    const ProbeField* last = fields.back();
    bool black = true;
    for (int k = 0; k < 75 && black; ++k) black = out[k] == 0.0f;
    if (black && fields.size() > 1 && indirect(last) == last->light_sh_all().data()) {
      std::copy_n(last->mean_light_sh(), 75, out);
      if (out_direct) std::copy_n(last->mean_direct_sh(), 75, out_direct);
    }
    return;
  }
  if (m.count == 1 || first != m.field[0]) return;
  float a[75], b[75];
  if (!one(m.field[1], a, out_direct ? b : nullptr)) return;  // the second is unlit: the first keeps it all
  for (int k = 0; k < 75; ++k) out[k] = m.weight[0] * out[k] + m.weight[1] * a[k];
  if (out_direct)
    for (int k = 0; k < 75; ++k) out_direct[k] = m.weight[0] * out_direct[k] + m.weight[1] * b[k];
}

// The same at n points (75 values each into out, and the direct light's
// into out_direct where given): with one field, its weights for a batch of
// points at once (ProbeField::interpolation_weights: the depth maps' cache
// misses overlap), then each point's blends; with several, point by point.
// The same values either way. indirect_of(k, f) and direct_of(k, f) name
// field f's SH arrays for point k (world or rotated into its object's frame).
template <class IndirectOf, class DirectOf>
void interpolate_fields_many(std::span<const ProbeField* const> fields, const glm::vec3* position, const glm::vec3* normal,
                             std::size_t n, IndirectOf indirect_of, DirectOf direct_of, float* out, float* out_direct) {
  if (fields.size() == 1 && out_direct) {
    constexpr std::size_t kBatch = 64;
    const ProbeField* f = fields.front();
    std::array<InterpolationResult, kBatch> weights;
    for (std::size_t c0 = 0; c0 < n; c0 += kBatch) {
      const std::size_t c1 = std::min(n, c0 + kBatch);
      f->interpolation_weights(std::span<const glm::vec3>(position + c0, c1 - c0), std::span<const glm::vec3>(normal + c0, c1 - c0),
                               std::span<InterpolationResult>(weights).first(c1 - c0));
      for (std::size_t k = c0; k < c1; ++k)
        ProbeField::blend(weights[k - c0], indirect_of(k, f), out + k * 75, direct_of(k, f), out_direct + k * 75);
    }
    return;
  }
  for (std::size_t k = 0; k < n; ++k)
    interpolate_fields_with(
        fields, position[k], normal[k], [&](const ProbeField* f) { return indirect_of(k, f); },
        [&](const ProbeField* f) { return direct_of(k, f); }, out + k * 75, out_direct ? out_direct + k * 75 : nullptr);
}

// The indirect light alone, from the fields' world-space SH.
void interpolate_fields(std::span<const ProbeField* const> fields, const glm::vec3& p, const glm::vec3& n, float* out75);

}  // namespace transgi::probes
