#pragma once
// Light as SH coefficients (25 per RGB channel), laid out [c * 25 + k] like
// the transfer, so shading is one dot product per channel.
#include <array>

#include <glm/glm.hpp>

#include "engine/math/sh.h"
#include "engine/scene/environment.h"

namespace transgi::shading {

using ShRgb = std::array<float, 3 * engine::math::kShCount>;

// Projects the environment's radiance onto the SH basis (world space), by
// summing every texel with its solid angle in double precision.
ShRgb project_environment(const engine::scene::Environment& env);

// Coefficients of the same light seen in an object's frame: if the object's
// rotation is R (object to world), L_obj(d) = L_world(R d).
ShRgb rotate_to_object(const ShRgb& world, const glm::quat& object_rotation);

// sum_c sum_k light[c][k] * transfer[c][k], per channel.
glm::vec3 shade(const ShRgb& light, const float* transfer);

// Irradiance E(n) from radiance SH [c * 25 + k] (clamped-cosine
// convolution, Ramamoorthi and Hanrahan 2001), clamped at zero.
glm::vec3 sh_irradiance(const float* radiance_sh, const glm::vec3& normal);

}  // namespace transgi::shading
