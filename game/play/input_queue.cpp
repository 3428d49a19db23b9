#include "play/input_queue.h"

namespace game {

void apply_input_events(engine::input::InputState& in, const std::vector<InputEvent>& events, bool keyboard_free,
                        bool mouse_free) {
  for (const InputEvent& e : events) {
    if (e.name.empty()) continue;
    if (e.down && !(e.mouse ? mouse_free : keyboard_free)) continue;  // the editor's
    in.set_key(e.name, e.down);
  }
}

}  // namespace game
