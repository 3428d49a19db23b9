#pragma once
// The real-time frame's reflections (shade_gi_realtime's last stage): metals
// by one ray a pixel, glossy dielectrics by one ray a 2x2 block at most,
// filtered over their plane and kept over frames. Internal to the shading
// module: realtime_gi.cpp calls these and holds their state.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "engine/image/image.h"
#include "engine/render/camera_rays.h"
#include "engine/render/light_set.h"
#include "engine/rt/rt_scene.h"
#include "probes/probe_field.h"
#include "shading/realtime_gi.h"
#include "shading/transfer_renderer.h"

namespace transgi::shading {

// The directional albedo of a dielectric's specular layer towards the
// viewer, per channel: the mean weight of its reflection rays.
glm::vec3 specular_layer_albedo(const GSample& s);

// Per pixel, a reflection's light over its last frames: a running mean over
// up to kFrames frames, found where the previous camera saw the same surface
// point (nearest pixel, within 3 pixels' footprint), as engines keep a
// reflection history apart from the antialiasing's, which averages only
// still views: one frame's rays alone leave a glossy surface mottled in
// motion. A frame is begin(), blend() once per reflective pixel (from any
// thread), end().
class ReflectionHistory {
 public:
  static constexpr int kFrames = 8;

  void begin(const GBuffer& g);
  // Pixel p's light this frame in, its running mean out.
  void blend(const GBuffer& g, std::size_t p, glm::vec3& direct, glm::vec3& gi);
  void end() { current_ ^= 1; }
  // A camera cut: the next frame takes nothing from this one.
  void forget() {
    for (Frame& f : frames_) f.camera.reset();
  }

 private:
  struct Frame {
    int width = 0, height = 0;
    glm::vec2 jitter{0.0f};
    std::optional<engine::render::CameraRays> camera;
    std::vector<std::uint8_t> frames;  // 0 = no reflection here
    std::vector<glm::vec3> position, direct, gi;
  };
  Frame frames_[2];
  int current_ = 0;
  bool has_prev_ = false;
  float spread_ = 0.0f;
};

// The glossy dielectrics' reflection rays of a frame, one per 2x2 block of
// pixels at most (shade_dielectric_reflections), kept from frame to frame
// for their storage.
constexpr std::uint32_t kNoRay = UINT32_MAX;
struct DielectricRays {
  std::vector<std::size_t> glossy;           // the glossy dielectric pixels
  std::vector<glm::vec3> glossy_albedo;      // per glossy pixel: its specular layer's albedo (specular_layer_albedo)
  int bw = 0, bh = 0;                        // blocks per row and column
  std::vector<std::uint32_t> ray_of_block;   // per block: its ray, or kNoRay
  std::vector<std::size_t> traced;           // per ray: its block
  std::vector<std::size_t> ray_pixel;        // per ray: the pixel it left from
  std::vector<int> ray_x, ray_y;             // per ray: that pixel's column and row
  std::vector<glm::vec3> direction;          // per ray: where it goes
  std::vector<glm::vec3> weight;             // per ray: F G1 over its pixel's specular layer's albedo
  std::vector<glm::vec3> direct, gi;         // per ray: the light it found, times its weight
  std::vector<glm::vec3> mean_direct, mean_gi;  // per ray: its neighbourhood's mean (gather_rays)
  std::vector<std::uint8_t> has_mean;
  // choose_dielectric_rays' lists per row of 4x4 tiles, before they are joined.
  struct Row {
    std::vector<std::size_t> glossy, ray_pixel;
    std::vector<glm::vec3> glossy_albedo, direction, weight;
  };
  std::vector<Row> rows;
  // The glossy pixels' filtered light over their last frames.
  ReflectionHistory history;

  [[nodiscard]] std::size_t block_of(std::size_t p, std::size_t width) const {
    return p / width / 2 * static_cast<std::size_t>(bw) + p % width / 2;
  }
};

// Metals' reflections at full resolution (transfer_renderer.h's MirrorRay):
// a metal's whole light, replacing its decoded GI (its direct light was left
// out of the composite); the sky and emitters its ray sees go to direct_out.
std::size_t shade_metal_reflections(const GBuffer& g, const engine::rt::RtScene& scene,
                                   std::span<const probes::ProbeField* const> fields, const MirrorRay& mirror,
                                   const engine::render::LightSet* lights, engine::image::ImageRGB& image,
                                   engine::image::ImageRGB* direct_out);

// Glossy dielectrics' specular layer (MirrorRay::dielectric_max_roughness),
// added to the diffuse light their cells were given. A floor can fill half
// the screen, so a quarter of its pixels trace a ray a frame
// (trace_dielectric_rays), each ray gathers its neighbours' (gather_rays),
// and every glossy pixel takes the rays' means around it on its own plane,
// times its own specular albedo; the antialiasing's 16 phases average the
// rest. Work in proportion to the glossy pixels, none without.
std::size_t shade_dielectric_reflections(const GBuffer& g, const engine::rt::RtScene& scene,
                                  std::span<const probes::ProbeField* const> fields, const engine::render::LightSet* lights,
                                  float max_roughness, DielectricRays& rays, engine::image::ImageRGB& image,
                                  engine::image::ImageRGB* direct_out);

}  // namespace transgi::shading
