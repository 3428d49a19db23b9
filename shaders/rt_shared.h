// Ray-tracing structs shared by the engine's C++ (engine/gpu/gpu_rt_scene)
// and GLSL (rt_traversal.glsl): a two-level BVH, the instances and the query
// records. Same rules as transgi_shared.h: 32-bit scalars only, padded by
// hand to 16 bytes, offsets checked by static_assert on the C++ side.
#ifndef RT_SHARED_H
#define RT_SHARED_H

#ifdef __cplusplus
#include <cstddef>
#include <cstdint>
namespace engine::gpu {
using uint = std::uint32_t;
#define RT_CONST inline constexpr
#else
#define RT_CONST const
#endif

RT_CONST uint kRtStackSize = 64u;  // per query; a SAH tree of 4 M leaves is about 40 deep per level
RT_CONST uint kRtGroupSize = 64u;
RT_CONST uint kRtNoHit = 0xffffffffu;

// One BVH node, BLAS or TLAS. count == 0: an interior node whose children are
// nodes first and first + 1; else a leaf of `count` items from `first`
// (triangles of the mesh, or instances).
struct BvhNodeGpu {
  float min_x, min_y, min_z;
  uint first;
  float max_x, max_y, max_z;
  uint count;
};

// A triangle in leaf order: its three corners in object space and the
// mesh's own index of it (the primitive id a hit reports). alpha_material:
// kRtOpaque, or the RtAlphaMaterialGpu whose cut-out it is tested against.
struct TriangleGpu {
  float p0_x, p0_y, p0_z;
  uint primitive;
  float p1_x, p1_y, p1_z;
  uint alpha_material;
  float p2_x, p2_y, p2_z, pad0;
};

RT_CONST uint kRtOpaque = 0xffffffffu;

// Alpha-masked materials (glTF alphaMode MASK), tested at every candidate
// hit as Embree's filter does (RtScene, alpha_passes): alpha = factor x the
// texture's nearest texel alpha (when it has one and the mesh has UVs),
// kept where alpha >= cutoff.
struct RtAlphaMaterialGpu {
  float alpha;       // base_color_factor.a
  float cutoff;
  int texture;       // RtAlphaTextureGpu index, -1 = none
  uint pad0;
};

struct RtAlphaTextureGpu {
  uint offset;       // first byte in the alpha bytes (4 a uint)
  int width, height;
  uint wrap;         // wrap_s | wrap_t << 8 (scene::Wrap: 0 repeat, 1 clamp, 2 mirrored)
};

// A masked triangle's texture coordinates (in leaf order, like TriangleGpu).
struct RtTriangleUvGpu {
  float u0, v0, u1, v1;
  float u2, v2;
  uint has_uv, pad0;
};

// World to object space for a similarity (rotation, uniform scale,
// translation) as a 3 x 4 matrix, rows r0..r2: a ray keeps its t.
struct InstanceGpu {
  float r0_x, r0_y, r0_z, r0_w;
  float r1_x, r1_y, r1_z, r1_w;
  float r2_x, r2_y, r2_z, r2_w;
  uint blas_root;        // node index of the mesh's BLAS root
  uint triangle_offset;  // of the mesh's triangles in the triangle buffer
  uint id;               // RtScene instance id (Hit::instance)
  uint mesh;             // SceneAssets mesh index
};

struct RayGpu {
  float origin_x, origin_y, origin_z, tmin;
  float dir_x, dir_y, dir_z, tmax;
};

struct HitGpu {
  float t, u, v;
  uint instance;  // kRtNoHit: missed
  uint primitive, mesh, pad0, pad1;
};

#ifdef __cplusplus
static_assert(sizeof(BvhNodeGpu) == 32 && offsetof(BvhNodeGpu, first) == 12 && offsetof(BvhNodeGpu, count) == 28,
              "BvhNodeGpu layout");
static_assert(sizeof(TriangleGpu) == 48 && offsetof(TriangleGpu, primitive) == 12 && offsetof(TriangleGpu, alpha_material) == 28 &&
              offsetof(TriangleGpu, p2_x) == 32, "TriangleGpu layout");
static_assert(sizeof(RtAlphaMaterialGpu) == 16 && sizeof(RtAlphaTextureGpu) == 16 && sizeof(RtTriangleUvGpu) == 32 &&
              offsetof(RtTriangleUvGpu, has_uv) == 24, "alpha-test records");
static_assert(sizeof(InstanceGpu) == 64 && offsetof(InstanceGpu, blas_root) == 48 && offsetof(InstanceGpu, mesh) == 60,
              "InstanceGpu layout");
static_assert(sizeof(RayGpu) == 32 && offsetof(RayGpu, dir_x) == 16, "RayGpu layout");
static_assert(sizeof(HitGpu) == 32 && offsetof(HitGpu, instance) == 12, "HitGpu layout");
}  // namespace engine::gpu
#endif

#endif  // RT_SHARED_H
