// The view's shadow rays (engine/render/view_shadows.h, engine/gpu/
// visibility_pass, shaders/view_shadows.comp), shared by C++ and GLSL. Same
// rules as rt_shared.h.
#ifndef VIEW_SHADOWS_SHARED_H
#define VIEW_SHADOWS_SHARED_H

#include "visibility_shared.h"

#ifdef __cplusplus
namespace engine::gpu {
#endif

RT_CONST uint kViewShadowCells = 64u;          // render::kViewShadowPatternCells
RT_CONST uint kViewShadowDirectional = 1u;     // ViewShadowLightGpu::flags
RT_CONST uint kViewShadowNearest = 2u;

// One light: its position (point and spot lights) or, for a directional
// light, its 8 x 8 pattern of unit directions towards it (xyz; w unused).
struct ViewShadowLightGpu {
  float position_x, position_y, position_z;
  uint flags;
  float directions[4 * kViewShadowCells];
};

// What the kernel adds to the visibility pass's push block.
struct ViewShadowPushGpu {
  int shift_x, shift_y;  // the pattern's shift (render::view_shadow_cell)
  uint lights;
  float offset_scale;    // rt::offset_ray_origin's scale
};

#ifdef __cplusplus
static_assert(sizeof(ViewShadowLightGpu) == 16 + 16 * kViewShadowCells && offsetof(ViewShadowLightGpu, directions) == 16,
              "ViewShadowLightGpu layout");
static_assert(sizeof(ViewShadowPushGpu) == 16, "ViewShadowPushGpu layout");
}  // namespace engine::gpu
#endif

#endif  // VIEW_SHADOWS_SHARED_H
