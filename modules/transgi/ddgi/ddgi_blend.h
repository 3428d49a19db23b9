#pragma once
// DDGI's per-probe blending (RTXGI's ProbeBlendingCS and ProbeBorderUpdate):
// a frame's ray records into a probe's octahedral irradiance and distance
// maps with hysteresis. The CPU statement that DdgiVolume::update runs and
// that the Vulkan kernel (shaders/ddgi_blend.comp) is tested against.
#include <vector>

#include <glm/glm.hpp>

#include "ddgi/ddgi_volume.h"
#include "ddgi/octahedral.h"

namespace transgi::ddgi {

// One probe ray's result: distance < 0 marks a back-face hit (RTXGI stores
// them negative and shortened), a miss is far (1e27).
struct RayRecord {
  glm::vec3 direction;
  glm::vec3 radiance;
  float distance;
};

// Irradiance, gamma-encoded E / (2 pi): cosine-weighted mean radiance per
// texel, blended with hysteresis (lowered for darkening texels, the step
// clamped when clamp_brightness), borders refreshed. A probe with too many
// back-face rays keeps its map.
void blend_irradiance(OctahedralMap<glm::vec3>& map, const std::vector<RayRecord>& rays, const DdgiSettings& s, float hysteresis,
                      bool clamp_brightness);
// Distance mean and mean square, power-cosine weighted, clamped to
// max_distance, blended with hysteresis, borders refreshed.
void blend_distance(OctahedralMap<glm::vec2>& map, const std::vector<RayRecord>& rays, const DdgiSettings& s,
                    float max_distance, float hysteresis);

}  // namespace transgi::ddgi
