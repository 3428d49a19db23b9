#pragma once
// The real-time GI path (issue 10, items 2-4):
//  1. a G-buffer of one ray through each pixel centre (deterministic);
//  2. GI decoded for a subset of pixels: one per cell of a grid at
//     `resolution_scale` of the output, plus every pixel that no cell sample
//     represents (silhouettes, thin objects), so GI never bleeds across
//     edges;
//  3. the probes' SH rotated into each moved object's frame once per frame
//     (interpolation is linear, so this equals rotating every pixel's light),
//     then per pixel: probe interpolation and the fused decoder + SH dot;
//  4. a joint bilateral upsample (bilinear x depth x normal weights) to the
//     output resolution.
// The reference for it is render_transfer (every pixel decoded, per-pixel
// rotation, batched inference); tests compare the two.
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "engine/image/image.h"
#include "engine/render/camera_rays.h"
#include "model/transfer_model.h"
#include "probes/probe_field.h"
#include "shading/fused_decoder.h"
#include "shading/transfer_batch_decoder.h"
#include "shading/gbuffer.h"
#include "shading/near_field.h"
#include "shading/transfer_renderer.h"

namespace transgi::shading {

class DirectTileShader;

struct RealtimeGiSettings {
  // GI is decoded on a grid this fraction of the output size per axis.
  // Higher = finer GI detail inside surfaces, at the cost of inference time
  // (quadratic in it). 1 = every pixel decoded.
  float resolution_scale = 0.5f;
  // Depth similarity: a grid sample's weight is max(0, 1 - (dz / (tol z))^2),
  // zero past tol of the pixel's depth. Higher = smoother GI across depth
  // steps, at the cost of bleeding across silhouettes.
  float depth_tolerance = 0.05f;
  // Normal similarity: weight x max(0, n . n_sample)^power. Higher = sharper
  // GI at creases, at the cost of more pixels decoded on their own.
  int normal_power = 8;
  // A pixel whose grid samples weigh less than this in total (of 1) is
  // decoded on its own. Lower = fewer extra decodes, at the cost of GI taken
  // from barely similar samples.
  float min_weight = 0.05f;
  // Off = plain bilinear upsampling (only to show what the guidance prevents).
  bool edge_aware = true;
  // On = each frame decodes one colour of a checkerboard of grid cells that
  // swaps every frame, and the other colour takes the previous frame's value
  // of the same surface point, carried through camera and object motion
  // (gi_history.h): about half the inference and light time, at the cost of
  // GI up to one frame late on those cells. Needs the scratch that carries
  // history from frame to frame; without it, or with the near field on,
  // every cell is decoded.
  bool reuse_history = false;
  // With reuse_history and the CPU's fused decoder (not a batch decoder): a
  // cell keeps the transfer it decoded (the network's 75 values, which
  // depend on the surface point and the view direction in its object's
  // frame, not on the light) for up to this many frames, and on the frames
  // its colour comes round only dots it with this frame's light; it decodes
  // again when its point leaves the footprint where the transfer was
  // decoded, the view turns past transfer_view_degrees, or the transfer
  // expires (gi_history.h). Higher = fewer decodes, at the cost of transfer
  // held at one sub-pixel position (the antialiasing jitter does not refine
  // it) for longer. 0 = every cell of the colour decoded.
  int transfer_max_age = 0;
  // How far the view direction at a point, in its object's frame, may turn
  // before its kept transfer is decoded again. Higher = fewer decodes under
  // a moving camera or object, at the cost of glossy transfer seen from up
  // to this angle off.
  float transfer_view_degrees = 2.0f;
  // With a batch decoder that can (a GPU's: ProbeLightMaker), the network
  // samples' lights are interpolated from the probes on its device, and only
  // a sample's position, normal and rotation cross the bus instead of 150
  // floats of light. On = 32 bytes a sample instead of 600, at the cost of
  // uploading the probes' depth maps and SH each frame.
  bool device_lights = true;

  bool operator==(const RealtimeGiSettings&) const = default;
};

struct GBuffer {
  int width = 0, height = 0;
  std::vector<GSample> samples;  // row-major, pixel (0, 0) top-left
  // Per pixel: world normal (xyz) and depth (w; 0 = no hit), what the
  // upsampling compares; written by trace_gbuffer. 16 bytes a pixel instead
  // of a whole GSample keeps those passes in cache.
  std::vector<glm::vec4> guide;
  // Per pixel: the base colour hit (0 for a miss): the real-time GI is
  // upsampled divided by it and multiplied back per pixel, so a texture
  // keeps its full-resolution detail; written by trace_gbuffer.
  std::vector<glm::vec3> albedo;
  // Per pixel: the world position hit (0 for a miss), for the soft
  // shadows' same-surface test (realtime_direct.h); written by trace_gbuffer.
  std::vector<glm::vec3> position;
  // Per pixel: the surface's roughness where it is metallic (>= 0.5), else
  // infinity (misses too), so the mirror pass finds its pixels in 4 bytes a
  // pixel rather than reading every GSample's material; written by trace_gbuffer.
  std::vector<float> metal_roughness;
  // Per pixel: the roughness of a non-metal with a specular layer
  // (specular > 0), else infinity: the glossy dielectrics of MirrorRay.
  std::vector<float> dielectric_roughness;
  // Per 4x4 tile ((width + 3) / 4 a row): the least dielectric_roughness in
  // it, so a pass over the glossy dielectrics skips the tiles without one.
  std::vector<float> tile_dielectric_roughness;
  // Per pixel: the entity hit (null for a miss), so routing samples by object
  // reads 8 bytes a pixel rather than a GSample; written by trace_gbuffer.
  std::vector<engine::ecs::Entity> entity;
  // The sub-pixel offset its rays were traced with (film = pixel + 0.5 + jitter).
  glm::vec2 jitter{0.0f};
  // The camera the G-buffer was traced from (trace_gbuffer), so the next
  // frame can find where a surface point was seen (gi_history.h).
  std::optional<engine::render::CameraRays> camera;
  // A GPU backend's batch (trace_gbuffer with a tracer), kept between frames
  // so 1080p's 2 M rays and hits are not allocated and zeroed every frame.
  struct Batch {
    std::vector<engine::rt::Ray> rays;
    std::vector<engine::rt::Hit> hits;
    std::vector<std::uint8_t> found;
    std::vector<std::size_t> tile_first;
  } batch;
};

// One ray through each pixel centre, in parallel over rows.
GBuffer trace_gbuffer(const engine::rt::RtScene& scene, const engine::scene::SceneAssets& assets,
                      const engine::render::CameraRays& camera, int width, int height);
// The same into `g`, reusing its storage (a frame loop keeps one G-buffer:
// 230,400 samples are tens of MB to fault in afresh every frame). With
// `direct`, each 4x4 tile is also shaded by it as soon as it is traced, while
// its samples are in cache (realtime_direct.h). With `tracer` (a GPU
// backend), every camera ray is traced by it in one batch first; Embree's
// packets trace them where it declines. `jitter` moves every ray off the
// pixel centre by that many pixels (temporal antialiasing, [-0.5, 0.5)).
// Textures are read `texture_lod_bias` mip levels off the pixel's footprint
// (TemporalAaSettings::texture_lod_bias_in_use()).
void trace_gbuffer(const engine::rt::RtScene& scene, const engine::scene::SceneAssets& assets,
                   const engine::render::CameraRays& camera, int width, int height, GBuffer& g,
                   DirectTileShader* direct = nullptr, engine::rt::RayBatchTracer* tracer = nullptr,
                   glm::vec2 jitter = glm::vec2(0.0f), float texture_lod_bias = 0.0f);

// Buffers the real-time path keeps from frame to frame: at 640x360 they are
// tens of MB that would otherwise be faulted in and zeroed every frame.
struct RealtimeGiScratch {
  struct Impl;
  std::unique_ptr<Impl> impl;
  RealtimeGiScratch();
  ~RealtimeGiScratch();
  RealtimeGiScratch(RealtimeGiScratch&&) noexcept;
  RealtimeGiScratch& operator=(RealtimeGiScratch&&) noexcept;
  // A camera cut: the next frame takes nothing from the frames before (the
  // GI reuse's cells, the glossy reflections' history); storage is kept.
  void forget_histories();
  // Last frame's GI image, handed back so the next one reuses its storage:
  // the upsampling writes every pixel, so nothing is cleared (clearing a
  // 640x360 image was serial time in the frame).
  void recycle(engine::image::ImageRGB&& image);
};

struct RealtimeGiStats {
  double rotate_ms = 0;     // probe SH into moved objects' frames
  double light_ms = 0;      // probe interpolation per decoded pixel
  double inference_ms = 0;  // latent gather, inputs, fused decoder + SH dot
  double inference_device_ms = 0;  // the batch decoder's own time (a GPU's timestamps), when one decoded
  double upsample_ms = 0;   // choosing samples, joint bilateral upsampling
  double reflect_ms = 0;    // reflection rays of metals and glossy dielectrics, their filter
  double near_ms = 0;       // near-field rays on the decoded grid (off in the real-time preset)
  std::size_t grid_samples = 0, edge_samples = 0;  // decoded: on the grid, on their own
  std::size_t reused_cells = 0;                     // grid cells that took the previous frame's value
  std::size_t inferred = 0, diffuse = 0;           // of those: through the network, diffuse fallback
  std::size_t kept_transfers = 0;                   // of the network's: lit with a kept transfer, not decoded
  std::size_t rotations = 0;                        // distinct object rotations this frame
  // Decoded samples whose GI came out non-finite (a NaN latent or weight, an
  // overflowing light) and were set to zero before upsampling.
  std::size_t nonfinite_samples = 0;
  std::size_t reflection_rays = 0;                 // metals' (one a pixel) and glossy dielectrics' (one a 2x2 block at most)
};

// What one real-time GI frame reads. Entities for which has_transfer is
// false, or all of them if model or decoder is null, are shaded diffusely:
// albedo / pi x irradiance. With near_field.rays > 0, each decoded grid cell
// also gets the near field's contact light (near_field.h; mirror_lights light
// its hits), filtered over the grid; edge pixels decoded on their own do not.
// With batch_decoder (a GPU backend's kernel) the network samples are decoded
// by it in one batch instead of by `decoder` tile by tile. Unless
// mirror.max_roughness < 0, metals and glossy dielectrics reflect by rays
// (MirrorRay): a metal's GI is its ray's, a glossy dielectric's is its
// diffuse light from the probes plus its filtered rays'; the sky and
// emitters those rays see, and not the probes' direct SH through their
// transfer, are their direct light.
struct RealtimeGiRequest {
  const GBuffer& gbuffer;
  const engine::rt::RtScene& scene;
  const engine::scene::SceneAssets& assets;
  // A point takes the first field whose grid holds it, else the first.
  std::span<const probes::ProbeField* const> fields;
  RealtimeGiSettings settings{};
  const model::TransferModel* model = nullptr;
  const FusedDecoder* decoder = nullptr;
  std::function<bool(engine::ecs::Entity)> has_transfer{};
  TransferBatchDecoder* batch_decoder = nullptr;
  const engine::render::LightSet* mirror_lights = nullptr;
  MirrorRay mirror{};
  NearFieldRays near_field{};
};

// Where a real-time GI frame writes besides its image; each may be null.
// With direct, the probes' direct sky and emitter light goes through the
// same transfer (or irradiance) and upsampling and is added to it (an image
// of the G-buffer's size holding the rest of the direct light, or else made
// one of zeros): the real-time direct light from everything but punctual
// lights and the split sun (see realtime_direct.h). scratch keeps storage
// and the histories (the GI reuse's, the reflections') from frame to frame.
struct RealtimeGiOutputs {
  RealtimeGiStats* stats = nullptr;
  engine::image::ImageRGB* direct = nullptr;
  RealtimeGiScratch* scratch = nullptr;
};

// The GI image, of the G-buffer's size.
engine::image::ImageRGB shade_gi_realtime(const RealtimeGiRequest& request, const RealtimeGiOutputs& out = {});

}  // namespace transgi::shading
