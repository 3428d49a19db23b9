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

struct ProbeLightsPush {
  uint count;       // samples
  uint fields;
  uint second;      // 1: also the direct light into the second light buffer
  uint rotations;   // rotated copies besides the world's
};

#ifdef __cplusplus
static_assert(sizeof(ProbeLightPointGpu) == 32 && offsetof(ProbeLightPointGpu, rotation) == 12, "ProbeLightPointGpu layout");
static_assert(sizeof(ProbeLightsPush) == 16, "ProbeLightsPush layout");
}  // namespace transgi::gpu
#endif

#endif  // PROBE_LIGHTS_SHARED_H
