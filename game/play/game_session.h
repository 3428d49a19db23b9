#pragma once
// One running game: the level (glTF + baked GI model + game.json), the
// TransGI plugin on its real-time preset, Lua scripts, the fly camera and
// the editor tools. A window, a headless replay and the tests all drive it
// the same way: set this frame's input, then frame().
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "editor/editor_tools.h"
#include "engine/gpu/vulkan_context.h"
#include "engine/app/app.h"
#include "engine/image/image.h"
#include "engine/input/input_state.h"
#include "replay/replay.h"

namespace game {

// What the view shows: TransGI (the game's renderer), the DDGI baseline, or
// the reference path tracer accumulating while nothing moves.
enum class GameMethod { TransGI, Ddgi, Reference };
const char* method_name(GameMethod m);

struct GameOptions {
  std::filesystem::path scene;     // the level's glTF
  std::filesystem::path model;     // empty = transgi.tgm beside the scene
  std::filesystem::path manifest;  // empty = game.json beside the scene, if there is one
  int width = 640, height = 360;
  int threads = 0;                 // 0 = all cores
  std::string view = "full";       // full | gi | direct
  GameMethod method = GameMethod::TransGI;  // what the view shows at start
  // Probe updates run before the first frame a player sees, as a loading
  // screen would (game time paused, no image made): the first frames
  // showed probe-sized bright squares while the probes settled. -1 = the
  // real-time preset's settle_frames; 0 = none. Higher = a better-settled
  // first frame, at the cost of that many probe updates of load time.
  int probe_warmup_frames = -1;
  // Then (unless the probes' warm-up is 0) frames made and thrown away, the
  // near field tracing every GI cell (GameSession::warm_up): 8 = its
  // per-cell mean's span. Higher = a steadier first frame, at the cost of
  // about 60 ms of load time each at 640x360.
  int image_warmup_frames = 8;
  // (entity name, Lua file): each named entity runs that script instead of
  // its own (--script ENTITY=FILE), for quick tries; a relative file is
  // taken from the working directory.
  std::vector<std::pair<std::string, std::filesystem::path>> scripts;
  // Where GI's probe work runs from the first frame: "cpu" or "vulkan"
  // (set_backend's choice).
  std::string backend = "cpu";
  // With "vulkan": the kernels run on this device (the window's own, which
  // presents the frames through its swapchain) rather than on one the
  // plugin makes. Null: the plugin makes its own.
  std::shared_ptr<engine::gpu::VulkanContext> host_gpu;
};

// "transgi" | "ddgi" | "reference", as the command line and replays name them.
GameMethod parse_method(const std::string& name);

// The top of a graph of these frame times: the largest, rounded up to 1, 2
// or 5 times a power of ten (at least 10 ms), so the scale reads easily and
// follows the frame time from 5 ms to 5 s.
float graph_top(const std::vector<float>& frame_ms);

class GameSession {
 public:
  // Throws std::runtime_error naming the file and field on bad content.
  explicit GameSession(const GameOptions& options);
  ~GameSession();

  // Starts a frame's input: clears last frame's presses, then applies the
  // replay events (if any) for this frame.
  void begin_input();
  void apply(const ReplayEvent& e);
  // Runs the editor tools and one App frame (scripts, transforms, GI).
  void frame();

  [[nodiscard]] const engine::image::ImageRGB& image() const;
  // Switch the method and pass (full | gi | direct); both take effect at the next frame.
  void set_method(GameMethod m);
  // Where GI's probe work runs ("cpu" or "vulkan"), for TransGI and DDGI
  // alike; from the next frame. Without a Vulkan device the CPU goes on and
  // backend_status() says why.
  void set_backend(const std::string& backend);
  [[nodiscard]] std::string backend_status();
  // Shader hot reload: compiles shaders/ (or $TRANSGI_SHADER_DIR) again; if
  // all compile, the GPU kernels are rebuilt from them at the next frame,
  // else each error goes to the log as "file:line: error: ..." and the
  // running kernels stay. Returns the errors.
  std::vector<std::string> reload_shaders();
  void set_view(const std::string& view);
  [[nodiscard]] GameMethod method() const { return method_; }
  [[nodiscard]] const std::string& view_name() const { return options_.view; }
  // Reference samples per pixel accumulated since the last change.
  [[nodiscard]] int reference_spp() const;
  // The level's first probe updates, before the first frame
  // (GameOptions::probe_warmup_frames), then a few frames made and thrown
  // away (GameOptions::image_warmup_frames): the near field's per-cell
  // means and the antialiasing's history start full, where one frame's
  // sparse lattice of contact rays left blocks on shaded faces for the first
  // dozen frames.
  void warm_up();
  // The last frame's stage times of the method shown (TransGI's, DDGI's, or
  // the path tracer's), named as the stats overlay shows them.
  struct StageTime {
    std::string name;
    double ms = 0;
  };
  [[nodiscard]] std::vector<StageTime> stage_times() const;
  [[nodiscard]] const GameOptions& options() const { return options_; }
  [[nodiscard]] engine::ecs::World& world();
  [[nodiscard]] engine::input::InputState& input();
  [[nodiscard]] EditorState& editor() { return editor_; }
  [[nodiscard]] EditorView view();
  [[nodiscard]] engine::ecs::Entity find(const std::string& name);
  [[nodiscard]] double last_frame_ms() const { return last_ms_; }
  [[nodiscard]] std::uint64_t frames() const { return frames_; }

 private:
  GameOptions options_;
  std::unique_ptr<engine::app::App> app_;
  engine::ecs::Entity camera_;
  EditorState editor_;
  GameMethod method_ = GameMethod::TransGI;
  std::string ddgi_backend_ = "cpu";  // applied to DDGI when its plugin is first added
  struct Reference;
  std::unique_ptr<Reference> reference_;
  void render_reference();
  double last_ms_ = 0;
  std::uint64_t frames_ = 0;
};

}  // namespace game
