#pragma once
// Checkerboard reuse of the real-time GI's decoded grid (issue 10). Each
// frame decodes the grid cells of one colour of a checkerboard that swaps
// every frame; a cell of the other colour takes the value the previous frame
// decoded for the same surface point. The point is carried to the previous
// frame through its object's motion and the previous camera, so a moving
// camera or object reuses too. Reuse needs, among the (up to four) previous
// cells around where the point lands, one that was decoded afresh, on the
// same entity, within one cell's footprint of the point in the object's own
// frame and with a normal within ~25 degrees. Otherwise (disocclusion, an
// object that appeared, a cut, a resize) the cell is decoded. So no value is
// more than one frame old, and a still view of a still scene reuses exactly
// what decoding would give (tested against decoding every cell).
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "engine/render/camera_rays.h"
#include "engine/rt/rt_scene.h"
#include "shading/upsampling.h"

namespace transgi::shading {

struct GBuffer;

class GiHistory {
 public:
  static constexpr std::int32_t kDecode = -1;

  // For every cell of this frame's grid: the previous frame's cell whose
  // value it takes, or kDecode (cells that miss are kDecode too; the caller
  // skips them). Remembers the cells' surface points for store(). With
  // `track`, also for every cell the previous frame's cell that saw the same
  // surface point, fresh or not (kDecode where none did): what a per-cell
  // running estimate follows from frame to frame. With `moved`, per cell
  // whether an object whose transform changed since the previous frame is
  // there now or was there then (the previous frame's cell at that index).
  void plan(const UpsamplingPlan& up, const GBuffer& g, const engine::rt::RtScene& scene, std::vector<std::int32_t>& source,
            std::vector<std::int32_t>* track = nullptr, std::vector<std::uint8_t>* moved = nullptr);
  // This frame's value of every cell (zero where a cell misses) and whether
  // it was decoded afresh; becomes the previous frame for the next plan().
  // Takes the vectors' contents (swapped with spent storage).
  void store(std::vector<glm::vec3>& value, std::vector<glm::vec3>& value_direct, const std::vector<std::uint8_t>& fresh);
  // The previous frame's value of cell c, as plan() named it.
  [[nodiscard]] const glm::vec3& value(std::int32_t c) const { return prev_.value[static_cast<std::size_t>(c)]; }
  [[nodiscard]] const glm::vec3& value_direct(std::int32_t c) const { return prev_.value_direct[static_cast<std::size_t>(c)]; }
  // Every cell's value (direct: zeros where none was stored), as value(c).
  [[nodiscard]] std::span<const glm::vec3> values() const { return prev_.value; }
  [[nodiscard]] std::span<const glm::vec3> values_direct() const { return prev_.value_direct; }
  void clear();

 private:
  // What a cell's reuse test reads of a previous cell, in one 24-byte
  // record: the history is read where the points land, a few MB a frame.
  struct Key {
    glm::vec3 object_position{0.0f};
    std::uint32_t object = kNoObject;  // index into that frame's `objects`
    std::int16_t normal[3] = {0, 0, 0};  // object-space normal, x 32767
    std::uint16_t fresh = 0;
  };
  static constexpr std::uint32_t kNoObject = 0xffffffffu;
  struct Cells {
    int width = 0, height = 0, grid_w = 0, grid_h = 0;
    float sx = 1, sy = 1;
    std::optional<engine::render::CameraRays> camera;
    std::vector<std::pair<engine::ecs::Entity, engine::transform::Similarity>> objects;  // in view, object to world
    std::vector<Key> key;
    std::vector<glm::vec3> value, value_direct;
  };
  Cells prev_, cur_;
  std::vector<std::uint32_t> object_of_cell_;
  std::uint64_t frame_ = 0;
};

}  // namespace transgi::shading
