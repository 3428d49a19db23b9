// Constants and structs shared by the C++ host code and the GLSL kernels
// (the Falcor pattern). Both languages include this file, so a field added on
// one side is added on the other. Rules that keep the layouts equal:
//  - only 32-bit scalars (uint, int, float), never vec3 (std430 pads it to 16);
//  - each struct padded by hand to a multiple of 16 bytes, and the C++ side
//    checks every size and offset with static_assert.
#ifndef TRANSGI_SHARED_H
#define TRANSGI_SHARED_H

#ifdef __cplusplus
#include <cstddef>
#include <cstdint>
namespace transgi::gpu {
using uint = std::uint32_t;
#define TRANSGI_CONST inline constexpr
#else
#define TRANSGI_CONST const
#endif

// Fused transfer inference (fused_inference.comp).
TRANSGI_CONST uint kFusedGroupSize = 64u;     // points per workgroup, one per invocation
TRANSGI_CONST uint kFusedMaxWidth = 128u;     // widest layer a kernel holds per invocation
TRANSGI_CONST uint kFusedRowsPerChunk = 32u;  // weight rows staged in shared memory at once: 32 x 128 fp32 = 16 KB
// The tiled variant (fused_inference_tiled.comp): a workgroup holds a tile of
// points' activations in shared memory, and each invocation keeps a 4-row x
// 16-point block of sums in registers.
TRANSGI_CONST uint kFusedTiledGroupSize = 128u;     // invocations per workgroup
TRANSGI_CONST uint kFusedTiledPoints = 64u;         // points per workgroup: 128 x 64 fp32 activations = 32 KB
TRANSGI_CONST uint kFusedTiledRowsPerLane = 4u;     // output rows per invocation (32 lanes x 4 = 128 rows)
TRANSGI_CONST uint kFusedTiledPointsPerLane = 16u;  // points per invocation (4 groups of lanes x 16 = 64)
TRANSGI_CONST uint kShCoefficients = 25u;     // degree-4 SH
TRANSGI_CONST uint kTransferOutputs = 75u;    // 25 x RGB

struct FusedPush {
  uint count;          // shading points
  uint inputs;         // decoder inputs (16)
  uint width;          // hidden width (<= kFusedMaxWidth)
  uint hidden_layers;  // ReLU layers before the linear output
  uint outputs;        // kTransferOutputs
  uint second;         // 1: also dot the transfer with Light2 into Rgb2
  uint pad1;
  uint pad2;
};

// SH projection of probe radiance maps (sh_projection.comp).
TRANSGI_CONST uint kProjectGroupSize = 32u;  // invocations per probe; 32 x 75 partial sums = 9.6 KB shared

struct ProjectPush {
  uint probes;
  uint texels;  // per map
  uint pad0;
  uint pad1;
};

// A probe grid (probes::ProbeGrid) as the kernels read it; probe_grid.glsl
// turns it into storage indices and grid points.
struct ProbeGridGpu {
  float min_x, min_y, min_z;
  int probes;
  float spacing_x, spacing_y, spacing_z;
  float min_spacing;
  int dims_x, dims_y, dims_z;
  int pad0;
  int scroll_x, scroll_y, scroll_z;
  int pad1;
};

// Probe interpolation with pruning (probe_interpolation.comp).
TRANSGI_CONST uint kInterpolateGroupSize = 64u;
TRANSGI_CONST uint kInterpolatePruneBackFacing = 1u;  // InterpolatePush::flags bits
TRANSGI_CONST uint kInterpolatePruneOccluded = 2u;
TRANSGI_CONST uint kInterpolateHasOffsets = 4u;

struct InterpolatePush {
  ProbeGridGpu grid;
  float bias_length;  // normal_bias x the grid's smallest spacing
  float visibility_threshold;
  int points;
  uint flags;
  uint map_width, map_height, texels;
  float visibility_ramp;
  // The points' viewer (the camera) and the view bias's length in metres
  // (view_bias x the grid's smallest spacing); 0 = no viewer.
  float viewer_x, viewer_y, viewer_z, view_bias_length;
};

// A probe field among several that a kernel reads from shared buffers (the
// probe rays' bounce light, the frame's lights): its interpolation, where its
// probes and depth texels start, where its mean light starts in an SH buffer
// (probe_lights.comp), whether it is there at all (probe_hit_finish.comp),
// and its placed grid's box with the hand-over band and whether it is a
// fallback, lighting only what no other box holds (cascades.h's BlendBox).
struct ProbeFieldGpu {
  InterpolatePush field;
  uint probe_base, depth_base, mean_at, enabled;
  float box_min_x, box_min_y, box_min_z, band;
  float box_max_x, box_max_y, box_max_z;
  uint fallback;
};

// Per probe: its relocation offset, its depth unit, whether it holds light.
struct ProbeGpu {
  float offset_x, offset_y, offset_z, depth_unit;
  uint usable, pad0, pad1, pad2;
};

// Per shading point: probes::InterpolationResult.
struct InterpolationGpu {
  int probes[8];
  float weights[8];
  uint pruned, fallback, pad0, pad1;
};

// Across-probe radiance sharing (radiance_raster.comp).
TRANSGI_CONST uint kRasterGroupSize = 64u;     // one workgroup per target probe; lane t owns texels t mod 64
TRANSGI_CONST uint kRasterChunk = 1024u;       // candidate points classified per pass (8 KB of shared memory)
TRANSGI_CONST uint kRasterDepthGuard = 1u;     // RasterPush::flags bits
TRANSGI_CONST uint kRasterSameSide = 2u;
TRANSGI_CONST uint kRasterHasDepth = 4u;
TRANSGI_CONST uint kRasterHasOffsets = 8u;

struct RasterPush {
  ProbeGridGpu grid;
  float relative_tolerance, absolute_tolerance, spread_tolerance;  // probes::SharingSettings
  uint flags;
  uint map_width, map_height, texels, pad1;
};

// probes::ShadedPoint, each vec3 padded to 16 bytes.
struct ShadedPointGpu {
  float px, py, pz, distance;  // distance: +inf for an escaped ray
  float rx, ry, rz, pad0;      // radiance towards the shooting probe
  float dx, dy, dz, pad1;      // unit direction from the shooting probe
  float nx, ny, nz, pad2;      // geometric normal on the shooting probe's side
};

// DDGI irradiance at shading points (ddgi_irradiance.comp).
TRANSGI_CONST uint kDdgiGroupSize = 64u;

struct DdgiPush {
  ProbeGridGpu grid;
  float normal_bias, view_bias, irradiance_gamma;
  int points;
  uint irradiance_size, distance_size, irradiance_interior, distance_interior;  // sizes include the border
};

// A shading point for DDGI: position, normal, view direction (eye to point).
struct DdgiPointGpu {
  float px, py, pz, pad0;
  float nx, ny, nz, pad1;
  float vx, vy, vz, pad2;
};

// DDGI blending (ddgi_blend.comp).
TRANSGI_CONST uint kDdgiBlendGroupSize = 64u;  // one workgroup per probe

struct DdgiBlendPush {
  uint probes, rays_per_probe, irradiance_interior, distance_interior;
  float hysteresis, irradiance_threshold, brightness_threshold, irradiance_gamma;
  float distance_exponent, max_distance;
  uint clamp_brightness;
  int max_backfaces;
};

// ddgi::RayRecord, padded.
struct DdgiRayGpu {
  float dx, dy, dz, distance;
  float rx, ry, rz, pad0;
};

#ifdef __cplusplus
static_assert(sizeof(DdgiBlendPush) == 48 && offsetof(DdgiBlendPush, hysteresis) == 16 &&
              offsetof(DdgiBlendPush, distance_exponent) == 32 && offsetof(DdgiBlendPush, max_backfaces) == 44,
              "DdgiBlendPush layout");
static_assert(sizeof(DdgiRayGpu) == 32 && offsetof(DdgiRayGpu, rx) == 16, "DdgiRayGpu layout");
static_assert(sizeof(DdgiPush) == 96 && offsetof(DdgiPush, normal_bias) == 64 &&
              offsetof(DdgiPush, irradiance_size) == 80, "DdgiPush layout");
static_assert(sizeof(DdgiPointGpu) == 48 && offsetof(DdgiPointGpu, nx) == 16 && offsetof(DdgiPointGpu, vx) == 32,
              "DdgiPointGpu layout");
static_assert(sizeof(RasterPush) == 96 && offsetof(RasterPush, spread_tolerance) == 72 && offsetof(RasterPush, flags) == 76 &&
                  offsetof(RasterPush, texels) == 88,
              "RasterPush layout");
static_assert(sizeof(ShadedPointGpu) == 64 && offsetof(ShadedPointGpu, rx) == 16 && offsetof(ShadedPointGpu, nx) == 48,
              "ShadedPointGpu layout");
static_assert(sizeof(ProbeGridGpu) == 64 && offsetof(ProbeGridGpu, spacing_x) == 16 &&
              offsetof(ProbeGridGpu, dims_x) == 32 && offsetof(ProbeGridGpu, scroll_x) == 48, "ProbeGridGpu layout");
static_assert(sizeof(InterpolatePush) == 112 && offsetof(InterpolatePush, bias_length) == 64 &&
              offsetof(InterpolatePush, flags) == 76 && offsetof(InterpolatePush, map_width) == 80 &&
              offsetof(InterpolatePush, viewer_x) == 96,
              "InterpolatePush layout");
static_assert(sizeof(ProbeGpu) == 32 && offsetof(ProbeGpu, usable) == 16, "ProbeGpu layout");
static_assert(sizeof(ProbeFieldGpu) == 160 && offsetof(ProbeFieldGpu, probe_base) == 112 && offsetof(ProbeFieldGpu, enabled) == 124 &&
              offsetof(ProbeFieldGpu, band) == 140 && offsetof(ProbeFieldGpu, box_max_x) == 144 &&
              offsetof(ProbeFieldGpu, fallback) == 156,
              "ProbeFieldGpu layout");
static_assert(sizeof(InterpolationGpu) == 80 && offsetof(InterpolationGpu, weights) == 32 &&
              offsetof(InterpolationGpu, pruned) == 64, "InterpolationGpu layout");
static_assert(sizeof(ProjectPush) == 16 && offsetof(ProjectPush, texels) == 4, "ProjectPush layout");
static_assert(sizeof(FusedPush) == 32, "FusedPush must match its std430/push-constant layout");
static_assert(offsetof(FusedPush, count) == 0 && offsetof(FusedPush, inputs) == 4 && offsetof(FusedPush, width) == 8 &&
              offsetof(FusedPush, hidden_layers) == 12 && offsetof(FusedPush, outputs) == 16 &&
                  offsetof(FusedPush, second) == 20,
              "FusedPush field offsets");
static_assert(kFusedRowsPerChunk * kFusedMaxWidth * 4 <= 16384, "the weight chunk must fit the 16 KB we plan for");
static_assert(kFusedTiledGroupSize / 32 * kFusedTiledPointsPerLane == kFusedTiledPoints &&
                  32 * kFusedTiledRowsPerLane == kFusedMaxWidth,
              "the tiled kernel's lanes must cover its tile's points and the widest layer's rows");
static_assert((kTransferOutputs + kTransferOutputs / 2) * kFusedTiledPoints <= kFusedMaxWidth * kFusedTiledPoints,
              "the tiled kernel's shared activations must hold the transfer and half a tile of light");
}  // namespace transgi::gpu
#endif

#endif  // TRANSGI_SHARED_H
