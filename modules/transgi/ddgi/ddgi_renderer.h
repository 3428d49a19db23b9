#pragma once
// DDGI's indirect diffuse at every pixel: a filtered primary ray per sample
// (as TransGI's G-buffer), then diffuse albedo / pi x the volume's irradiance
// at the hit. Glossy indirect light is not DDGI's to give.
#include <span>

#include "ddgi/ddgi_kernels.h"
#include "ddgi/ddgi_volume.h"
#include "engine/image/image.h"
#include "engine/render/camera_rays.h"
#include "shading/realtime_gi.h"
#include "shading/upsampling.h"

namespace transgi::ddgi {

// Irradiance from several volumes (authored ones, then cascades finest
// first), blended as probes::mix_at says; a volume with no active probe
// around the point hands it to the next one holding it. With one volume,
// exactly its DdgiVolume::irradiance.
glm::vec3 irradiance_from(std::span<const DdgiVolume* const> volumes, const glm::vec3& position, const glm::vec3& normal,
                          const glm::vec3& view_dir);
// The same blend of the irradiance maps' light (column 0) and the emitted
// maps' (column 1; 0 from a volume without them): DdgiKernels::irradiance
// on the CPU, point by point.
glm::mat2x3 irradiance_and_emitted_from(std::span<const DdgiVolume* const> volumes, const glm::vec3& position,
                                        const glm::vec3& normal, const glm::vec3& view_dir);
// The blend of irradiance_from over values a backend looked up per volume,
// all points of volume v at once: value[v][k] and lit[v][k] are volume v's
// DdgiVolume::irradiance at point k (column 1: its emitted maps').
void mix_volume_batches(std::span<const DdgiVolume* const> volumes, std::span<const glm::vec3> positions,
                        const std::vector<std::vector<glm::mat2x3>>& value, const std::vector<std::vector<std::uint8_t>>& lit,
                        std::span<glm::mat2x3> out);

// The offline GI pass on the CPU (CpuDdgiKernels::render_gi): each sample's
// ray traced and its surface lit point by point.
engine::image::ImageRGB render_ddgi_gi(const engine::rt::RtScene& scene, std::span<const DdgiVolume* const> volumes,
                                       const engine::render::CameraRays& camera, int width, int height,
                                       const DdgiRenderSettings& settings);
// The same pass in batches, for a device backend: every sample's ray through
// `tracer`, the surfaces made on the CPU, every lookup through
// kernels.irradiance. Throws engine::gpu::GpuError where the tracer declines
// the scene (one built without its assets).
engine::image::ImageRGB render_ddgi_gi_batched(const engine::rt::RtScene& scene, std::span<const DdgiVolume* const> volumes,
                                               const engine::render::CameraRays& camera, int width, int height,
                                               const DdgiRenderSettings& settings, engine::rt::RayBatchTracer& tracer,
                                               DdgiKernels& kernels);

// DDGI's light on a real-time G-buffer (one sample per pixel, as TransGI's
// real-time frame traces it): the volumes' irradiance about each surface's
// normal and about its mirror direction, looked up on a grid at
// `upsampling.resolution_scale` of the image (and at every pixel no cell
// represents) and upsampled to each pixel exactly as TransGI's GI is
// (shading/upsampling.h: bilinear x depth x normal weights), then reflected
// by the pixel's own material: its diffuse albedo x (1 - its dielectric
// specular layer's albedo) / pi x the first, the layer's albedo / pi x the
// second (a varnished floor reflects the room, blurred: engines use
// reflection probes there; DDGI has none, and without it the layer's light
// was missing from DDGI's GI). The emitted maps (DdgiSettings::emitted_maps)
// are looked up and upsampled with it: the sky's and the emitters' direct
// light; the punctual lights' is the caller's (shading::DirectTileShader). A
// metal (metallic >= 0.5, as the G-buffer marks it) has little diffuse
// albedo and would be black: it gets its GGX specular albedo x the
// irradiance about its mirror direction / pi at its own pixel. Every lookup
// goes to kernels.irradiance in one batch. `plan` is scratch kept between
// frames.
struct DdgiPixels {
  engine::image::ImageRGB gi;       // from the irradiance maps: indirect light
  engine::image::ImageRGB emitted;  // from the emitted maps (DdgiSettings::emitted_maps): direct light, else 0
};
DdgiPixels shade_ddgi_gbuffer(const shading::GBuffer& g, std::span<const DdgiVolume* const> volumes,
                              const shading::RealtimeGiSettings& upsampling, shading::UpsamplingPlan& plan,
                              DdgiKernels& kernels);

}  // namespace transgi::ddgi
