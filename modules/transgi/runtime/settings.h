#pragma once
// Every TransGI run-time knob, in one resource. Each says what raising it
// buys and what it costs.
#include <cstdint>

#include "probes/probe_field.h"

namespace transgi::runtime {

struct TransGISettings {
  // Probe rays, map size, sharing, accumulation, interpolation and skips
  // (see ProbeFieldSettings and the structs it holds; its `grid` is ignored:
  // each ProbeVolume gives its own).
  probes::ProbeFieldSettings probes;
  // G-buffer samples per pixel (each decoded by the network). Higher =
  // antialiased edges, at the cost of that many times the inference.
  int gbuffer_spp = 1;
  // Direct-light samples per pixel (shadow rays to punctual lights, sampled
  // area lights and environment). Higher = less direct-light noise, at the
  // cost of tracing time. 0 = GI only.
  int direct_spp = 4;
  std::uint64_t seed = 0;
};

}  // namespace transgi::runtime
