#pragma once
// Scene components created by the glTF importer (and by game code).
#include <cstdint>
#include <string>

#include <glm/glm.hpp>

namespace engine::scene {

struct Name {
  std::string value;
};

// An instance of SceneAssets::meshes[mesh], placed by the entity's WorldTransform.
struct MeshInstance {
  std::uint32_t mesh = 0;
};

// Perspective camera looking down its local -Z, +Y up (glTF convention).
struct Camera {
  float yfov_radians = 0.8f;
  float aspect_ratio = 0.0f;  // 0 = use the output image's aspect
  float znear = 0.01f;
  float zfar = 0.0f;          // 0 = infinite
};

// KHR_lights_punctual. Lights shine down their local -Z.
struct PunctualLight {
  enum class Type : std::uint8_t { Point, Spot, Directional };
  Type type = Type::Point;
  glm::vec3 color{1.0f};
  float intensity = 1.0f;  // candela (point, spot) or lux (directional)
  float range = 0.0f;      // 0 = infinite
  float inner_cone_angle = 0.0f;
  float outer_cone_angle = 0.7853982f;
  // Directional only: the angular radius (radians) of the source's disk, as
  // a sun has (the real sun's is 0.0047; the sample level's painted sun's
  // 0.045). Higher = softer shadow edges, at the cost of their sharpness;
  // 0 = a delta light. glTF: the light's extras.angular_radius, which
  // KHR_lights_punctual has no field for.
  float angular_radius = 0.0f;
  bool enabled = true;
};

}  // namespace engine::scene
