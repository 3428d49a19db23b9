#pragma once
// Splits a bright sun out of a lat-long environment map, so a real-time
// renderer can shade it as a directional light (one shadow ray) and leave
// only the smooth remainder of the sky to its probes.
//
// What holds after split_sun: for every pixel of the map, residual pixel +
// (the sun's share of it) = the original pixel, so the sun's irradiance plus
// the residual's irradiance equals the original map's on any surface whose
// horizon does not cut the disk. The sun's direction is the disk's
// power-weighted mean direction and its angular radius that of a cone of the
// disk's solid angle, which keeps the penumbra width.
#include <optional>

#include "engine/scene/environment.h"

namespace engine::scene {

struct ExtractedSun {
  glm::vec3 direction{0.0f, 1.0f, 0.0f};  // world, unit, from the scene towards the sun
  glm::vec3 irradiance{0.0f};             // W/m^2 on a surface facing the sun (strength included)
  float solid_angle = 0.0f;               // of the disk, sr
  float angular_radius = 0.0f;            // of a cone of that solid angle, radians
  int pixels = 0;                         // map pixels the disk covered
};

struct SunExtractionSettings {
  // A pixel is a sun candidate when its luminance is this many times the
  // map's median. Higher = only sharper, brighter suns are split out, at the
  // cost of leaving a bright sky spot for the probes to carry.
  float peak_to_median = 100.0f;
  // Largest disk split out (sr). Higher = broad glows count as a sun too, at
  // the cost of a blurrier sun shadow than the map implies. 0.03 sr is a
  // 5.6 degree radius.
  float max_solid_angle = 0.03f;
};

struct SunSplit {
  std::optional<ExtractedSun> sun;  // none: the map holds no sun; residual is the map itself
  Environment residual;
};

// Pure: reads env, returns the sun and the residual map (same size, strength
// and matrix as env).
SunSplit split_sun(const Environment& env, const SunExtractionSettings& settings = {});

}  // namespace engine::scene
