#pragma once
// Window input as events, in the order they happened, applied once a frame.
// Polling the keys once a frame loses a tap shorter than a frame: at 2-4 fps
// a click or a tap of E (100 ms) falls between two polls. The window's
// callbacks queue every change instead, and a key that went down and up
// within one frame still reads as pressed (and released) in that frame.
#include <string>
#include <vector>

#include "engine/input/input_state.h"

namespace game {

struct InputEvent {
  std::string name;    // an engine key name ("E", "ctrl", "mouse_left")
  bool down = false;   // pressed (true) or released
  bool mouse = false;  // a mouse button, else a key
};

// Applies a frame's queued events in order. A press reaches the game only
// where the editor does not want it: a key when ImGui does not take the
// keyboard (keyboard_free), a mouse button when the cursor is over the game
// view and not a panel (mouse_free). Releases always do, so nothing sticks.
void apply_input_events(engine::input::InputState& in, const std::vector<InputEvent>& events, bool keyboard_free,
                        bool mouse_free);

}  // namespace game
