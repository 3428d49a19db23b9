#pragma once
// Deterministic real-time direct light (issue 10, item 6), from the G-buffer:
//  - emission the camera sees, and the background (with its sun disk) where
//    camera rays escape;
//  - every punctual light, the sun split out of the environment included,
//    with one shadow ray per light per pixel, traced as 4x4-pixel Embree
//    packets. Delta lights keep that one ray: hard shadows.
//  - a directional light with a disk (the sun) gets a soft shadow: each
//    pixel's ray goes to one point of a fixed 8x8 pattern over the disk (no
//    seed, no frame index), so 8x8 neighbouring pixels see the whole disk
//    between them. A filter over the visibility of the pixels around each
//    pixel on the same surface (penumbra_filter, after the last tile) turns
//    that dither into the disk's average visibility: a smooth penumbra, as
//    wide as the disk and the blocker's distance make it, and the same in
//    every frame. The BRDF takes the disk's centre.
// The rest of the direct light, the residual sky and emissive meshes, comes
// from the probes' direct SH through the transfer (shade_gi_realtime's
// direct_out), which the frame adds with add_image.
// The reference is the path tracer's direct pass.
#include <array>
#include <atomic>
#include <memory>
#include <span>
#include <vector>

#include "engine/image/image.h"
#include "engine/render/camera_rays.h"
#include "engine/render/light_set.h"
#include "engine/render/temporal_aa.h"
#include "engine/render/view_shadows.h"
#include "shading/realtime_gi.h"

namespace transgi::shading {

// Points of the disk pattern (disk_pattern): one 8 x 8 block, the view's
// shadow pattern (render/view_shadows.h).
inline constexpr int kDiskPatternCells = engine::render::kViewShadowPatternCells;

struct RealtimeDirectStats {
  std::size_t shadow_rays = 0;
  std::size_t lights = 0;  // punctual lights shaded (the split sun included)
  // Pixels whose seen emission, background or light came out non-finite and
  // were set to zero (issue 13's NaN containment).
  std::size_t nonfinite_pixels = 0;
  // Shadow rays the shader asked the view's answers for (traced_with_view)
  // and found none traced: a light the device found below the surface where the
  // host's rounding put it just above. Shaded as blocked.
  std::size_t untraced_answers = 0;
  bool traced_with_view = false;  // the shadow rays were the view's (shade_direct_realtime)
};

// The pass one 4x4 tile at a time: shade_direct_realtime runs it over the
// whole G-buffer, and the real-time frame runs it inside the G-buffer's own
// tile loop (trace_gbuffer's `direct`), while the tile's samples are still in
// cache; the image is the same either way. shade_tile may run on several
// threads at once for different tiles.
class DirectTileShader {
 public:
  // `pattern_phase`: which of kDiskPatternPhases shifts of the disk pattern
  // this frame uses (disk_pattern_shift): the temporal antialiasing's jitter
  // phase, so that a still pixel's cycle mean averages 16 points of the disk
  // where its penumbra is too narrow for the filter to hold the whole
  // pattern (a contact shadow's serrated edge). 0 = the unshifted pattern.
  DirectTileShader(const engine::rt::RtScene& scene, const engine::render::LightSet& lights,
                   const engine::render::CameraRays& camera, int width, int height,
                   engine::image::ImageRGB recycled = {}, int pattern_phase = 0);
  // `recycled`: last frame's image, whose storage this one reuses where the
  // size matches (tiles write every pixel, so nothing is cleared: clearing
  // a 640x360 image was serial time in the frame).
  // A tile's rays, hits and per-pixel terms. Built once per loop over tiles,
  // not per tile: constructing 16 rays and hits every tile cost a fifth of
  // the pass.
  struct Scratch {
    engine::rt::Ray rays[16];
    engine::rt::Hit hits[16];
    bool found[16];
    float distance[16];
    std::size_t pixel[16];
    const GSample* samples[16];
    std::array<glm::vec3, 2> local[16];  // wo, wi in the shading frame
    glm::vec3 light[16];
  };
  // Pixels [tx, tx + 4) x [ty, ty + 4) of `g`, which must already hold them.
  void shade_tile(const GBuffer& g, int tx, int ty, Scratch& scratch);
  void shade_tile(const GBuffer& g, int tx, int ty) {
    Scratch scratch;
    shade_tile(g, tx, ty, scratch);
  }
  // The image, once every tile of `g` is shaded: the soft lights'
  // visibility filtered, then added.
  engine::image::ImageRGB take(const GBuffer& g, RealtimeDirectStats* stats = nullptr);

  // Batched shadow rays (a GPU tracer): a first pass over the tiles with
  // `collect` set only gathers each tile's shadow rays into (*collect)[tile];
  // a second pass with `distances` set shades, reading tile t's answers
  // (the distance to the first hit, infinity for none) from
  // distances[first[t]] on, in the order the first pass gathered them.
  // Or one pass with `view` set: the answers the device traced with the
  // camera's view for view_shadow_request (render/view_shadows.h's layout).
  struct Batch {
    std::vector<std::vector<engine::rt::Ray>>* collect = nullptr;
    const std::vector<float>* distances = nullptr;
    const std::vector<std::size_t>* first = nullptr;
    const std::vector<float>* view = nullptr;
  };
  void set_batch(const Batch& batch) { batch_ = batch; }

 private:
  const engine::rt::RtScene& scene_;
  const engine::render::LightSet& lights_;
  const engine::render::CameraRays& camera_;
  engine::image::ImageRGB out_;
  std::size_t n_lights_ = 0;
  glm::ivec2 pattern_shift_{0};  // disk_pattern_shift(pattern_phase)
  std::vector<std::array<engine::render::LightSample, kDiskPatternCells>> directional_;
  std::vector<std::uint8_t> is_directional_;
  // A directional light with a disk: per pixel, how far along the pixel's
  // pattern direction the first blocker is (infinity: lit; NaN: the light
  // does not reach this pixel at all). take() adds the BRDF along the
  // disk's centre times the filtered visibility.
  struct SoftLight {
    std::size_t light = 0;
    float tan_radius = 0.0f;
    engine::render::LightSample centre;
    std::unique_ptr<float[]> blocker;  // width x height, written by the tiles
  };
  std::vector<SoftLight> soft_;
  std::vector<int> soft_of_;  // per punctual light: its index in soft_, or -1
  // Shadow rays per 4x4 tile, summed by take(): one shared counter added to
  // by every tile is a cache line bouncing between the cores all frame.
  std::vector<std::uint32_t> rays_per_tile_;
  std::atomic<std::size_t> nonfinite_{0};  // rare: only a bad pixel adds
  std::atomic<std::size_t> untraced_{0};   // rare too
  Batch batch_;
};

// to += from, pixel by pixel (same size), in parallel.
void add_image(engine::image::ImageRGB& to, const engine::image::ImageRGB& from);

// With `tracer` (a GPU backend) the shadow rays of the whole image are the
// answers the device traced with the camera's view, where the G-buffer took
// a view queued with view_shadow_request for these lights and this phase
// (CameraHitTracer::take_view_shadows); else they go to it in one batch.
// Without a tracer, Embree's packets trace them tile by tile.
engine::image::ImageRGB shade_direct_realtime(const GBuffer& g, const engine::rt::RtScene& scene,
                                              const engine::render::LightSet& lights,
                                              const engine::render::CameraRays& camera,
                                              RealtimeDirectStats* stats = nullptr,
                                              engine::rt::RayBatchTracer* tracer = nullptr, int pattern_phase = 0);

// The shadow rays DirectTileShader asks for, as a request a device traces
// with the camera's view: every punctual light, a directional one with its
// 8x8 pattern shifted for `pattern_phase` (the nearest blocker's distance
// where it has a disk), a point or spot light towards its position.
engine::render::ViewShadowRequest view_shadow_request(const engine::render::LightSet& lights, int pattern_phase,
                                                      float offset_scale);

// Before the probes update: the real-time frame's camera view queued on
// `tracer`'s device (CameraHitTracer::queue_camera_hits), so that it is
// drawn with the probe rays' submission rather than one of its own, at the
// jitter the frame will take (taa's next; none where it is disabled) and,
// with `lights`, with the deterministic direct light's shadow rays for the
// pattern phase it will shade with. Only a hint; nothing where the tracer
// is null or cannot rasterise.
void queue_realtime_view(engine::rt::RayBatchTracer* tracer, const engine::rt::RtScene& scene,
                         const engine::render::CameraRays& camera, const engine::render::TemporalAntialiasing& taa,
                         const engine::render::TemporalAaSettings& taa_settings, const engine::render::LightSet* lights);

// The fixed point on [0, 1)^2 that pixel (x, y) uses for disk lights: an
// R2 low-discrepancy sequence over each 8x8 block.
glm::vec2 disk_pattern(int x, int y);
// Directional light `light`'s samples over that pattern: cell i holds the
// sample at disk_pattern(i & 7, i >> 3) (it does not depend on the point).
std::array<engine::render::LightSample, kDiskPatternCells> directional_pattern(const engine::render::LightSet& lights,
                                                                               std::size_t light);
// Phases of the pattern's shift: pixel (x, y) takes disk_pattern(x + s.x,
// y + s.y) in phase k, s = disk_pattern_shift(k). The 16 shifts are the
// even offsets of the 8x8 block, in an order that spreads each run of
// phases, so a pixel visits 16 points of the disk over a cycle. A shift
// moves the pattern as a whole: a filter window 8 or 16 pixels wide still
// holds every point once, so the widest penumbrae do not change with it.
inline constexpr int kDiskPatternPhases = 16;
glm::ivec2 disk_pattern_shift(int phase);

// The soft shadow's filter. blocker: per pixel of `g`, the distance to what
// blocks its pattern ray (infinity: lit; NaN: not a receiver). Returns per
// pixel the fraction of lit receivers around it on its own surface (a
// normal within ~25 degrees, within 2 % of its depth of its plane) in a
// square whose half-width is the penumbra's on screen (the blockers'
// harmonic mean distance over the 16x16 pixels around it x tan_radius over
// the pixel's footprint): a box of 8 or 16 pixels, which holds every point
// of the 8x8 pattern, where the penumbra is 4 pixels wide or more, one no
// wider than it where narrower.
// `out` has one value per pixel of `blocker`; every one is written.
void penumbra_filter(const GBuffer& g, std::span<const float> blocker, float tan_radius, float pixel_spread,
                     std::span<float> out);

}  // namespace transgi::shading
