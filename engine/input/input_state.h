#pragma once
// Keyboard and mouse state for one frame, as a World resource. A window (or
// a replayed input file) writes it before App::update(); gameplay systems
// and scripts read it in Update. Keys are named, not numbered, so scripts and
// replay files say "E", "space" or "mouse_left" whatever the window library.
#include <string>
#include <unordered_set>

#include <glm/glm.hpp>

namespace engine::input {

struct InputState {
  std::unordered_set<std::string> down;      // held now
  std::unordered_set<std::string> pressed;   // went down during this frame
  std::unordered_set<std::string> released;  // went up during this frame
  glm::vec2 mouse{0.0f};        // cursor, pixels from the top-left of the view
  glm::vec2 mouse_delta{0.0f};  // cursor motion during this frame

  // Call once per frame before the new frame's events.
  void begin_frame() {
    pressed.clear();
    released.clear();
    mouse_delta = glm::vec2(0.0f);
  }
  void set_key(const std::string& key, bool is_down) {
    if (is_down) {
      if (down.insert(key).second) pressed.insert(key);
    } else if (down.erase(key) > 0) {
      released.insert(key);
    }
  }
  void move_mouse(const glm::vec2& to) {
    mouse_delta += to - mouse;
    mouse = to;
  }
  [[nodiscard]] bool is_down(const std::string& key) const { return down.contains(key); }
  [[nodiscard]] bool was_pressed(const std::string& key) const { return pressed.contains(key); }
};

}  // namespace engine::input
