#version 460
// The probe rays of a frame, on the device: ray k leaves tracing probe
// k / M along direction k % M (the frame's rotated spherical Fibonacci set),
// with its generator's item (the probe's index x 4096 + the ray's), as
// ProbeField::update builds them on the CPU. What rt_query.comp then traces.
#extension GL_GOOGLE_include_directive : require
#include "probe_shading_shared.h"
#include "rt_shared.h"

layout(local_size_x = kProbeShadingGroupSize) in;
layout(std430, set = 0, binding = 0) readonly buffer Origins { vec4 origins[]; };       // per tracing probe: xyz, w = its index (as float bits)
layout(std430, set = 0, binding = 1) readonly buffer Directions { vec4 directions[]; };  // M unit directions
layout(std430, set = 0, binding = 2) writeonly buffer Rays { RayGpu rays[]; };
layout(std430, set = 0, binding = 3) writeonly buffer Items { uint items[]; };            // per ray: item (lo, hi)
layout(push_constant) uniform PushBlock { uint count; uint rays_per_probe; } p;

void main() {
  const uint k = gl_GlobalInvocationID.x;
  if (k >= p.count) return;
  const uint j = k / p.rays_per_probe, i = k % p.rays_per_probe;
  const vec4 o = origins[j];
  const vec3 d = directions[i].xyz;
  rays[k] = RayGpu(o.x, o.y, o.z, 0.0, d.x, d.y, d.z, uintBitsToFloat(0x7f800000u));
  const uint probe = floatBitsToUint(o.w);
  // probe * 4096 + i as 64 bits: probe < 2^20 keeps the low word exact.
  const uint lo = (probe << 12) + i;
  items[2u * k] = lo;
  items[2u * k + 1u] = (probe >> 20) + (lo < (probe << 12) ? 1u : 0u);
}
