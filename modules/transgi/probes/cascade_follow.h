#pragma once
// The one implementation of cascades following the camera, shared by both
// probe plugins (TransGI's ProbeField, DDGI's DdgiVolume): a plugin keeps a
// CascadeState per cascade set and calls follow_camera each frame with how to
// make, compare and scroll its own field type. A Field has placement(): its
// grid as placed, before any probe relocation.
#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "probes/cascades.h"

namespace transgi::probes {

template <class Field>
struct CascadeState {
  std::vector<std::shared_ptr<Field>> fields{};  // finest first, then the far field if there is one
  std::vector<glm::ivec3> origins{};             // each field's cascade_origin
  // The scene was small enough (CascadeSettings::fit_scene_cell) that
  // `fields` is one grid fitted to its bounds, decided and fitted once.
  bool fitted_to_scene = false;
  // The last of `fields` is the far field (CascadeSettings::far_field): a
  // grid over the scene's bounds, fitted once, beyond every cascade.
  bool far_field = false;
};

// The viewer: eye position and unit forward (zero when unknown); a non-finite
// eye becomes the origin and a far one is clamped, so cell indices fit an int.
struct CascadeViewer {
  glm::vec3 eye{0.0f}, forward{0.0f};
  [[nodiscard]] CascadeViewer sanitised() const;
};

// Where the cascades centre: the requested camera (else the first one; with
// none, the middle of [lo, hi]) and its view direction. `cameras` is an ECS
// view of (const Camera, const WorldTransform).
template <class CameraView, class Entity>
CascadeViewer viewer_of(const CameraView& cameras, Entity requested, const glm::vec3& lo, const glm::vec3& hi) {
  CascadeViewer v{0.5f * (lo + hi), glm::vec3(0.0f)};
  bool found = false;
  cameras.each([&](Entity e, const auto&, const auto& to_world) {
    if (!found || e == requested) {
      v.eye = to_world.translation;
      v.forward = to_world.rotation * glm::vec3(0.0f, 0.0f, -1.0f);  // glTF cameras look down -z
    }
    found = true;
  });
  return v;
}

// Whether a scene with these bounds gets one fitted grid (fit_scene_cell).
[[nodiscard]] bool fits_one_grid(const CascadeSettings& c, const glm::vec3& lo, const glm::vec3& hi);

// After it, `state` holds one field per cascade placed on the viewer (and the
// far field after them where the scene reaches beyond the coarsest), or the
// one fitted grid (over the scene's geometry less its ground planes,
// core_of() = geometry_core, asked once when the choice is made; with the far
// field after it over the whole scene when a ground plane was left out).
// Fields are made by make(grid, k) (k = -1 for the fitted grid, k = count
// for the far field); a field for which same_but_place(field, grid, k) is
// false is made anew; one whose origin moved is scrolled by scroll(field,
// cells, coarser), coarsest first, so a finer cascade's entered probes are
// seeded from a coarser one that has already moved; scroll returns how many
// probes entered, and so does follow_camera, summed. kept(field) is called on
// each field that was neither made nor rebuilt this frame (to tell it of
// scene changes) and on every field with the viewer (to aim budgets).
template <class Field, class CoreOf, class Make, class SameButPlace, class Scroll, class Kept>
int follow_camera(CascadeState<Field>& state, const CascadeSettings& c, const CascadeViewer& viewer, const glm::vec3& scene_lo,
                  const glm::vec3& scene_hi, CoreOf core_of, Make make, SameButPlace same_but_place, Scroll scroll, Kept kept) {
  const int far_k = std::max(1, c.count);
  if (state.fields.empty()) {
    const SceneBox core = core_of();
    const glm::vec3 lo = core.empty() ? scene_lo : core.lo, hi = core.empty() ? scene_hi : core.hi;
    if (fits_one_grid(c, lo, hi)) {
      state.fields = {make(ProbeGrid::centred_in(lo, hi, c.dims), -1)};
      state.origins = {glm::ivec3(0)};
      state.fitted_to_scene = true;
      state.far_field = c.far_field && (glm::any(glm::lessThan(scene_lo, lo)) || glm::any(glm::greaterThan(scene_hi, hi)));
      if (state.far_field) {
        state.fields.push_back(make(ProbeGrid::centred_in(scene_lo, scene_hi, c.dims), far_k));
        state.origins.push_back(glm::ivec3(0));
      }
      return 0;
    }
  }
  if (state.fitted_to_scene) {
    for (std::size_t i = 0; i < state.fields.size(); ++i) {
      auto& f = state.fields[i];
      const int k = state.far_field && i + 1 == state.fields.size() ? far_k : -1;
      const ProbeGrid grid = f->placement();
      if (!same_but_place(*f, grid, k))
        f = make(grid, k);
      else
        kept(*f, false);
    }
    return 0;
  }
  const CascadeViewer v = viewer.sanitised();
  const int n = std::max(1, c.count);
  // The far field, if any, stays last; set aside while the cascades follow.
  std::shared_ptr<Field> far;
  if (state.far_field && !state.fields.empty()) far = state.fields.back();
  state.fields.resize(static_cast<std::size_t>(n));
  state.origins.resize(static_cast<std::size_t>(n));
  int entered = 0;
  for (int k = n - 1; k >= 0; --k) {
    auto& field = state.fields[static_cast<std::size_t>(k)];
    glm::ivec3& origin = state.origins[static_cast<std::size_t>(k)];
    const glm::ivec3 wanted_origin = cascade_origin(c, k, v.eye, v.forward);
    const ProbeGrid wanted = cascade_grid(c, k, wanted_origin);
    if (field) {
      // Equal but for where it stands: scroll it; anything else: rebuild.
      const ProbeGrid& now = field->placement();
      if (!same_but_place(*field, now, k) || now.dims != wanted.dims || now.spacing() != wanted.spacing()) field.reset();
    }
    if (!field) {
      field = make(wanted, k);
      origin = wanted_origin;
    } else {
      const Field* coarser = k + 1 < n ? state.fields[static_cast<std::size_t>(k + 1)].get() : nullptr;
      entered += scroll(*field, wanted_origin - origin, coarser);
      origin = wanted_origin;
      kept(*field, true);
    }
  }
  state.far_field = c.far_field && needs_far_field(c, scene_lo, scene_hi);
  if (state.far_field) {
    if (!far || !same_but_place(*far, far->placement(), n))
      far = make(ProbeGrid::centred_in(scene_lo, scene_hi, c.dims), n);
    else
      kept(*far, false);
    state.fields.push_back(std::move(far));
    state.origins.push_back(glm::ivec3(0));
  }
  return entered;
}

}  // namespace transgi::probes
