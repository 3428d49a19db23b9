#version 460
// The second half of a probe ray's shading (probes::finish_probe_ray): the
// light sample's contribution where its shadow ray was clear, plus the
// diffuse albedo / pi times the bounce light, the irradiance interpolated
// from the probes of the field that holds the hit (the previous frame's SH,
// or the outer cascade's outside this field's box).
#extension GL_GOOGLE_include_directive : require
#include "probe_shading_shared.h"
#include "rt_shared.h"

layout(local_size_x = kProbeShadingGroupSize) in;
layout(std430, set = 0, binding = 0) readonly buffer Pending { PendingProbeRayGpu pending[]; };
layout(std430, set = 0, binding = 1) readonly buffer ShadowHits { HitGpu shadow_hits[]; };  // per ray: its shadow ray's first hit
layout(std430, set = 0, binding = 2) writeonly buffer Out { ProbeRayHitGpu out_hits[]; };
layout(std430, set = 0, binding = 3) readonly buffer Feedback { ProbeFeedbackGpu feedback; };
layout(std430, set = 0, binding = 4) readonly buffer Depth { uint depth[]; };      // both fields' depth texels
layout(std430, set = 0, binding = 5) readonly buffer Probes { ProbeGpu probes[]; };  // both fields' probes
layout(std430, set = 0, binding = 6) readonly buffer ProbeSh { float probe_sh[]; };  // both fields' probes x 75
layout(std430, set = 0, binding = 7) writeonly buffer Briefs { ProbeRayBriefGpu briefs[]; };  // Out's fields the host needs
layout(std430, set = 0, binding = 8) writeonly buffer Emission { float emission[]; };     // and its emission, 3 a ray
layout(push_constant) uniform PushBlock { ProbeFinishPush p; };

#include "probe_interpolation.glsl"
#include "sh_irradiance.glsl"

// ProbeField::irradiance: the pruned trilinear SH at (x, n), convolved with
// the clamped cosine about n.
vec3 field_irradiance(ProbeFieldGpu f, vec3 x, vec3 n) {
  const InterpolationGpu r = interpolate_probes_at(f.field, f.probe_base, f.depth_base, x, n);
  float y[25];
  sh_eval(n, y);
  vec3 e = vec3(0.0);
  for (uint k = 0u; k < kShCoefficients; ++k) {
    const float a = sh_cosine_band(k) * y[k];
    if (a == 0.0) continue;
    vec3 l = vec3(0.0);
    for (int c = 0; c < 8; ++c) {
      if (r.weights[c] == 0.0) continue;
      const uint at = (f.probe_base + uint(r.probes[c])) * kTransferOutputs + k;
      l += r.weights[c] * vec3(probe_sh[at], probe_sh[at + kShCoefficients], probe_sh[at + 2u * kShCoefficients]);
    }
    e += a * l;
  }
  return max(e, vec3(0.0));
}

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= p.count) return;
  const PendingProbeRayGpu q = pending[i];
  ProbeRayHitGpu o;
  o.px = q.px;
  o.py = q.py;
  o.pz = q.pz;
  o.distance = q.distance;
  o.nx = q.nx;
  o.ny = q.ny;
  o.nz = q.nz;
  o.flags = q.flags & (kProbeRayHit | kProbeRayBackFace | kProbeRaySawLight | kProbeRayReplacedNonFinite);
  o.er = q.er;
  o.eg = q.eg;
  o.eb = q.eb;
  o.pad0 = o.pad1 = 0.0;
  vec3 radiance = vec3(0.0);
  if ((q.flags & kProbeRayTakesFeedback) != 0u) {
    if ((q.flags & kProbeRayNeedsShadow) != 0u && shadow_hits[i].instance == kRtNoHit) {
      radiance += vec3(q.ur, q.ug, q.ub);
      o.flags |= kProbeRaySawLight;
    }
    const vec3 x = vec3(q.px, q.py, q.pz), n = vec3(q.sx, q.sy, q.sz);
    const ProbeFieldGpu self = feedback.self;
    const bool outside = any(lessThan(x, vec3(self.box_min_x, self.box_min_y, self.box_min_z))) ||
                         any(greaterThan(x, vec3(self.box_max_x, self.box_max_y, self.box_max_z)));
    vec3 bounce = vec3(0.0);
    if (feedback.outer.enabled != 0u && outside) bounce = field_irradiance(feedback.outer, x, n);
    else if (self.enabled != 0u) bounce = field_irradiance(self, x, n);
    radiance += vec3(q.ar, q.ag, q.ab) * bounce;
    if (any(isnan(radiance)) || any(isinf(radiance))) {
      radiance = vec3(0.0);
      o.flags |= kProbeRayReplacedNonFinite;
    }
  }
  o.rr = radiance.r;
  o.rg = radiance.g;
  o.rb = radiance.b;
  out_hits[i] = o;
  briefs[i] = ProbeRayBriefGpu(o.distance, o.flags);
  emission[3u * i] = o.er;
  emission[3u * i + 1u] = o.eg;
  emission[3u * i + 2u] = o.eb;
}
