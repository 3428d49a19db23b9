#include "replay/replay.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

namespace game {

std::vector<ReplayEvent> parse_replay(const std::string& text, const std::string& name) {
  static const std::set<std::string> kNamed = {"key_down", "key_up", "key_press", "mouse_down", "mouse_up",
                                               "select", "gizmo_grab", "gizmo_mode", "method", "view", "backend"};
  static const std::set<std::string> kXY = {"mouse_move", "mouse_move_by"};
  std::vector<ReplayEvent> out;
  std::istringstream in(text);
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    if (auto hash = line.find('#'); hash != std::string::npos) line.erase(hash);
    std::istringstream words(line);
    std::string frame_word;
    if (!(words >> frame_word)) continue;
    auto bad = [&](const std::string& why) { throw std::runtime_error(name + ":" + std::to_string(n) + ": " + why); };
    ReplayEvent e;
    e.line = n;
    e.file = name;
    try {
      std::size_t used = 0;
      e.frame = std::stoi(frame_word, &used);
      if (used != frame_word.size() || e.frame < 0) bad("the frame must be a non-negative integer, got '" + frame_word + "'");
    } catch (const std::logic_error&) {
      bad("the frame must be a non-negative integer, got '" + frame_word + "'");
    }
    if (!(words >> e.kind)) bad("an event must follow the frame");
    if (kNamed.contains(e.kind)) {
      if (!(words >> e.name)) bad(e.kind + " needs a name");
      if ((e.kind == "mouse_down" || e.kind == "mouse_up") && e.name != "left" && e.name != "right")
        bad(e.kind + ": the button must be left or right, got '" + e.name + "'");
      if (e.kind == "gizmo_mode" && e.name != "translate" && e.name != "rotate")
        bad("gizmo_mode: expected translate or rotate, got '" + e.name + "'");
      if (e.kind == "method" && e.name != "transgi" && e.name != "ddgi" && e.name != "reference")
        bad("method: expected transgi, ddgi or reference, got '" + e.name + "'");
      if (e.kind == "backend" && e.name != "cpu" && e.name != "vulkan")
        bad("backend: expected cpu or vulkan, got '" + e.name + "'");
      if (e.kind == "view" && e.name != "full" && e.name != "gi" && e.name != "direct")
        bad("view: expected full, gi or direct, got '" + e.name + "'");
      if (e.kind == "gizmo_grab" && !std::set<std::string>{"x", "y", "z", "xy", "yz", "zx", "rx", "ry", "rz"}.contains(e.name))
        bad("gizmo_grab: expected x, y, z, xy, yz, zx, rx, ry or rz, got '" + e.name + "'");
    } else if (kXY.contains(e.kind)) {
      if (!(words >> e.xy.x >> e.xy.y) || !std::isfinite(e.xy.x) || !std::isfinite(e.xy.y))
        bad(e.kind + " needs two finite numbers");
    } else if (e.kind != "reload_shaders") {  // the one event with no argument
      bad("unknown event '" + e.kind + "'");
    }
    std::string extra;
    if (words >> extra) bad("unexpected '" + extra + "' after the event");
    out.push_back(e);
  }
  std::stable_sort(out.begin(), out.end(), [](const ReplayEvent& a, const ReplayEvent& b) { return a.frame < b.frame; });
  return out;
}

std::vector<ReplayEvent> load_replay(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error(file.string() + ": cannot open the input replay");
  std::ostringstream text;
  text << in.rdbuf();
  return parse_replay(text.str(), file.string());
}

}  // namespace game
