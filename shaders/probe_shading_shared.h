// Structs of the probe-ray shading kernels (probe_hit_begin.comp,
// probe_hit_finish.comp), shared with modules/transgi/gpu/vulkan_probe_shading:
// probes::begin_probe_ray and finish_probe_ray on the device. Same rules as
// transgi_shared.h.
#ifndef PROBE_SHADING_SHARED_H
#define PROBE_SHADING_SHARED_H

#include "transgi_shared.h"

#ifdef __cplusplus
namespace transgi::gpu {
#endif

TRANSGI_CONST uint kProbeShadingGroupSize = 64u;
// probe_points.comp: a tracing probe whose points the host dropped.
TRANSGI_CONST uint kProbePointsSkip = 0xffffffffu;
// The least roughness a probe ray's hit reflects its light sample with (what
// Cycles calls Filter Glossy), its energy kept at the surface's own
// directional albedo. A mirror-like lobe meeting the light sample's
// direction by chance turns one ray into a spike thousands of times the
// probe's mean, which its map then holds for dozens of frames as a glow; a
// probe's low-order SH cannot hold a sharp reflection anyway. Higher = fewer
// and weaker spikes, at the cost of blurrier glints in the probes' light.
TRANSGI_CONST float kProbeHitMinRoughness = 0.5f;

// ProbeRayHit's flags and PendingProbeRay's.
TRANSGI_CONST uint kProbeRayHit = 1u;
TRANSGI_CONST uint kProbeRayBackFace = 2u;
TRANSGI_CONST uint kProbeRaySawLight = 4u;
TRANSGI_CONST uint kProbeRayReplacedNonFinite = 8u;
TRANSGI_CONST uint kProbeRayNeedsShadow = 16u;
TRANSGI_CONST uint kProbeRayTakesFeedback = 32u;

struct ProbeHitPush {
  uint count;
  uint seed_lo, seed_hi;      // make_rng(seed, item, sample)
  uint sample_lo, sample_hi;
  float offset_scale;         // RtScene::offset_scale
  uint pad0, pad1;
};

// probes::PendingProbeRay, between the two kernels (its radiance is zero).
struct PendingProbeRayGpu {
  float px, py, pz, distance;     // distance: +inf for an escaped ray
  float nx, ny, nz;               // geometric normal, facing the probe
  uint flags;
  float er, eg, eb, pad0;         // emitted
  float ur, ug, ub, pad1;         // unoccluded: what the light sample adds if its shadow ray is clear
  float ar, ag, ab, pad2;         // diffuse albedo / pi
  float sx, sy, sz, pad3;         // shading normal
};

// What the host reads of a probe ray when the raster's points are made on
// the device (probe_points.comp): enough to classify the probe and update
// its depth and sky cells, 8 bytes instead of 64; what it emitted (for a
// field that projects its emitters from its rays rather than sampling
// them) in a buffer of its own, read only where needed.
struct ProbeRayBriefGpu {
  float distance;
  uint flags;
};

struct ProbeRayEmissionGpu {
  float er, eg, eb;
};

// probes::ProbeRayHit.
struct ProbeRayHitGpu {
  float px, py, pz, distance;
  float nx, ny, nz;
  uint flags;
  float rr, rg, rb, pad0;  // radiance leaving the hit towards the probe
  float er, eg, eb, pad1;  // emitted
};

// probes::update_own_depth on the device (probe_own_depth.comp): batch
// probe k's depth map in its store's slot, from its own rays in the
// shading's hits.
struct OwnDepthProbeGpu {
  uint slot;       // its map: the store's depth from slot * texels
  uint first_ray;  // its rays: the shading's hits from here, rays_per_probe of them
  float unit;      // DepthMap::unit
  float blend;     // the history's weight this frame (probes::own_depth_blend)
};

struct OwnDepthPush {
  uint count, rays_per_probe, width, height;
};

// Where a probe ray's bounce light comes from: a field's interpolation
// inside its box, the outer cascade's beyond it (`enabled` 0: no light).
struct ProbeFeedbackGpu {
  ProbeFieldGpu self;
  ProbeFieldGpu outer;
};

struct ProbeFinishPush {
  uint count, pad0, pad1, pad2;
};

#ifdef __cplusplus
static_assert(sizeof(ProbeHitPush) == 32 && offsetof(ProbeHitPush, offset_scale) == 20, "ProbeHitPush layout");
static_assert(sizeof(PendingProbeRayGpu) == 96 && offsetof(PendingProbeRayGpu, flags) == 28 &&
              offsetof(PendingProbeRayGpu, sx) == 80, "PendingProbeRayGpu layout");
static_assert(sizeof(ProbeRayHitGpu) == 64 && offsetof(ProbeRayHitGpu, flags) == 28 && offsetof(ProbeRayHitGpu, er) == 48,
              "ProbeRayHitGpu layout");
static_assert(sizeof(ProbeFeedbackGpu) == 320, "ProbeFeedbackGpu layout");
static_assert(sizeof(OwnDepthProbeGpu) == 16 && sizeof(OwnDepthPush) == 16, "OwnDepth layouts");
static_assert(sizeof(ProbeRayBriefGpu) == 8 && sizeof(ProbeRayEmissionGpu) == 12, "ProbeRayBriefGpu layouts");
}  // namespace transgi::gpu
#endif

#endif  // PROBE_SHADING_SHARED_H
