#pragma once
// glTF 2.0 metallic-roughness material, with KHR_materials_emissive_strength
// and KHR_materials_specular (factor and colour).
#include <cmath>
#include <cstdint>
#include <string>

#include <glm/glm.hpp>

namespace engine::material {

inline constexpr std::int32_t kNoTexture = -1;

enum class AlphaMode : std::uint8_t { Opaque, Mask, Blend };

struct Material {
  std::string name;
  glm::vec4 base_color_factor{1.0f};
  std::int32_t base_color_texture = kNoTexture;  // sRGB, alpha in .a
  float metallic_factor = 1.0f;
  float roughness_factor = 1.0f;
  std::int32_t metallic_roughness_texture = kNoTexture;  // linear: G = roughness, B = metallic
  glm::vec3 emissive_factor{0.0f};
  float emissive_strength = 1.0f;
  std::int32_t emissive_texture = kNoTexture;  // sRGB
  float specular_factor = 1.0f;               // KHR_materials_specular
  glm::vec3 specular_color_factor{1.0f};
  AlphaMode alpha_mode = AlphaMode::Opaque;
  float alpha_cutoff = 0.5f;
  bool double_sided = false;

  [[nodiscard]] glm::vec3 emission() const { return emissive_factor * emissive_strength; }
  [[nodiscard]] bool is_emissive() const {
    const glm::vec3 e = emission();
    return e.r > 0 || e.g > 0 || e.b > 0;
  }
  // Whether any texture is read; if not, a texture footprint changes nothing.
  [[nodiscard]] bool is_textured() const {
    return base_color_texture != kNoTexture || metallic_roughness_texture != kNoTexture || emissive_texture != kNoTexture;
  }
  // Whether its colour is a texture or a hue rather than a grey: the surfaces
  // where GI must keep a texture's detail and colour (issue 37's colour
  // measure). A hue: the base colour's chromaticity rgb / (r + g + b) lies
  // more than 0.1 (L1) from grey's (1/3, 1/3, 1/3); a cream wall (0.8, 0.75,
  // 0.6) is just past it (0.109), an orange desk (0.6, 0.3, 0.1) far past it (0.53).
  [[nodiscard]] bool is_textured_or_coloured() const {
    if (base_color_texture != kNoTexture) return true;
    const float sum = base_color_factor.r + base_color_factor.g + base_color_factor.b;
    if (!(sum > 0)) return false;
    const glm::vec3 c = glm::vec3(base_color_factor) / sum;
    return std::abs(c.r - 1.0f / 3) + std::abs(c.g - 1.0f / 3) + std::abs(c.b - 1.0f / 3) > 0.1f;
  }
};

}  // namespace engine::material
