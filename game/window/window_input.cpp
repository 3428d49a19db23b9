#include <string>
#include "window/window_input.h"

#include <GLFW/glfw3.h>

namespace game {

std::string key_name(int k) {
  if (k >= GLFW_KEY_A && k <= GLFW_KEY_Z) return std::string(1, static_cast<char>('A' + (k - GLFW_KEY_A)));
  if (k >= GLFW_KEY_0 && k <= GLFW_KEY_9) return std::string(1, static_cast<char>('0' + (k - GLFW_KEY_0)));
  if (k >= GLFW_KEY_F1 && k <= GLFW_KEY_F12) {
    std::string name = "F";  // appended, not "F" + ...: GCC 12 warns of a bogus memcpy on that form
    name += std::to_string(k - GLFW_KEY_F1 + 1);
    return name;
  }
  switch (k) {
    case GLFW_KEY_SPACE: return "space";
    case GLFW_KEY_LEFT_CONTROL: case GLFW_KEY_RIGHT_CONTROL: return "ctrl";
    case GLFW_KEY_LEFT_SHIFT: case GLFW_KEY_RIGHT_SHIFT: return "shift";
    case GLFW_KEY_ESCAPE: return "escape";
    case GLFW_KEY_DELETE: return "delete";
    case GLFW_KEY_TAB: return "tab";
    default: return "";
  }
}

}  // namespace game
