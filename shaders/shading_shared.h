// Scene shading structs shared by the engine's C++ (engine/gpu/gpu_shading_scene)
// and GLSL (scene_shading.glsl): what a kernel needs to shade a ray hit as
// render::make_surface and render::LightSet do on the CPU (mesh attributes,
// glTF materials, textures, and every light a frame samples). Same rules as
// rt_shared.h: 32-bit scalars only, padded by hand to 16 bytes, offsets
// checked by static_assert on the C++ side.
#ifndef SHADING_SHARED_H
#define SHADING_SHARED_H

#ifdef __cplusplus
#include <cstddef>
#include <cstdint>
namespace engine::gpu {
using uint = std::uint32_t;
#define SHADING_CONST inline constexpr
#else
#define SHADING_CONST const
#endif

SHADING_CONST int kShadingNoTexture = -1;

// A mesh triangle in the mesh's own order (ShadingMeshGpu::first +
// primitive): object-space corners, vertex normals and texture coordinates.
struct ShadingTriangleGpu {
  float p0_x, p0_y, p0_z;
  uint material;
  float p1_x, p1_y, p1_z;
  uint has_uv;
  float p2_x, p2_y, p2_z, pad0;
  float n0_x, n0_y, n0_z, n1_x;
  float n1_y, n1_z, n2_x, n2_y;
  float n2_z, u0, v0, u1;
  float v1, u2, v2, pad1;
};

// An instance by its RtScene id: object to world as t + R (s p).
struct ShadingInstanceGpu {
  float r0_x, r0_y, r0_z, t_x;  // rows of R, then the translation
  float r1_x, r1_y, r1_z, t_y;
  float r2_x, r2_y, r2_z, t_z;
  float scale;
  uint mesh;
  uint live;
  uint pad0;
};

// material::Material as evaluate_material and evaluate_emission read it.
// emission = emissive_factor x emissive_strength.
struct MaterialGpu {
  float base_r, base_g, base_b, base_a;
  float metallic, roughness, specular;
  int base_texture;
  float specular_r, specular_g, specular_b;
  int metallic_roughness_texture;
  float emission_r, emission_g, emission_b;
  int emissive_texture;
  uint double_sided, pad0, pad1, pad2;
};

// Level 0 of a texture: RGBA8 texels packed one to a uint from `first`.
struct TextureGpu {
  uint first;
  int width, height;
  uint wrap;  // wrap_s | wrap_t << 8 (scene::Wrap: 0 repeat, 1 clamp, 2 mirrored) | cut_out << 16
};

// LightSet's emissive triangle i in world space; pdf = its bin's density
// (Distribution1D::pdf), the CDF lives in the light tables.
struct EmissiveTriangleGpu {
  float p0_x, p0_y, p0_z;
  uint material;
  float p1_x, p1_y, p1_z;
  float area;
  float p2_x, p2_y, p2_z;
  float pdf;
  float u0, v0, u1, v1;
  float u2, v2, pad0, pad1;
};

SHADING_CONST uint kPunctualPoint = 0u;  // scene::PunctualLight::Type's order
SHADING_CONST uint kPunctualSpot = 1u;
SHADING_CONST uint kPunctualDirectional = 2u;

struct PunctualLightGpu {
  float position_x, position_y, position_z;
  uint type;
  float direction_x, direction_y, direction_z;  // the way the light shines
  float range;
  float power_r, power_g, power_b;  // colour x intensity
  float angular_radius;
  float cos_inner, cos_outer;
  float pad0, pad1;
};

// The light set's counts and the environment's frame; the environment's
// texels and its alias table (math::AliasDistribution2D: per texel its
// threshold, alias (as float bits), pdf and the alias's pdf) sit in one
// float buffer at these offsets (the emissive triangles' CDF, triangles + 1
// floats, in a buffer of its own).
struct LightSetGpu {
  int groups, has_environment, triangles, punctual;
  int env_width, env_height;
  float env_strength;
  uint pad9;
  uint env_texels;    // width x height x RGB
  uint env_alias;     // width x height x 4
  uint pad10, pad11, pad12;
  uint pad0, pad1, pad2;
  float to_world_r0_x, to_world_r0_y, to_world_r0_z, pad3;  // rows of the map's local-to-world rotation
  float to_world_r1_x, to_world_r1_y, to_world_r1_z, pad4;
  float to_world_r2_x, to_world_r2_y, to_world_r2_z, pad5;
  float to_local_r0_x, to_local_r0_y, to_local_r0_z, pad6;
  float to_local_r1_x, to_local_r1_y, to_local_r1_z, pad7;
  float to_local_r2_x, to_local_r2_y, to_local_r2_z, pad8;
};

// The constant tables: the sRGB decode of a byte, then the GGX albedo
// tables (specular_albedo.cpp: 64 x 64 directional (a, b), 64 averages).
SHADING_CONST uint kShadingSrgbLut = 0u;
SHADING_CONST uint kShadingAlbedoMu = 64u;
SHADING_CONST uint kShadingAlbedoAlpha = 64u;
SHADING_CONST uint kShadingAlbedoDirectional = 256u;
SHADING_CONST uint kShadingAlbedoAverage = 256u + 2u * 64u * 64u;
SHADING_CONST uint kShadingTableFloats = 256u + 2u * 64u * 64u + 2u * 64u;

#ifdef __cplusplus
static_assert(sizeof(ShadingTriangleGpu) == 112 && offsetof(ShadingTriangleGpu, n0_x) == 48 &&
              offsetof(ShadingTriangleGpu, u0) == 84 && offsetof(ShadingTriangleGpu, pad1) == 108,
              "ShadingTriangleGpu layout");
static_assert(sizeof(ShadingInstanceGpu) == 64 && offsetof(ShadingInstanceGpu, scale) == 48, "ShadingInstanceGpu layout");
static_assert(sizeof(MaterialGpu) == 80 && offsetof(MaterialGpu, base_texture) == 28 &&
              offsetof(MaterialGpu, emissive_texture) == 60 && offsetof(MaterialGpu, double_sided) == 64,
              "MaterialGpu layout");
static_assert(sizeof(TextureGpu) == 16, "TextureGpu layout");
static_assert(sizeof(EmissiveTriangleGpu) == 80 && offsetof(EmissiveTriangleGpu, pdf) == 44 &&
              offsetof(EmissiveTriangleGpu, u2) == 64, "EmissiveTriangleGpu layout");
static_assert(sizeof(PunctualLightGpu) == 64 && offsetof(PunctualLightGpu, cos_inner) == 48, "PunctualLightGpu layout");
static_assert(sizeof(LightSetGpu) == 160 && offsetof(LightSetGpu, to_world_r0_x) == 64 &&
              offsetof(LightSetGpu, to_local_r0_x) == 112, "LightSetGpu layout");
}  // namespace engine::gpu
#endif

#endif  // SHADING_SHARED_H
