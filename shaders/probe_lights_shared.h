// Structs of the real-time frame's probe-light kernel (probe_lights.comp),
// shared with modules/transgi/gpu/vulkan_probe_lights: each network sample's
// light interpolated from the probe fields on the device
// (probes::interpolate_fields_with), written straight into the fused
// decoder's light buffers. Same rules as transgi_shared.h.
#ifndef PROBE_LIGHTS_SHARED_H
#define PROBE_LIGHTS_SHARED_H

#include "transgi_shared.h"

#ifdef __cplusplus
namespace transgi::gpu {
#endif

TRANSGI_CONST uint kProbeLightsGroupSize = 64u;
TRANSGI_CONST uint kProbeLightsMaxFields = 16u;  // cascades and authored volumes; more fall back to the CPU

// A sample: where it is, its world normal, and the rotation its object's
// frame takes (-1: world).
struct ProbeLightPointGpu {
  float px, py, pz;
  int rotation;
  float nx, ny, nz, pad0;
};

// A field as the samples read it: its interpolation, where its probes and
// depth texels start in the shared buffers, its box and hand-over band
// (cascades.h's BlendBox), and where its mean light (75 indirect, 75 direct:
// the ambient term when no field is lit) starts in the SH buffer.
struct ProbeLightFieldGpu {
  InterpolatePush field;
  uint probe_base, depth_base, mean_at, pad0;
  float box_min_x, box_min_y, box_min_z, band;
  float box_max_x, box_max_y, box_max_z, pad1;
};

struct ProbeLightsPush {
  uint count;       // samples
  uint fields;
  uint second;      // 1: also the direct light into the second light buffer
  uint rotations;   // rotated copies besides the world's
};

#ifdef __cplusplus
static_assert(sizeof(ProbeLightPointGpu) == 32 && offsetof(ProbeLightPointGpu, rotation) == 12, "ProbeLightPointGpu layout");
static_assert(sizeof(ProbeLightFieldGpu) == 144 && offsetof(ProbeLightFieldGpu, probe_base) == 96 &&
              offsetof(ProbeLightFieldGpu, band) == 124 && offsetof(ProbeLightFieldGpu, box_max_x) == 128,
              "ProbeLightFieldGpu layout");
static_assert(sizeof(ProbeLightsPush) == 16, "ProbeLightsPush layout");
}  // namespace transgi::gpu
#endif

#endif  // PROBE_LIGHTS_SHARED_H
