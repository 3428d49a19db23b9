#pragma once
// Temporal antialiasing with reprojection (issue 37): each frame traces its
// camera rays through a different sub-pixel point (a Halton (2, 3) cycle),
// and the image a player sees is this frame's blended with the history of
// earlier frames, found where each pixel's surface point was in the previous
// frame: carried back through its object's motion (rigid objects move, the
// point stays put in the object's frame) and the previous camera. A history
// sample counts only where the previous frame saw the same object there,
// on the same tangent plane, with a similar normal. Where the pixel moved on
// screen, or the caller says the light changed, the history is clamped to
// the range of the current frame's pixel and its eight neighbours (widened
// by a margin, so small changes of light blend instead of flickering), so
// what changed does not linger; where neither holds it is not, so a feature
// thinner than a pixel, which only some jitter points hit, keeps its average instead of being
// clamped away by the frames that miss it. Where nothing in the history
// matches (an object moved away, a cut, a resize) the pixel restarts from
// this frame: no ghost. A still view converges to the mean over the jitter
// cycle: an antialiased image at one sample per pixel per frame.
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "engine/ecs/entity.h"
#include "engine/image/image.h"
#include "engine/render/camera_rays.h"
#include "engine/rt/rt_scene.h"

namespace engine::render {

struct TemporalAaSettings {
  bool enabled = false;
  // The current frame's weight where the history matches (a history of
  // fewer than 1 / blend frames is their plain mean). Higher = follows
  // changing light sooner, at the cost of more aliasing and of more of the
  // jitter's alternation at edges left in (UE4's default is 0.04). 1/16:
  // one jitter cycle (jitter_phases) is averaged evenly before the blend
  // takes over, and an edge pixel's alternation moves it by 1/16 a frame.
  float blend = 0.0625f;
  // Where the history is clamped, the range of the current neighbours is
  // widened by this fraction of its middle: a change of light smaller than
  // that (a probe's update, the sun a little further on) is blended over
  // frames instead of passed through as flicker. Higher = steadier under
  // slowly changing light, at the cost of a trail that long behind a
  // change of that size (a moving shadow's soft edge).
  float clamp_margin = 0.2f;
  // Sub-pixel points in the jitter cycle. Higher = finer antialiasing of a
  // still view, at the cost of a longer cycle to converge.
  int jitter_phases = 16;
  // Where the camera, the pixel's surface and the light have stayed still
  // for a whole jitter cycle, the pixel shows the plain mean of a cycle's
  // samples, the same in every frame while nothing changes: each new
  // cycle's mean is faded in linearly over the next cycle, so what drifts
  // (the probes settling) moves smoothly instead of stepping once a cycle.
  // The exponential history alone keeps a ripple of the jitter at
  // high-contrast edges (each phase's weight rises and decays in turn: 2-3 %
  // of a room's pixels flickered by more than 2/255). On = no ripple, at the
  // cost of still pixels following slow drift up to two cycles late. Off =
  // the exponential history everywhere.
  bool cycle_mean = true;
  // A still camera's pixels whose surface and history hold no moved object
  // are blended a row at a time, vectorised. false = every pixel by the
  // per-pixel path: the reference the fast path is tested against.
  bool vectorised_rows = true;
  // Textures are read this many mip levels finer than a pixel's footprint
  // asks: the jitter cycle already averages each pixel's area, and the mip's
  // own filter on top of it blurred textures (a grazing floor most, where
  // the isotropic footprint is the long side). -1 leaves about the
  // reference's 1.5-pixel filter (engines bias their mips under TAA the same
  // way). Lower = sharper textures, at the cost of shimmer in motion.
  float texture_lod_bias = -1.0f;
  // The bias a G-buffer reads textures with: none without antialiasing,
  // whose single sample per pixel must then be the pixel's own average.
  [[nodiscard]] float texture_lod_bias_in_use() const { return enabled ? texture_lod_bias : 0.0f; }
};

// What the resolve needs to know of each pixel's surface, this frame. The
// resolve takes the vectors' contents into its history and gives back the
// spent storage of the frame before (the same size), so no frame copies
// them: fill them afresh before the next resolve.
struct TaaSurfaces {
  std::vector<glm::vec3>& position;  // world position (unused for a miss)
  std::vector<glm::vec4>& guide;     // world normal (xyz), depth (w; 0 = the ray missed)
  std::vector<ecs::Entity>& entity;  // what the ray hit (null for a miss)
};

struct TaaObject {
  ecs::Entity entity;
  transform::Similarity to_world;
};
// The ray-traced scene's instances as resolve() takes them.
std::vector<TaaObject> objects_of(const rt::RtScene& scene);

class TemporalAntialiasing {
 public:
  static constexpr std::size_t kMaxLayers = 4;
  // The sub-pixel offset, in [-0.5, 0.5)^2 pixels, of the next frame's camera
  // rays (film = pixel + 0.5 + jitter); 0 when disabled.
  [[nodiscard]] glm::vec2 next_jitter(const TemporalAaSettings& settings) const;
  // The next frame's phase in the jitter cycle, 0..jitter_phases - 1 (0
  // when disabled): what else varies over the cycle (a shadow pattern's
  // shift) takes it, so a still pixel's cycle mean averages that too.
  [[nodiscard]] int next_phase(const TemporalAaSettings& settings) const;
  // Blends each of `layers` (same size as the camera's image, traced with
  // next_jitter()'s offset) with its history, in place, and keeps the
  // result and the surfaces as the next frame's history. Every layer shares
  // the reprojection; each is clamped by its own neighbours.
  // light_changed: anything but the camera and the objects' motion changed
  // what this frame shows (lights, materials, what the probes hold), so
  // every pixel's history is clamped.
  // objects: every object's object-to-world transform now (objects_of()).
  void resolve(const CameraRays& camera, TaaSurfaces surfaces, std::span<const TaaObject> objects,
               std::span<image::ImageRGB* const> layers, const TemporalAaSettings& settings, bool light_changed);
  // Forgets the history: the next frame is its own.
  void clear();

  struct Stats {
    std::size_t reused = 0;    // pixels blended with their history
    std::size_t rejected = 0;  // hit pixels whose history did not match (restarted)
  };
  [[nodiscard]] const Stats& stats() const { return stats_; }

 private:
  // Per entity index: its transform in a frame (valid for `generation`).
  struct Placed {
    std::uint32_t generation = 0;
    bool present = false;
    transform::Similarity to_world;
  };
  // Per entity index, this frame: whether it moved since the previous one,
  // and the transform that carries a point of it back there.
  struct Motion {
    std::uint32_t generation = 0;
    bool moved = false;
    transform::Similarity back;
  };
  void plan_motion(std::span<const TaaObject> objects);
  [[nodiscard]] bool moved(ecs::Entity e) const {
    return !e.is_null() && e.index < motion_.size() && motion_[e.index].moved && motion_[e.index].generation == e.generation;
  }
  // Whether the previous frame showed, at or beside its pixel q, an object
  // other than `self` that has since moved: q's history holds some of it.
  [[nodiscard]] bool moved_beside(std::size_t q, ecs::Entity self) const;
  // Per previous pixel: whether it or a neighbour showed an object that has
  // since moved (empty when none moved), so moved_beside runs only there.
  void mark_near_moved();
  std::vector<std::uint8_t> near_moved_;
  void keep_history(const CameraRays& camera, TaaSurfaces& surfaces, std::span<image::ImageRGB* const> layers);
  class NeighbourRange;
  // A still camera's row: blends every pixel whose surface and history
  // hold no moved object with its history at the pixel itself (the common
  // case, vectorised), marks them in `plain` and returns how many; the
  // rest are left to resolve()'s per-pixel path.
  std::size_t blend_still_row(std::size_t row, int w, const std::vector<ecs::Entity>& entity,
                              std::span<image::ImageRGB* const> layers, const NeighbourRange& range, float clamp_amount,
                              float blend, const TemporalAaSettings& settings, std::vector<std::uint8_t>& plain,
                              std::vector<float>& alpha3);

  struct Previous {
    std::optional<CameraRays> camera;
    std::vector<glm::vec3> position;
    std::vector<glm::vec4> guide;
    std::vector<ecs::Entity> entity;
    std::vector<std::uint8_t> frames;  // per pixel: frames its history holds, up to 255
    std::vector<image::ImageRGB> layers;
    std::vector<Placed> placed;  // by entity index
  } prev_;
  std::vector<Motion> motion_;  // by entity index, this frame
  std::vector<Placed> placed_;  // by entity index, this frame
  bool any_moved_ = false;
  std::vector<image::ImageRGB> out_;  // the resolve's output, kept to reuse its storage
  std::vector<std::uint8_t> frames_;  // this frame's per-pixel frame counts
  // TemporalAaSettings::cycle_mean. Per pixel: whether this frame blended it
  // with its own history at the pixel itself (a still camera, nothing moved
  // there); samples summed in the current cycle (0: not summing; a sum
  // starts at phase 0); frames since the last cycle's mean was complete
  // (0: none yet), over which the shown value fades from cycle_from_ to
  // cycle_to_ (that mean).
  std::vector<std::uint8_t> still_plain_, cycle_count_, cycle_ramp_;
  std::vector<image::ImageRGB> cycle_sum_, cycle_from_, cycle_to_;  // per layer
  void apply_cycle_mean(std::span<image::ImageRGB* const> layers, int phases, std::uint64_t phase, bool light_changed);
  std::uint64_t frame_ = 0;
  Stats stats_;
};

// Halton (2, 3) point `index` of a cycle of `phases`, centred on 0.
glm::vec2 taa_jitter(std::uint64_t index, int phases);

}  // namespace engine::render
