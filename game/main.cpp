// transgi-game: the sample level as a small game, in a window with the editor
// (the default), or headless, replaying timed input and recording frames:
//   transgi-game [--frames N --screenshot F.png] [--scene ...]
//   transgi-game --headless --frames N [--script-input replay.txt] [--record DIR] [--screenshot F.png]
//                [--scene level.gltf] [--model M.tgm] [--game game.json] [--width W --height H] [--view full|gi|direct]
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>
#include <vector>

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
    "                    [--view full|gi|direct] [--exposure STOPS] [--threads T]\n"
    "  window only: [--select NAME] [--gizmo translate|rotate] (what the editor shows at start)\n";

struct Cli {
  std::map<std::string, std::string> values;
  bool headless = false;
};

Cli parse(int argc, char** argv) {
  static const std::vector<std::string> kValued = {"frames", "script-input", "record", "screenshot", "scene", "model",
                                                   "game", "width", "height", "view", "exposure", "threads", "select", "gizmo"};
  Cli c;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--headless") {
      c.headless = true;
      continue;
    }
    if (a == "--help" || a == "-h") {
      std::fputs(kUsage, stdout);
      std::exit(0);
    }
    if (a.rfind("--", 0) != 0) throw std::runtime_error("unexpected argument '" + a + "'");
    const std::string key = a.substr(2);
    if (std::find(kValued.begin(), kValued.end(), key) == kValued.end()) throw std::runtime_error("unknown option --" + key);
    if (i + 1 >= argc) throw std::runtime_error("--" + key + " needs a value");
    c.values[key] = argv[++i];
  }
  return c;
}

int integer(const Cli& c, const std::string& key, int lo, int hi, int fallback) {
  auto it = c.values.find(key);
  if (it == c.values.end()) return fallback;
  try {
    std::size_t used = 0;
    const long v = std::stol(it->second, &used);
    if (used == it->second.size() && v >= lo && v <= hi) return static_cast<int>(v);
  } catch (const std::exception&) {
  }
  throw std::runtime_error("--" + key + ": expected an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got '" +
                           it->second + "'");
}

std::string value(const Cli& c, const std::string& key, const std::string& fallback = {}) {
  auto it = c.values.find(key);
  return it == c.values.end() ? fallback : it->second;
}

// What the window and headless runs share.
game::GameOptions game_options(const Cli& cli) {
  game::GameOptions o;
  o.scene = value(cli, "scene", TRANSGI_DEFAULT_LEVEL);
  o.model = value(cli, "model");
  o.manifest = value(cli, "game");
  o.width = integer(cli, "width", 16, 8192, 640);
  o.height = integer(cli, "height", 16, 8192, 360);
  o.threads = integer(cli, "threads", 0, 1024, 0);
  o.view = value(cli, "view", "full");
  return o;
}

int run_headless(const Cli& cli) {
  const game::GameOptions o = game_options(cli);
  const int frames = integer(cli, "frames", 1, 1000000, 120);
  float exposure = 0.0f;
  if (auto e = value(cli, "exposure"); !e.empty()) {
    try {
      exposure = std::stof(e);
    } catch (const std::exception&) {
      throw std::runtime_error("--exposure: expected a number of stops, got '" + e + "'");
    }
    if (!std::isfinite(exposure) || std::abs(exposure) > 20) throw std::runtime_error("--exposure: must be within [-20, 20] stops");
  }
  std::vector<game::ReplayEvent> events;
  if (auto r = value(cli, "script-input"); !r.empty()) events = game::load_replay(r);
  std::unique_ptr<game::Recorder> recorder;
  if (auto dir = value(cli, "record"); !dir.empty()) recorder = std::make_unique<game::Recorder>(dir, exposure);

  game::GameSession session(o);
  engine::core::ProgressBar bar("transgi-game", static_cast<std::uint64_t>(frames), true);
  std::size_t next = 0;
  double total_ms = 0;
  for (int f = 0; f < frames; ++f) {
    session.begin_input();
    for (; next < events.size() && events[next].frame <= f; ++next) session.apply(events[next]);
    session.frame();
    total_ms += session.last_frame_ms();
    if (recorder) recorder->add_frame(session.image());
    bar.update(static_cast<std::uint64_t>(f + 1));
  }
  if (next < events.size())
    std::fprintf(stderr, "warning: %zu replay events after frame %d were not played\n", events.size() - next, frames - 1);
  std::printf("%d frames at %dx%d, mean frame %.1f ms (engine frame: editor, scripts, GI, direct light, composite)\n", frames,
              o.width, o.height, total_ms / frames);
  const auto& log = session.world().resource<engine::core::Log>();
  std::printf("log: %zu errors, %zu warnings\n", log.count(engine::core::LogLevel::Error), log.count(engine::core::LogLevel::Warning));
  if (auto shot = value(cli, "screenshot"); !shot.empty()) {
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
    const Cli cli = parse(argc, argv);
    if (!cli.headless) {
      for (const char* headless_only : {"script-input", "record"})
        if (cli.values.contains(headless_only)) throw std::runtime_error(std::string("--") + headless_only + " needs --headless");
      const game::GameOptions o = game_options(cli);
      game::WindowOptions w;
      w.frames = integer(cli, "frames", 0, 1000000, 0);
      w.screenshot = value(cli, "screenshot");
      w.select = value(cli, "select");
      w.gizmo = value(cli, "gizmo", "translate");
      return game::run_window(o, w);
    }
    return run_headless(cli);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "transgi-game: %s\n", e.what());
    return 1;
  }
}
