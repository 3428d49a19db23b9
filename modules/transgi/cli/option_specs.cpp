#include "cli/option_specs.h"

#include <climits>
#include <cmath>
#include <cstdio>
#include <utility>

#include "ddgi/ddgi_volume.h"
#include "runtime/transgi_plugin.h"

namespace transgi::cli {

namespace {

std::string number_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

// "X" when both presets agree, else "X (quality), Y (realtime)".
std::string by_preset(double quality, double realtime) {
  if (quality == realtime) return number_text(quality);
  return number_text(quality) + " (quality), " + number_text(realtime) + " (realtime)";
}
std::string by_preset(int quality, int realtime) { return by_preset(static_cast<double>(quality), static_cast<double>(realtime)); }
std::string on_off_by_preset(bool quality, bool realtime) {
  const char* q = quality ? "on" : "off";
  const char* r = realtime ? "on" : "off";
  if (quality == realtime) return q;
  return std::string(q) + " (quality), " + r + " (realtime)";
}

OptionSpec integer(std::string name, std::string value, double lo, double hi, std::string default_text, std::string help) {
  return {std::move(name), std::move(value), std::move(default_text), std::move(help), std::pair{lo, hi}, {}, false};
}
OptionSpec number(std::string name, std::string value, double lo, double hi, std::string default_text, std::string help) {
  return integer(std::move(name), std::move(value), lo, hi, std::move(default_text), std::move(help));
}
OptionSpec choice(std::string name, std::vector<std::string> choices, std::string default_text, std::string help) {
  return {std::move(name), "WORD", std::move(default_text), std::move(help), std::nullopt, std::move(choices), false};
}
OptionSpec text(std::string name, std::string value, std::string default_text, std::string help) {
  return {std::move(name), std::move(value), std::move(default_text), std::move(help), std::nullopt, {}, false};
}
OptionSpec flag(std::string name, std::string help) { return {std::move(name), "", "", std::move(help), std::nullopt, {}, true}; }

void append(std::vector<OptionSpec>& to, std::vector<OptionSpec> from) {
  for (OptionSpec& o : from) to.push_back(std::move(o));
}

}  // namespace

std::vector<OptionSpec> runtime_option_specs(const std::string& default_preset) {
  const runtime::TransGISettings q = runtime::quality_preset(), r = runtime::realtime_preset();
  const auto direct = [](runtime::DirectLight d) { return d == runtime::DirectLight::Deterministic ? "deterministic" : "stochastic"; };
  return {
      choice("preset", {"quality", "realtime"}, default_preset,
             "the settings the options below change: quality is the paper's path, realtime the game's"),
      number("gi-scale", "S", 0.05, 1.0, by_preset(q.realtime.resolution_scale, r.realtime.resolution_scale),
             "real-time GI resolution over the image's: higher = finer GI, at the cost of more decoded points"),
      integer("probe-budget", "K", 0, 1 << 20, by_preset(q.probes.update_budget, r.probes.update_budget),
              "probes traced a frame (0 = all): higher = light follows changes sooner, at the cost of probe time"),
      integer("probe-steady-budget", "K", 0, 1 << 20,
              by_preset(q.probes.steady_light_budget, r.probes.steady_light_budget),
              "probes traced a frame once the lights have held (0 = --probe-budget): higher = bounce light follows a "
              "moved object sooner, at the cost of probe time"),
      choice("gi-reuse", {"on", "off"}, on_off_by_preset(q.realtime.reuse_history, r.realtime.reuse_history),
             "real-time GI cells taken from the frame before where nothing changed: about half the decoding"),
      integer("keep-transfer", "F", 0, 4096, by_preset(q.realtime.transfer_max_age, r.realtime.transfer_max_age),
              "with gi-reuse, frames a cell keeps its decoded transfer (0 = none): higher = fewer decodes, at the cost of "
              "transfer held at one sub-pixel position longer"),
      number("keep-transfer-degrees", "D", 0.0, 90.0,
             by_preset(q.realtime.transfer_view_degrees, r.realtime.transfer_view_degrees),
             "view turn before a kept transfer is decoded again: higher = fewer decodes, at the cost of glossy transfer "
             "seen from that far off"),
      choice("taa", {"on", "off"}, on_off_by_preset(q.taa.enabled, r.taa.enabled),
             "temporal antialiasing of the real-time frame (off shows one frame's samples)"),
      integer("probe-settle", "F", 0, 4096, by_preset(q.probes.settle_frames, r.probes.settle_frames),
              "first frames that trace every probe before the budget applies"),
      integer("map-width", "W", 4, 4096, by_preset(q.probes.map.width, r.probes.map.width),
              "probe radiance map width (height half): higher = sharper probe light, at the cost of raster time"),
      choice("changed-first", {"on", "off"}, on_off_by_preset(q.probes.changed_first, r.probes.changed_first),
             "spend the probe budget on the probes whose light changed first"),
      choice("direct", {"deterministic", "stochastic"},
             q.direct_light == r.direct_light ? std::string(direct(q.direct_light))
                                              : std::string(direct(q.direct_light)) + " (quality), " + direct(r.direct_light) + " (realtime)",
             "direct light: a fixed light-sample pattern filtered into penumbrae, or Monte Carlo samples"),
      choice("backend", {"cpu", "vulkan"}, "cpu", "where probe rays, the G-buffer's rays and the probe kernels run"),
      text("device", "NAME", "the first discrete GPU", "the Vulkan device to take (a part of its name)"),
      choice("device-inference", {"on", "off"}, on_off_by_preset(q.device_inference, r.device_inference),
             "run the real-time transfer inference on the Vulkan device"),
      choice("device-lights", {"on", "off"}, on_off_by_preset(q.realtime.device_lights, r.realtime.device_lights),
             "interpolate the network samples' light on the device (32 bytes a sample cross the bus, not 600)"),
      choice("reflections", {"on", "off"}, on_off_by_preset(q.mirror.max_roughness >= 0, r.mirror.max_roughness >= 0),
             "trace the reflections of mirrors, glossy metals and glossy non-metals: off = the network's SH-4 transfer alone (the paper's)"),
      integer("near-field-rays", "N", 0, 1024, by_preset(q.near_field.rays, r.near_field.rays),
              "contact-light rays per GI cell (0 = off): higher = less noise, at the cost of ray time"),
      number("near-field-reach", "CELLS", 0.01, 16.0, by_preset(q.near_field.reach_cells, r.near_field.reach_cells),
             "near-field ray length in probe cells: higher = more contact light found, at the cost of overlap with the probes"),
      integer("near-field-filter", "R", 0, 16, by_preset(q.near_field.filter_radius, r.near_field.filter_radius),
              "near-field filter radius in GI cells: higher = smoother, at the cost of detail"),
      integer("near-field-budget", "N", 0, 1 << 24, by_preset(q.near_field.cell_budget, r.near_field.cell_budget),
              "real-time path: GI cells that trace near-field rays a frame (0 = no limit): higher = less noise at high resolutions, at the cost of ray time"),
      integer("near-field-history", "F", 1, 255, by_preset(q.near_field.history_frames, r.near_field.history_frames),
              "real-time path: frames a cell's contact light is averaged over: higher = less noise, at the cost of lag after a change of light"),
      integer("near-field-cut-fade", "F", 0, 255, by_preset(q.near_field.cut_fade_frames, r.near_field.cut_fade_frames),
              "real-time path: frames the contact light fades in over after a cut or a sudden turn (0 = off): higher = calmer, at the cost of contact light missing meanwhile"),
  };
}

std::vector<OptionSpec> placement_option_specs(runtime::ProbeVolumeMode default_mode) {
  const runtime::ProbePlacement placement;
  const auto& c = placement.cascades;
  return {
      choice("probe-volume", {"cascades", "scene", "authored"}, std::string(runtime::name_of(default_mode)),
             "where probes go: grids around the camera, one grid over the scene, or the level's volumes"),
      integer("probe-grid", "N", 1, 64, "8", "probes along each axis of the scene grid (--probe-volume scene)"),
      integer("cascades", "N", 1, 8, std::to_string(c.count),
              "camera-centred grids, each twice the last's extent: higher = GI reaches further, at the cost of more probes"),
      number("cascade-cell", "METRES", 0.01, 100.0, number_text(c.finest_cell),
             "finest cascade's cell: smaller = finer light near the camera, at the cost of more probes"),
      number("cascade-fit-scene", "METRES", 0.0, 1e6, number_text(c.fit_scene_cell),
             "one grid over the scene, not cascades, when its cells would be this small or smaller (0 = never)"),
      integer("cascade-map-width", "W", 0, 4096, std::to_string(c.map_width),
              "cascade probes' map width on the real-time path (0 = --map-width): higher = finer light, at the cost of memory"),
      number("cascade-look-ahead", "F", 0.0, 1.0, number_text(c.look_ahead),
             "cascade centres ahead of the camera, in half extents: higher = more probes in view, at the cost of more entering on a turn"),
  };
}

std::vector<OptionSpec> sun_option_specs() {
  return {
      number("sun-elevation", "DEG", -90.0, 90.0, "the scene's", "turns the scene's directional light: its elevation"),
      number("sun-azimuth", "DEG", -360.0, 360.0, "the scene's", "turns the scene's directional light: its azimuth"),
  };
}

const char* const kRenderSynopsis =
    "usage: transgi render --scene S.gltf --out F.exr [--method reference|transgi|ddgi] [options]\n"
    "  An image of the scene: the path tracer's (reference), TransGI's (--model M.tgm) or DDGI's.\n";

std::vector<OptionSpec> render_option_specs() {
  const ddgi::DdgiSettings d;
  std::vector<OptionSpec> o = {
      text("scene", "PATH", "", "the glTF scene"),
      text("out", "PATH", "", "the EXR written (through a temporary file)"),
      choice("method", {"reference", "transgi", "ddgi"}, "reference", "who renders: the path tracer, TransGI or DDGI"),
      choice("pass", {"full", "direct", "gi", "albedo", "all"}, "full",
             "what is written; all writes OUT, OUT_direct and OUT_gi (the reference also OUT_albedo, the first surface's base colour, and OUT_textured, where it is textured or coloured)"),
      text("png", "PATH", "none", "an sRGB PNG of the same image"),
      number("exposure", "EV", -30, 30, "0", "the PNG's exposure"),
      integer("width", "W", 1, 16384, "320", "image width in pixels"),
      integer("height", "H", 1, 16384, "180", "image height in pixels"),
      integer("threads", "T", 0, 1024, "0 (every core)", "worker threads; the image is the same for any count"),
      text("camera", "NAME", "the scene's first", "the camera node to render from"),
      integer("spp", "N", 1, 1'000'000, "64 (reference), 4 (--lighting environment), 1 (transgi, ddgi)",
              "samples per pixel (the G-buffer's for transgi and ddgi): higher = less noise, at the cost of time"),
      integer("seed", "K", 0, static_cast<double>(INT64_MAX), "0", "the random streams' seed"),
      text("model", "PATH", "none: required with --method transgi", "the baked transfer model (.tgm)"),
      choice("lighting", {"probes", "environment"}, "probes", "transgi: light from the probes, or the environment's SH only"),
      choice("transfer", {"network", "ground-truth"}, "network", "transgi --lighting environment: decoded or traced transfer"),
      integer("gt-rays", "N", 1, 1'000'000, "2048", "rays per point for --transfer ground-truth"),
      text("coefficient-maps", "PREFIX", "none", "transgi --lighting environment: write three SH coefficient images"),
      flag("allow-unbaked", "transgi: shade meshes the model has no latents for diffusely instead of refusing"),
      text("no-latent", "NODE,...", "none", "transgi: shade these nodes as if unbaked"),
      integer("frames", "F", 1, 100000,
              std::to_string(runtime::quality_preset().probes.accumulation.warmup_frames + runtime::quality_preset().temporal_window) +
                  " (transgi: the probes' warm-up, then the temporal window), 400 (ddgi)",
              "frames run before the image is taken"),
      integer("timing-frames", "N", 1, 1000, "3", "last frames whose stage times are reported"),
      integer("temporal-window", "N", 1, 1024, std::to_string(runtime::quality_preset().temporal_window),
              "transgi quality path: a still view's GI is the mean of the last N jittered frames: higher = smoother "
              "edges and less noise, at the cost of N frames to settle"),
      integer("direct-spp", "N", 1, 100000, "16", "direct-light samples per pixel (--direct stochastic, quality path)"),
      integer("probe-rays", "M", 1, 100000, "100 (transgi), 256 (ddgi)",
              "rays per probe a frame: higher = less probe noise, at the cost of probe time"),
      choice("probe-skip", {"on", "off"}, "on", "transgi: skip probes in walls and probes whose light has converged"),
      choice("sharing", {"depth-guard", "paper"}, "depth-guard", "transgi: radiance sharing across probes, guarded by depth or as the paper"),
      number("hysteresis", "H", 0.0, 1.0, number_text(d.hysteresis), "ddgi: weight of the old irradiance: higher = steadier, at the cost of lag"),
      number("brightness-threshold", "B", 0.0, 1e30, std::isfinite(d.brightness_threshold) ? number_text(d.brightness_threshold) : "off",
             "ddgi: a texel's largest change an update (in RTXGI's gamma-5 units; RTXGI's is 0.1) before it moves only a quarter of "
             "the way: lower = steadier under fireflies, at the cost of a darker mean under daylight"),
      integer("warmup-frames", "W", 0, 100000, "64", "ddgi: first frames blended without hysteresis"),
      number("irradiance-gamma", "G", 0.1, 20.0, number_text(d.irradiance_gamma),
             "ddgi: the irradiance maps' encoding gamma: 1 averages the irradiance, RTXGI's 5 its fifth root (lower under noise)"),
  };
  append(o, runtime_option_specs("quality"));
  append(o, placement_option_specs(runtime::ProbeVolumeMode::Cascades));
  append(o, sun_option_specs());
  return o;
}

namespace {

// The options of a command that runs the real-time frame on a scene: the
// scene and model first, the command's own, then the runtime's and the probe
// placement's.
std::vector<OptionSpec> real_time_run_specs(std::vector<OptionSpec> own) {
  std::vector<OptionSpec> o = {
      text("scene", "PATH", "", "the glTF scene"),
      text("model", "PATH", "", "the baked transfer model (.tgm)"),
      flag("allow-unbaked", "shade meshes the model has no latents for diffusely instead of refusing"),
  };
  append(o, std::move(own));
  append(o, runtime_option_specs("realtime"));
  append(o, placement_option_specs(runtime::ProbeVolumeMode::Cascades));
  return o;
}

}  // namespace

const char* const kBenchFrameSynopsis =
    "usage: transgi bench-frame --scene S.gltf --model M.tgm [options]\n"
    "  The real-time frame's time, stage by stage, with an object moving.\n";

std::vector<OptionSpec> bench_frame_option_specs() {
  const runtime::TransGISettings r = runtime::realtime_preset();
  return real_time_run_specs({
      integer("width", "W", 16, 8192, "640", "frame width in pixels"),
      integer("height", "H", 16, 8192, "360", "frame height in pixels"),
      integer("frames", "N", 1, 100000, "100", "frames timed"),
      integer("warmup", "N", 0, 100000, "64", "frames run before the timing starts"),
      integer("threads", "T", 0, 1024, "0 (every core)", "worker threads"),
      text("camera", "NAME", "the scene's first", "the camera node to render from"),
      text("object", "NAME", "the smallest mesh node a tenth of the scene's size or more",
           "the node moved on an orbit 0.15 of its size wide, a turn every 120 frames"),
      text("csv", "PATH", "none", "every frame's stage times as CSV"),
      integer("direct-spp", "N", 0, 100000, std::to_string(r.direct_spp), "direct-light samples per pixel (--direct stochastic)"),
      text("gi-out", "PATH", "none", "the last frame's GI pass as EXR"),
      text("reference-out", "PATH", "none", "the path tracer's GI pass of the moved scene as EXR"),
      integer("reference-spp", "N", 1, 1 << 20, "1024", "samples per pixel of --reference-out"),
  });
}

const char* const kFlyThroughSynopsis =
    "usage: transgi fly-through --scene S.gltf --model M.tgm --out DIR --path X,Y,Z;X,Y,Z;... [options]\n"
    "  The camera flies the path with the real-time frame running; every frame is checked, and the stops are\n"
    "  compared with the path tracer.\n";

std::vector<OptionSpec> fly_through_option_specs() {
  return real_time_run_specs({
      text("out", "DIR", "", "the folder the stops' GI images, the path tracer's and the per-frame CSV go to"),
      text("path", "X,Y,Z;...", "", "the camera's polyline, two points or more, flown at an even speed"),
      integer("width", "W", 16, 8192, "320", "frame width in pixels"),
      integer("height", "H", 16, 8192, "180", "frame height in pixels"),
      integer("frames", "N", 2, 100000, "300", "frames the flight takes"),
      text("stops", "F,F,...", "a third, two thirds and the last frame", "frames compared with the path tracer"),
      integer("reference-spp", "N", 0, 1 << 20, "256", "the path tracer's samples per pixel at the stops (0 = no comparison)"),
      number("pitch", "DEG", -89.0, 89.0, "-10", "the camera's pitch while it flies"),
      integer("threads", "T", 0, 1024, "0 (every core)", "worker threads"),
  });
}

const char* const kSunSweepSynopsis =
    "usage: transgi sun-sweep --scene S.gltf --model M.tgm --out DIR [options]\n"
    "  The sun steps across the sky with the real-time frame running; after each step, the frames until the GI\n"
    "  settles, and the settled image against the path tracer.\n";

std::vector<OptionSpec> sun_sweep_option_specs() {
  return real_time_run_specs({
      text("out", "DIR", "", "the folder the settled GI images, the path tracer's and the CSVs go to"),
      integer("width", "W", 16, 8192, "320", "frame width in pixels"),
      integer("height", "H", 16, 8192, "180", "frame height in pixels"),
      text("camera", "NAME", "the scene's first", "the camera node to render from"),
      integer("positions", "N", 1, 360, "8", "places the sun steps through"),
      integer("frames", "N", 17, 100000, "96", "frames run at each place"),
      integer("warmup", "N", 0, 100000, "96", "frames run before the first step"),
      number("elevation-from", "DEG", -90, 90, "10", "the sun's first elevation"),
      number("elevation-to", "DEG", -90, 90, "80", "the sun's last elevation"),
      number("azimuth-from", "DEG", -360, 360, "the scene's sun", "the sun's first azimuth"),
      number("azimuth-to", "DEG", -360, 360, "the scene's sun", "the sun's last azimuth"),
      number("settle-tolerance", "F", 1e-4, 1.0, "0.05", "how near its settled value the GI's mean must stay to count as settled"),
      integer("reference-spp", "N", 0, 1 << 20, "512", "the path tracer's samples per pixel (0 = no comparison)"),
      choice("probe-skip", {"on", "off"}, "on", "skip probes in walls and probes whose light has converged"),
      integer("threads", "T", 0, 1024, "0 (every core)", "worker threads"),
  });
}

}  // namespace transgi::cli
