// The visibility pass's push block (engine/gpu/visibility_pass, shaders
// visibility.vert, visibility.frag, visibility_resolve.comp), shared by C++
// and GLSL. Same rules as rt_shared.h.
#ifndef VISIBILITY_SHARED_H
#define VISIBILITY_SHARED_H

#include "rt_shared.h"

#ifdef __cplusplus
namespace engine::gpu {
#endif

RT_CONST uint kVisibilityGroupSize = 64u;  // resolve invocations per workgroup, one per pixel

// render::CameraRays as the kernels need it: the film point of each pixel is
// (x, y) + sample (the same sub-pixel offset for every pixel, as a
// rasteriser samples), its ray origin + normalize(c0 sx + c1 sy - c2) with
// sx = (2 film.x / width - 1) tan_half_x, sy = (1 - 2 film.y / height) tan_half_y.
struct VisibilityPushGpu {
  float origin_x, origin_y, origin_z, near_plane;  // near_plane: the raster's, in the camera's units
  float c0_x, c0_y, c0_z, tan_half_x;              // the camera's rotation, by columns
  float c1_x, c1_y, c1_z, tan_half_y;
  float c2_x, c2_y, c2_z, pad0;
  float sample_x, sample_y;                        // the film offset in each pixel, in [0, 1)
  uint width, height;
};

// A pixel's hit as the resolve writes it: rt_query.comp's HitGpu without
// the mesh (the instance's record names it) and the padding, 20 bytes
// instead of 32, since every pixel's comes back to the host.
// instance == kRtNoHit: the pixel saw nothing.
struct VisibilityHitGpu {
  float t, u, v;
  uint instance;   // RtScene instance id
  uint primitive;  // the triangle's index in its mesh
};

#ifdef __cplusplus
static_assert(sizeof(VisibilityHitGpu) == 20 && offsetof(VisibilityHitGpu, instance) == 12, "VisibilityHitGpu layout");
static_assert(sizeof(VisibilityPushGpu) == 80 && offsetof(VisibilityPushGpu, c0_x) == 16 &&
              offsetof(VisibilityPushGpu, sample_x) == 64, "VisibilityPushGpu layout");
}  // namespace engine::gpu
#endif

#endif  // VISIBILITY_SHARED_H
