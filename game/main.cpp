// transgi-game: the sample level as a small game, in a window with the editor
// (the default), or headless, replaying timed input and recording frames:
//   transgi-game [--frames N --screenshot F.png] [--scene ...]
//   transgi-game --headless --frames N [--script-input replay.txt] [--record DIR] [--screenshot F.png]
//                [--scene level.gltf] [--model M.tgm] [--game game.json] [--width W --height H] [--view full|gi|direct]
//                [--method transgi|ddgi|reference]
// Exit codes: kUsage below.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <numeric>
#include <sstream>
#include <string>
#include <vector>

#include "engine/core/args.h"
#include "engine/core/install_paths.h"
#include "engine/core/log.h"
#include "engine/core/progress.h"
#include "engine/image/tonemap.h"
#include "play/game_session.h"
#include "record/recorder.h"
#include "replay/replay.h"
#include "window/window_run.h"

namespace {

constexpr const char* kUsage =
    "usage: transgi-game [--headless] [--frames N] [--script-input replay.txt] [--record DIR] [--screenshot F.png]\n"
    "                    [--scene level.gltf] [--model M.tgm] [--game game.json] [--width W] [--height H]\n"
    "                    [--method transgi|ddgi|reference] [--view full|gi|direct] [--exposure STOPS] [--threads T]\n"
    "                    [--backend cpu|vulkan] (vulkan: the GI's probe work on the GPU; in a window, the frames\n"
    "                    presented through a Vulkan swapchain on the same device)\n"
    "                    [--script ENTITY=FILE[,ENTITY=FILE...]] (the entity runs that Lua file instead of its own)\n"
    "  window only: [--select NAME] [--gizmo translate|rotate] [--probes] (what the editor shows at start)\n"
    "  headless only: [--script-input replay.txt] [--record DIR]\n"
    "exit codes: 0 the run finished with no error logged; 1 it could not run (a missing or bad scene, model,\n"
    "  manifest or replay file: the message names it); 2 a bad command line; 3 the run finished and wrote its\n"
    "  outputs, but errors were logged on the way (a replay event that could not apply, a failing script: see\n"
    "  the \"log:\" line and the messages above it).\n";

engine::core::Args parse(int argc, char** argv) {
  return engine::core::Args("transgi-game", std::vector<std::string>(argv + 1, argv + argc),
                            {"frames", "script-input", "record", "screenshot", "scene", "model", "game", "width", "height", "view",
                             "method", "script", "exposure", "threads", "select", "gizmo", "backend"},
                            {"headless", "help", "probes"});
}

// The sample level: installed beside the program (bin/ ->
// share/transgi/levels), else in the source tree.
std::filesystem::path default_level() {
  if (auto level = engine::core::beside_executable("../share/transgi/levels/living_room/scene.gltf")) return *level;
  return TRANSGI_DEFAULT_LEVEL;
}

// What the window and headless runs share.
game::GameOptions game_options(const engine::core::Args& args) {
  game::GameOptions o;
  o.scene = args.str("scene", default_level().string());
  o.model = args.str("model", std::string());
  o.manifest = args.str("game", std::string());
  o.width = static_cast<int>(args.integer("width", 16, 8192, 640));
  o.height = static_cast<int>(args.integer("height", 16, 8192, 360));
  o.threads = static_cast<int>(args.integer("threads", 0, 1024, 0));
  o.view = args.choice("view", {"full", "gi", "direct"}, "full");
  o.method = game::parse_method(args.choice("method", {"transgi", "ddgi", "reference"}, "transgi"));
  o.backend = args.choice("backend", {"cpu", "vulkan"}, "cpu");
  if (args.has("script")) {
    std::stringstream list(args.str("script"));
    for (std::string item; std::getline(list, item, ',');) {
      const auto eq = item.find('=');
      if (eq == std::string::npos || eq == 0 || eq + 1 == item.size())
        throw engine::core::UsageError("transgi-game: --script: expected ENTITY=FILE, got '" + item + "'");
      o.scripts.emplace_back(item.substr(0, eq), item.substr(eq + 1));
    }
  }
  return o;
}

int run_headless(const engine::core::Args& args) {
  const game::GameOptions o = game_options(args);
  const int frames = static_cast<int>(args.integer("frames", 1, 1000000, 120));
  const auto exposure = static_cast<float>(args.number("exposure", -20.0, 20.0, 0.0));
  std::vector<game::ReplayEvent> events;
  if (args.has("script-input")) events = game::load_replay(args.str("script-input"));
  std::unique_ptr<game::Recorder> recorder;
  if (args.has("record")) recorder = std::make_unique<game::Recorder>(args.str("record"), exposure);

  game::GameSession session(o);
  engine::core::ProgressBar bar("transgi-game", static_cast<std::uint64_t>(frames), true);
  std::size_t next = 0;
  std::vector<double> frame_ms;
  for (int f = 0; f < frames; ++f) {
    session.begin_input();
    // An event that cannot apply (no such entity, a handle out of view) is
    // logged and skipped: the run goes on to write its frames, and exits 3.
    for (; next < events.size() && events[next].frame <= f; ++next) {
      try {
        session.apply(events[next]);
      } catch (const std::exception& e) {
        session.world().resource<engine::core::Log>().error("replay", e.what());
      }
    }
    session.frame();
    frame_ms.push_back(session.last_frame_ms());
    if (recorder) recorder->add_frame(session.image());
    bar.update(static_cast<std::uint64_t>(f + 1));
  }
  if (next < events.size())
    std::fprintf(stderr, "warning: %zu replay events after frame %d were not played\n", events.size() - next, frames - 1);
  std::printf("%d frames at %dx%d, mean frame %.1f ms (engine frame: editor, scripts, GI, direct light, composite)\n", frames,
              o.width, o.height, std::accumulate(frame_ms.begin(), frame_ms.end(), 0.0) / frames);
  // The first frames warm probes up; the second half is the steady state.
  std::vector<double> late(frame_ms.begin() + frames / 2, frame_ms.end());
  std::nth_element(late.begin(), late.begin() + static_cast<std::ptrdiff_t>(late.size() / 2), late.end());
  std::printf("median frame of the last %zu: %.1f ms; %s stages of the last frame (ms):", late.size(),
              late[late.size() / 2], game::method_name(session.method()));
  for (const auto& st : session.stage_times()) std::printf(" %s %.2f;", st.name.c_str(), st.ms);
  std::printf("\n");
  const auto& log = session.world().resource<engine::core::Log>();
  std::printf("log: %zu errors, %zu warnings\n", log.count(engine::core::LogLevel::Error), log.count(engine::core::LogLevel::Warning));
  if (args.has("screenshot")) {
    const std::string shot = args.str("screenshot");
    engine::image::write_png_srgb(shot, session.image(), exposure);
    std::printf("wrote %s\n", shot.c_str());
  }
  if (recorder)
    for (const std::string& line : recorder->finish()) std::printf("wrote %s\n", line.c_str());
  return log.count(engine::core::LogLevel::Error) > 0 ? 3 : 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const engine::core::Args args = parse(argc, argv);
    if (args.has("help")) {
      std::fputs(kUsage, stdout);
      return 0;
    }
    if (!args.positional().empty()) throw engine::core::UsageError("transgi-game: unexpected argument '" + args.positional()[0] + "'");
    if (!args.has("headless")) {
      for (const char* headless_only : {"script-input", "record"})
        if (args.has(headless_only)) throw engine::core::UsageError(std::string("transgi-game: --") + headless_only + " needs --headless");
      game::WindowOptions w;
      w.frames = static_cast<int>(args.integer("frames", 0, 1000000, 0));
      w.screenshot = args.str("screenshot", std::string());
      w.select = args.str("select", std::string());
      w.gizmo = args.choice("gizmo", {"translate", "rotate"}, "translate");
      w.probes = args.has("probes");
      return game::run_window(game_options(args), w);
    }
    for (const char* window_only : {"select", "gizmo", "probes"})
      if (args.has(window_only))
        throw engine::core::UsageError(std::string("transgi-game: --") + window_only +
                                       " sets what the editor shows at start, and --headless has no editor: drop one of them");
    return run_headless(args);
  } catch (const engine::core::UsageError& e) {
    std::fprintf(stderr, "%s\n%s", e.what(), kUsage);
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "transgi-game: %s\n", e.what());
    return 1;
  }
}
