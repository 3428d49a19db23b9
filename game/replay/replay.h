#pragma once
// Timed input for headless and recorded runs: one event per line,
//   <frame> <event> [args]     # comment
// events:
//   key_down K / key_up K      a named key ("W", "E", "space", "ctrl")
//   key_press K                down this frame, up the next
//   mouse_move X Y             cursor to pixel (X, Y) of the view, y down
//   mouse_move_by DX DY        cursor moved by (DX, DY) pixels
//   mouse_down B / mouse_up B  B = left | right; held as key "mouse_B"
//   select NAME                the editor selects the entity (as a click in its list)
//   gizmo_grab HANDLE          cursor onto the selection's gizmo handle:
//                              x, y, z (translate axes), xy, yz, zx (translate
//                              planes) or rx, ry, rz (rings)
//   gizmo_mode translate|rotate
//   method transgi|ddgi|reference   what the view shows
//   view full|gi|direct             which pass
//   backend cpu|vulkan             where GI's probe work runs (issue 12)
//   reload_shaders                  compile shaders/ again; rebuild the GPU kernels if all compile
#include <filesystem>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace game {

struct ReplayEvent {
  int frame = 0;
  std::string kind;
  std::string name;      // key, button, entity, handle or mode
  glm::vec2 xy{0.0f};    // mouse_move(_by)
  int line = 0;
  std::string file;      // the replay it came from, as given to parse_replay
  // "file:line", for messages about this event.
  [[nodiscard]] std::string where() const { return file + ":" + std::to_string(line); }
};

// Sorted by frame, file order kept within a frame. Throws naming the file
// and line on a bad event.
std::vector<ReplayEvent> load_replay(const std::filesystem::path& file);
std::vector<ReplayEvent> parse_replay(const std::string& text, const std::string& name);

}  // namespace game
