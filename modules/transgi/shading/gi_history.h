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
//
// Kept transfer (TransferKeeping): a cell's decoded transfer (the network's
// 75 values) depends on the surface point and the view direction in its
// object's frame, not on the light, so it is kept in a pool and follows the
// surface point from frame to frame as the values do, through any number of
// frames. A cell whose colour comes round takes this frame's light and dots
// it with its kept transfer instead of decoding, while the point stays within
// one cell's footprint of where the transfer was decoded, the view direction
// in the object's frame within the threshold, and the transfer younger than
// its lifetime (between half and all of max_age frames, spread by cell so the
// refreshes do not come at once). A still view reuses exactly what decoding
// gave: only the light differs, and it is this frame's.
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "engine/render/camera_rays.h"
#include "engine/rt/rt_scene.h"
#include "shading/upsampling.h"

namespace transgi::shading {

struct GBuffer;

// How long and how far a decoded transfer is kept (GiHistory::plan).
struct TransferKeeping {
  int max_age = 0;            // frames; 0 = no transfer is kept
  float min_view_cos = 1.0f;  // cosine of the largest change of view direction
  // What decoded the kept transfers (the decoder, the model) and from which
  // assets (their generation and edit_version: the network reads each
  // point's base colour, which an edited material changes): when any of
  // these changes, nothing kept before is taken.
  const void* decoder = nullptr;
  const void* model = nullptr;
  std::uint64_t assets_generation = 0, assets_edit = 0;
};

class GiHistory {
 public:
  static constexpr std::int32_t kDecode = -1;
  static constexpr std::uint8_t kMovedFrom = 1, kMovedHere = 2;
  static constexpr std::uint32_t kNoSlot = 0xffffffffu;

  // For every cell of this frame's grid: the previous frame's cell whose
  // value it takes, or kDecode (cells that miss are kDecode too; the caller
  // skips them). Remembers the cells' surface points for store(). With
  // `track`, also for every cell the previous frame's cell that saw the same
  // surface point, fresh or not (kDecode where none did): what a per-cell
  // running estimate follows from frame to frame. With `moved`, per cell
  // whether an object whose transform changed since the previous frame is
  // there now (kMovedHere: the cell's own surface moved) or was there then
  // (kMovedFrom: the previous frame's cell at that index), else 0.
  void plan(const UpsamplingPlan& up, const GBuffer& g, const engine::rt::RtScene& scene, std::vector<std::int32_t>& source,
            std::vector<std::int32_t>* track = nullptr, std::vector<std::uint8_t>* moved = nullptr,
            const TransferKeeping& keeping = {});

  // Kept transfer, after plan(): the pool slot whose transfer cell c of this
  // frame takes (kNoSlot: decode it), and the 75 values at a slot.
  [[nodiscard]] std::uint32_t kept_slot(std::size_t c) const { return cur_.slot[c]; }
  [[nodiscard]] const float* transfer(std::uint32_t slot) const { return pool_.values.data() + std::size_t{slot} * 75; }
  [[nodiscard]] float* transfer(std::uint32_t slot) { return pool_.values.data() + std::size_t{slot} * 75; }
  // A slot for the transfer cell c decodes this frame, anchored at its point
  // and view direction; it becomes the cell's kept_slot. May grow the pool:
  // take transfer() pointers after the last call of a frame.
  std::uint32_t new_transfer_slot(std::size_t c);
  [[nodiscard]] bool keeps_transfer() const { return keeping_.max_age > 0; }
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
  // Where and when a kept transfer was decoded.
  struct Anchor {
    glm::vec3 object_position{0.0f};
    std::int16_t wo[3] = {0, 0, 0};  // object-space view direction, x 32767
    std::uint64_t expires = 0;       // the first frame it is no longer taken
  };
  struct TransferPool {
    std::vector<float> values;  // 75 a slot
    std::size_t slots = 0;
    std::vector<std::uint32_t> free;  // slots no cell holds, taken from the back
  };
  // Slots no cell of prev_ holds go back to the free list.
  void collect_free_slots();

  struct Cells {
    int width = 0, height = 0, grid_w = 0, grid_h = 0;
    float sx = 1, sy = 1;
    std::optional<engine::render::CameraRays> camera;
    std::vector<std::pair<engine::ecs::Entity, engine::transform::Similarity>> objects;  // in view, object to world
    std::vector<Key> key;
    std::vector<glm::vec3> value, value_direct;
    // Kept transfer: each cell's pool slot (kNoSlot: none) and its anchor,
    // carried with it from cell to cell (read beside the cell, not at a
    // slot scattered through the pool); for anchoring a new one, the
    // object-space view direction the cell is seen along now.
    std::vector<std::uint32_t> slot;
    std::vector<Anchor> anchor;
    std::vector<std::array<std::int16_t, 3>> wo;
  };
  Cells prev_, cur_;
  TransferKeeping keeping_;
  TransferPool pool_;
  std::vector<std::uint32_t> object_of_cell_;
  std::uint64_t frame_ = 0;
};

}  // namespace transgi::shading
