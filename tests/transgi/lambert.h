#pragma once
// A plain Lambertian material (no specular layer) for test scenes.
#include "engine/material/material.h"

inline engine::material::Material lambert(glm::vec3 albedo) {
  engine::material::Material m;
  m.base_color_factor = glm::vec4(albedo, 1);
  m.metallic_factor = 0;
  m.roughness_factor = 1;
  m.specular_factor = 0;
  return m;
}
