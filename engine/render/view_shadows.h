#pragma once
// Shadow rays from every pixel a camera sees towards a set of lights, one
// ray per pixel and light, made from the view's hits alone: what a device
// traces right after its visibility pass, in the same submission, so that
// the host's direct light reads their answers instead of sending rays of its
// own (CameraHitTracer::queue_camera_hits). trace_view_shadows is the CPU
// oracle the device's kernel (shaders/view_shadows.comp) is tested against.
//
// Pixel (x, y) with a hit at distance t along its camera ray (origin o,
// unit direction d) stands at p = o + t d, with the hit triangle's
// geometric normal ng turned towards the camera. Its ray to light l leaves
// rt::offset_ray_origin(p, ng, offset_scale):
// - a directional light: along directions[c], c = view_shadow_cell(x, y,
//   pattern_shift) (a pattern of 8 x 8 directions over the light's disk,
//   tiled over the image), unbounded;
// - a point or spot light: towards its position, up to 1 - 1e-4 of the
//   distance.
// A ray is traced only where its direction lies above the surface within
// kViewShadowSlack (dot(direction, ng) > -kViewShadowSlack): a superset of
// the rays a shader that tests dot > 0 with its own rounding of p and ng
// asks for. The answer for (l, pixel) is at [l * pixels + pixel]:
// - nearest lights: the distance to the nearest blocker (a soft shadow's
//   width needs it), +infinity where nothing blocks;
// - others: 0 where blocked, +infinity where not;
// - NaN where no ray was traced (no hit, or the light below the surface).
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "engine/render/camera_rays.h"
#include "engine/rt/rt_scene.h"

namespace engine::render {

inline constexpr int kViewShadowPatternCells = 64;  // 8 x 8
inline constexpr float kViewShadowSlack = 1e-3f;

// Cell of pixel (x, y) in the 8 x 8 pattern shifted by `shift`.
[[nodiscard]] inline int view_shadow_cell(int x, int y, glm::ivec2 shift) {
  return ((x + shift.x) & 7) | (((y + shift.y) & 7) << 3);
}

struct ViewShadowLight {
  bool directional = false;
  bool nearest = false;  // the nearest blocker's distance, else blocked or not
  glm::vec3 position{0.0f};  // point and spot lights
  std::array<glm::vec3, kViewShadowPatternCells> directions{};  // directional lights: unit, towards the light
  bool operator==(const ViewShadowLight&) const = default;
};

struct ViewShadowRequest {
  std::vector<ViewShadowLight> lights;
  glm::ivec2 pattern_shift{0};
  float offset_scale = 1.0f;  // RtScene::offset_scale
  bool operator==(const ViewShadowRequest&) const = default;
};

// The answers for the view whose camera rays are camera.generate((x, y) +
// film_offset) and whose hits are `hits` / `found` (CameraHitTracer's),
// traced with Embree; out holds lights x pixels values.
void trace_view_shadows(const rt::RtScene& scene, const CameraRays& camera, glm::vec2 film_offset,
                        std::span<const rt::Hit> hits, std::span<const std::uint8_t> found, const ViewShadowRequest& request,
                        std::span<float> out);

}  // namespace engine::render
