#version 460
// The real-time frame's light per network sample, made on the device
// (probes::interpolate_fields_with): the pruned trilinear SH of the first
// field that holds the point and has a lit probe around it, blended across a
// cascade's hand-over band with the next, or the last field's mean light
// where none is lit; the probes' indirect SH into Light, their direct sky
// and emitter SH into Light2, each in the sample's object frame (the CPU
// rotates each field's SH once per distinct rotation). Written straight
// into the fused decoder's light buffers, so only a sample's position,
// normal and rotation cross the bus, not 150 floats of light.
#extension GL_GOOGLE_include_directive : require
#include "probe_lights_shared.h"

layout(local_size_x = kProbeLightsGroupSize) in;
layout(std430, set = 0, binding = 0) readonly buffer Points { ProbeLightPointGpu points[]; };
layout(std430, set = 0, binding = 1) readonly buffer Fields { ProbeFieldGpu fields[]; };
layout(std430, set = 0, binding = 2) readonly buffer Depth { uint depth[]; };        // every field's depth texels
layout(std430, set = 0, binding = 3) readonly buffer Probes { ProbeGpu probes[]; };  // every field's probes
layout(std430, set = 0, binding = 4) readonly buffer Sh { float sh[]; };             // every copy of every field's SH
// Where field f's indirect (2 f) and direct (2 f + 1) SH start for rotation
// r + 1 (0: the world's): sh_at[(r + 1) * 2 * fields + 2 f + direct].
layout(std430, set = 0, binding = 5) readonly buffer ShAt { uint sh_at[]; };
layout(std430, set = 0, binding = 6) writeonly buffer Light { float light[]; };    // n x 75
layout(std430, set = 0, binding = 7) writeonly buffer Light2 { float light2[]; };  // n x 75 when second
layout(push_constant) uniform PushBlock { ProbeLightsPush p; };

#include "probe_interpolation.glsl"

// cascades.cpp's depth_inside: how far x lies inside field f's box.
float depth_inside(uint f, vec3 x) {
  const ProbeFieldGpu b = fields[f];
  const vec3 d = min(x - vec3(b.box_min_x, b.box_min_y, b.box_min_z), vec3(b.box_max_x, b.box_max_y, b.box_max_z) - x);
  return min(d.x, min(d.y, d.z));
}

bool holds(uint f, vec3 x) {
  const ProbeFieldGpu b = fields[f];
  return all(greaterThanEqual(x, vec3(b.box_min_x, b.box_min_y, b.box_min_z))) &&
         all(lessThanEqual(x, vec3(b.box_max_x, b.box_max_y, b.box_max_z)));
}

// ProbeField::interpolate: field f's weights at (x, n), and whether a lit
// probe weighed in without the fallback.
bool field_weights(uint f, vec3 x, vec3 n, out InterpolationGpu r) {
  const ProbeFieldGpu b = fields[f];
  r = interpolate_probes_at(b.field, b.probe_base, b.depth_base, x, n);
  if (r.fallback != 0u) return false;
  for (int c = 0; c < 8; ++c)
    if (r.weights[c] != 0.0) return true;
  return false;
}

// Field f's blend of its probes' SH coefficient k (of 75) in copy `rot`.
float blended(uint f, InterpolationGpu r, int rot, uint direct, uint k) {
  const uint at = sh_at[uint(rot + 1) * 2u * p.fields + 2u * f + direct];
  float v = 0.0;
  for (int c = 0; c < 8; ++c)
    if (r.weights[c] != 0.0) v += r.weights[c] * sh[at + uint(r.probes[c]) * kTransferOutputs + k];
  return v;
}

void write_light(uint i, uint k, float indirect, float direct) {
  light[i * kTransferOutputs + k] = indirect;
  if (p.second != 0u) light2[i * kTransferOutputs + k] = direct;
}

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= p.count) return;
  const ProbeLightPointGpu q = points[i];
  const vec3 x = vec3(q.px, q.py, q.pz), n = vec3(q.nx, q.ny, q.nz);
  const uint last = p.fields - 1u;

  // blend_boxes: the first field whose box holds x, and across its band the
  // next; the fallbacks (the far field, last) only where no other box holds x.
  uint blended_fields = p.fields;
  while (blended_fields > 0u && fields[blended_fields - 1u].fallback != 0u) --blended_fields;
  const uint blended_last = blended_fields > 0u ? blended_fields - 1u : last;
  uint first = last, second = 0u;
  float w0 = 1.0, w1 = 0.0;
  bool two = false;
  uint f = 0u;
  while (f < blended_fields && depth_inside(f, x) < 0.0) ++f;
  if (f < blended_fields) {
    first = f;
    const float band = fields[f].band;
    const float w = band > 0.0 ? clamp(depth_inside(f, x) / band, 0.0, 1.0) : 1.0;
    if (w < 1.0) {
      uint g = f + 1u;
      while (g < blended_fields && depth_inside(g, x) < 0.0) ++g;
      if (g < blended_fields || f != blended_last) {
        second = g < blended_fields ? g : blended_last;
        w0 = w;
        w1 = 1.0 - w;
        two = true;
      }
    }
  } else {
    uint h = blended_fields;
    while (h < p.fields && depth_inside(h, x) < 0.0) ++h;
    first = h < p.fields ? h : last;
  }

  // An unlit field hands the point on to the next that holds it.
  const uint mixed_first = first;
  InterpolationGpu r;
  bool lit = field_weights(first, x, n, r);
  while (!lit) {
    if (first == last) break;
    uint g = first + 1u;
    while (g < p.fields && !holds(g, x)) ++g;
    first = g < p.fields ? g : last;
    lit = field_weights(first, x, n, r);
  }
  if (!lit) {
    // No field has a lit probe around x: the last field's own (fallback)
    // interpolation, or, where that is black and the SH is the world's, its mean light.
    bool black = true;
    for (uint k = 0u; k < kTransferOutputs && black; ++k) black = blended(first, r, q.rotation, 0u, k) == 0.0;
    const bool mean = black && p.fields > 1u && q.rotation < 0;
    for (uint k = 0u; k < kTransferOutputs; ++k) {
      if (mean) write_light(i, k, sh[fields[last].mean_at + k], sh[fields[last].mean_at + kTransferOutputs + k]);
      else write_light(i, k, blended(first, r, q.rotation, 0u, k), p.second != 0u ? blended(first, r, q.rotation, 1u, k) : 0.0);
    }
    return;
  }
  InterpolationGpu r2;
  const bool blend = two && first == mixed_first && field_weights(second, x, n, r2);
  for (uint k = 0u; k < kTransferOutputs; ++k) {
    float a = blended(first, r, q.rotation, 0u, k);
    float d = p.second != 0u ? blended(first, r, q.rotation, 1u, k) : 0.0;
    if (blend) {
      a = w0 * a + w1 * blended(second, r2, q.rotation, 0u, k);
      if (p.second != 0u) d = w0 * d + w1 * blended(second, r2, q.rotation, 1u, k);
    }
    write_light(i, k, a, d);
  }
}
