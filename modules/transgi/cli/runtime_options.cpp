#include "cli/runtime_options.h"

#include <algorithm>

#include "runtime/transgi_plugin.h"

namespace transgi::cli {

runtime::TransGISettings runtime_settings_from(const Args& args, const char* default_preset) {
  runtime::TransGISettings s = args.choice("preset", {"quality", "realtime"}, default_preset) == "realtime"
                                   ? runtime::realtime_preset()
                                   : runtime::quality_preset();
  s.realtime.resolution_scale = static_cast<float>(args.number("gi-scale", 0.05, 1.0, s.realtime.resolution_scale));
  s.probes.update_budget = static_cast<int>(args.integer("probe-budget", 0, 1 << 20, s.probes.update_budget));
  s.probes.steady_light_budget =
      static_cast<int>(args.integer("probe-steady-budget", 0, 1 << 20, s.probes.steady_light_budget));
  if (args.has("gi-reuse")) s.realtime.reuse_history = args.choice("gi-reuse", {"on", "off"}, "on") == "on";
  s.realtime.transfer_max_age = static_cast<int>(args.integer("keep-transfer", 0, 4096, s.realtime.transfer_max_age));
  s.realtime.transfer_view_degrees =
      static_cast<float>(args.number("keep-transfer-degrees", 0.0, 90.0, s.realtime.transfer_view_degrees));
  if (args.has("taa")) s.taa.enabled = args.choice("taa", {"on", "off"}, "on") == "on";
  s.probes.settle_frames = static_cast<int>(args.integer("probe-settle", 0, 4096, s.probes.settle_frames));
  s.probes.map.width = static_cast<int>(args.integer("map-width", 4, 4096, s.probes.map.width));
  s.probes.map.height = std::max(2, s.probes.map.width / 2);
  if (args.has("changed-first"))
    s.probes.changed_first = args.choice("changed-first", {"on", "off"}, "off") == "on";
  if (args.has("direct"))
    s.direct_light = args.choice("direct", {"deterministic", "stochastic"}, "stochastic") == "deterministic"
                         ? runtime::DirectLight::Deterministic
                         : runtime::DirectLight::Stochastic;
  s.backend = args.choice("backend", {"cpu", "vulkan"}, "cpu") == "vulkan" ? runtime::Backend::Vulkan : runtime::Backend::Cpu;
  s.gpu_device = args.str("device", std::string());
  if (args.has("device-inference")) s.device_inference = args.choice("device-inference", {"on", "off"}, "off") == "on";
  if (args.has("device-lights")) s.realtime.device_lights = args.choice("device-lights", {"on", "off"}, "on") == "on";
  if (args.has("reflections") && args.choice("reflections", {"on", "off"}, "on") == "off") s.mirror.max_roughness = -1.0f;
  near_field_from(args, s.near_field);
  return s;
}

void near_field_from(const Args& args, shading::NearFieldRays& n) {
  n.rays = static_cast<int>(args.integer("near-field-rays", 0, 1024, n.rays));
  n.reach_cells = static_cast<float>(args.number("near-field-reach", 0.01, 16.0, n.reach_cells));
  n.filter_radius = static_cast<int>(args.integer("near-field-filter", 0, 16, n.filter_radius));
  n.cell_budget = static_cast<int>(args.integer("near-field-budget", 0, 1 << 24, n.cell_budget));
  n.history_frames = static_cast<int>(args.integer("near-field-history", 1, 255, n.history_frames));
  n.cut_fade_frames = static_cast<int>(args.integer("near-field-cut-fade", 0, 255, n.cut_fade_frames));
}

runtime::ProbePlacement probe_placement_from(const Args& args, runtime::ProbeVolumeMode default_mode) {
  runtime::ProbePlacement p;
  const std::string mode = args.choice("probe-volume", {"cascades", "scene", "authored"}, std::string(runtime::name_of(default_mode)));
  p.mode = mode == "cascades" ? runtime::ProbeVolumeMode::Cascades
           : mode == "scene"  ? runtime::ProbeVolumeMode::Scene
                              : runtime::ProbeVolumeMode::Authored;
  p.scene_dims = glm::ivec3(static_cast<int>(args.integer("probe-grid", 1, 64, 8)));
  p.cascades.count = static_cast<int>(args.integer("cascades", 1, 8, p.cascades.count));
  p.cascades.finest_cell = static_cast<float>(args.number("cascade-cell", 0.01, 100.0, p.cascades.finest_cell));
  p.cascades.fit_scene_cell = static_cast<float>(args.number("cascade-fit-scene", 0.0, 1e6, p.cascades.fit_scene_cell));
  p.cascades.map_width = static_cast<int>(args.integer("cascade-map-width", 0, 4096, p.cascades.map_width));
  p.cascades.look_ahead = static_cast<float>(args.number("cascade-look-ahead", 0.0, 1.0, p.cascades.look_ahead));
  return p;
}

}  // namespace transgi::cli
