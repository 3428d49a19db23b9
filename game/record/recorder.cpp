#include "record/recorder.h"

#include <cstdio>
#include <cstdlib>
#include <stdexcept>

#include "engine/image/png.h"
#include "engine/image/tonemap.h"

namespace game {

namespace fs = std::filesystem;

namespace {

std::string frame_name(int i) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "frame_%04d.png", i);
  return buf;
}

bool ffmpeg_available() { return std::system("command -v ffmpeg >/dev/null 2>&1") == 0; }

}  // namespace

Recorder::Recorder(fs::path dir, float exposure_stops) : dir_(std::move(dir)), exposure_(exposure_stops) {
  std::error_code ec;
  fs::create_directories(dir_, ec);
  if (ec || !fs::is_directory(dir_)) throw std::runtime_error(dir_.string() + ": cannot create the recording folder: " + ec.message());
  for (const auto& entry : fs::directory_iterator(dir_))  // a shorter run must not leave an older run's frames behind
    if (entry.path().filename().string().rfind("frame_", 0) == 0) fs::remove(entry.path());
}

void Recorder::add_frame(const engine::image::ImageRGB& linear) {
  engine::image::write_png_srgb(dir_ / frame_name(frames_), linear, exposure_);
  ++frames_;
}

std::vector<std::string> Recorder::finish(int fps, int sheet_columns, int sheet_frames) {
  std::vector<std::string> written;
  if (frames_ == 0) return written;
  written.push_back((dir_ / "frame_NNNN.png").string() + " (" + std::to_string(frames_) + " frames)");
  std::vector<fs::path> picks;
  const int n = std::min(sheet_frames, frames_);
  for (int i = 0; i < n; ++i) picks.push_back(dir_ / frame_name(n == 1 ? 0 : i * (frames_ - 1) / (n - 1)));
  write_contact_sheet(dir_ / "contact_sheet.png", picks, sheet_columns, 2);
  written.push_back((dir_ / "contact_sheet.png").string());
  if (ffmpeg_available()) {
    const fs::path tmp = dir_ / "run.tmp.mp4", mp4 = dir_ / "run.mp4";
    const std::string cmd = "ffmpeg -loglevel error -y -framerate " + std::to_string(fps) + " -i '" + (dir_ / "frame_%04d.png").string() +
                            "' -c:v libx264 -pix_fmt yuv420p -crf 20 '" + tmp.string() + "'";
    if (std::system(cmd.c_str()) == 0) {
      fs::rename(tmp, mp4);
      written.push_back(mp4.string());
    } else {
      std::error_code ec;
      fs::remove(tmp, ec);
      written.push_back("(ffmpeg failed; no MP4)");
    }
  } else {
    written.push_back("(ffmpeg not found; no MP4)");
  }
  return written;
}

void write_contact_sheet(const fs::path& out, const std::vector<fs::path>& frames, int columns, int downscale) {
  if (frames.empty()) return;
  std::vector<engine::image::Rgb8Image> tiles;
  for (const fs::path& f : frames) {
    const engine::image::Rgb8Image frame = engine::image::read_png(f);
    const int w = frame.width, h = frame.height;
    const std::uint8_t* data = frame.pixels.data();
    engine::image::Rgb8Image t(std::max(1, w / downscale), std::max(1, h / downscale));
    for (int y = 0; y < t.height; ++y)
      for (int x = 0; x < t.width; ++x)
        for (int ch = 0; ch < 3; ++ch) {
          int sum = 0;  // box filter over the downscale x downscale block
          for (int dy = 0; dy < downscale; ++dy)
            for (int dx = 0; dx < downscale; ++dx)
              sum += data[(static_cast<std::size_t>(y * downscale + dy) * w + (x * downscale + dx)) * 3 + ch];
          t.at(x, y)[ch] = static_cast<std::uint8_t>(sum / (downscale * downscale));
        }
    if (!tiles.empty() && (t.width != tiles[0].width || t.height != tiles[0].height))
      throw std::runtime_error(f.string() + ": frames of a contact sheet must share one size");
    tiles.push_back(std::move(t));
  }
  const int gap = 4, cols = std::min<int>(columns, static_cast<int>(tiles.size()));
  const int rows = (static_cast<int>(tiles.size()) + cols - 1) / cols;
  const int tw = tiles[0].width, th = tiles[0].height;
  engine::image::Rgb8Image sheet(cols * tw + (cols + 1) * gap, rows * th + (rows + 1) * gap);
  for (std::size_t i = 0; i < tiles.size(); ++i) {
    const int ox = gap + static_cast<int>(i) % cols * (tw + gap), oy = gap + static_cast<int>(i) / cols * (th + gap);
    for (int y = 0; y < th; ++y)
      for (int x = 0; x < tw; ++x)
        for (int ch = 0; ch < 3; ++ch) sheet.at(ox + x, oy + y)[ch] = tiles[i].at(x, y)[ch];
  }
  engine::image::write_png(out, sheet);
}

}  // namespace game
