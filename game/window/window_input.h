#pragma once
// GLFW keys and buttons as the engine's named keys.
#include <string>

namespace game {

// "A".."Z", "0".."9", "space", "ctrl", "shift", "escape", "delete", "tab",
// or "" for keys the game does not name.
std::string key_name(int glfw_key);

}  // namespace game
