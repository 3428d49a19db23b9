#pragma once
// The interactive game: a GLFW window (OpenGL 3.3 core) showing the
// session's frame, with the Dear ImGui editor over it.
#include <filesystem>
#include <string>

#include "play/game_session.h"

namespace game {

struct WindowOptions {
  int frames = 0;                    // > 0: close after this many frames
  std::filesystem::path screenshot;  // written from the window's back buffer before closing
  int window_width = 1280, window_height = 720;
  std::string select;                 // an entity selected at start (scripted screenshots)
  std::string gizmo = "translate";    // translate | rotate
  bool probes = false;                // the probe overlay on at start (View > Probes)
};

// Returns the exit code. A missing display, a GL context that cannot be
// made and a bad scene end with a message, never a crash.
int run_window(const GameOptions& game, const WindowOptions& window);

}  // namespace game
