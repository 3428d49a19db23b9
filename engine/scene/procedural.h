#pragma once
// Procedural meshes for tests, test scenes and the content generator.
#include "engine/scene/mesh_asset.h"

namespace engine::scene {

// UV sphere with analytic normals; `segments` around, `rings` pole to pole.
MeshAsset make_uv_sphere(float radius, int segments, int rings, std::uint32_t material = 0);
// Axis-aligned box centred at the origin with half extents `half`. Normals
// point outward, or inward when `inward` (a room seen from inside).
MeshAsset make_box(glm::vec3 half, bool inward = false, std::uint32_t material = 0);
// Torus around +Y: `major` radius of the ring, `minor` of the tube.
MeshAsset make_torus(float major, float minor, int segments, int sides, std::uint32_t material = 0);
// Open cylinder (a tube) along +Y from y = 0 to `height`, outward normals,
// with its top radius scaled by `taper` (taper < 1 gives a cone-like spout).
MeshAsset make_tube(float radius, float height, int segments, float taper = 1.0f, std::uint32_t material = 0);
// Appends `b` to `a` (vertices re-indexed).
void append_mesh(MeshAsset& a, const MeshAsset& b);
// Quad in the XZ plane centred at the origin, normal +Y, UVs 0..1.
MeshAsset make_quad(glm::vec2 half, std::uint32_t material = 0);

}  // namespace engine::scene
