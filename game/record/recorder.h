#pragma once
// Writes a recorded run: frame_NNNN.png for every frame, then (where ffmpeg
// is on the PATH) run.mp4, and contact_sheet.png, a grid of evenly spaced
// frames. Every file is written to a temporary name and renamed.
#include <filesystem>
#include <string>
#include <vector>

#include "engine/image/image.h"

namespace game {

class Recorder {
 public:
  // Creates `dir`. Throws naming it if it cannot.
  explicit Recorder(std::filesystem::path dir, float exposure_stops = 0.0f);
  void add_frame(const engine::image::ImageRGB& linear);
  // Writes the MP4 (if ffmpeg is found) and the contact sheet; returns what
  // was written, one line per file.
  std::vector<std::string> finish(int fps = 30, int sheet_columns = 4, int sheet_frames = 12);
  [[nodiscard]] int frames() const { return frames_; }

 private:
  std::filesystem::path dir_;
  float exposure_;
  int frames_ = 0;
};

// A grid of the given PNG frames, each scaled by 1/downscale, with a thin
// gap; the frames must share one size.
void write_contact_sheet(const std::filesystem::path& out, const std::vector<std::filesystem::path>& frames, int columns,
                         int downscale);

}  // namespace game
