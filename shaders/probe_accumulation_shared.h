// Structs of TransGI's accumulation kernel (probe_accumulation.comp), shared
// with modules/transgi/gpu/vulkan_probe_accumulator: probes::accumulate and
// probes::filled_radiance for a batch of probes. Same rules as
// transgi_shared.h.
#ifndef PROBE_ACCUMULATION_SHARED_H
#define PROBE_ACCUMULATION_SHARED_H

#include "transgi_shared.h"

#ifdef __cplusplus
namespace transgi::gpu {
#endif

TRANSGI_CONST uint kAccumulateGroupSize = 64u;  // one workgroup per probe
TRANSGI_CONST uint kAccumulateChangeGroups = 8u;

// A probe's scalar state (probes::ProbeMapState), in and out, and whether
// this frame detected a lighting change (out).
struct ProbeAccumulationGpu {
  float radiance_scale, noise_variance, drift, pad0;
  int noise_frames, frames, stable_frames;
  uint changed;
};

struct AccumulatePush {
  uint probes, texels, width, height;
  float hysteresis, change_threshold, change_sigmas, fast_hysteresis;
  int warmup_frames, fill_passes;
  uint pad0, pad1;
};

#ifdef __cplusplus
static_assert(sizeof(ProbeAccumulationGpu) == 32 && offsetof(ProbeAccumulationGpu, noise_frames) == 16, "ProbeAccumulationGpu layout");
static_assert(sizeof(AccumulatePush) == 48 && offsetof(AccumulatePush, hysteresis) == 16 && offsetof(AccumulatePush, warmup_frames) == 32,
              "AccumulatePush layout");
}  // namespace transgi::gpu
#endif

#endif  // PROBE_ACCUMULATION_SHARED_H
