#include "shading/realtime_gi.h"

#include "probes/cascades.h"

#include <chrono>
#include <atomic>
#include <cmath>
#include <stdexcept>
#include <limits>
#include <map>
#include <unordered_map>

#include <glm/gtc/quaternion.hpp>

#include "engine/jobs/parallel_for.h"
#include "engine/render/camera_hit_tracer.h"
#include "engine/math/sampling.h"
#include "shading/gi_history.h"
#include "shading/realtime_direct.h"
#include "shading/realtime_reflections.h"
#include "shading/sh_light.h"
#include "shading/transfer_inference.h"
#include "shading/upsampling.h"

namespace transgi::shading {


namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

constexpr std::size_t kNone = SIZE_MAX;

}  // namespace

// The near field's per-cell buffers, kept across frames (add_contact_light).
struct ContactScratch {
  std::vector<glm::vec3> contact, filtered;
  std::vector<glm::vec4> row;
  std::vector<std::uint8_t> valid, wanted, estimated;
  // Per cell of the last frame: the running mean of its filtered contact
  // light and how many frames it holds; this frame's, then swapped.
  std::vector<glm::vec3> mean, mean_next;
  std::vector<std::uint8_t> count, count_next;
  // Per cell of the last frame: its mean started in a cut (NearFieldRays::
  // cut_fade_frames) and still fades in; this frame's, then swapped.
  std::vector<std::uint8_t> fading, fading_next;
  std::vector<std::int32_t> track;  // GiHistory::plan's
  std::vector<std::uint8_t> moved, near_moved, near_moved_row;  // GiHistory::plan's, and it dilated
  std::uint64_t frame = 0;

  // Whether cell c has contact light this frame: a mean (tracked) or a
  // filtered estimate that reached it.
  [[nodiscard]] bool has_contact(std::size_t c, bool tracked) const { return tracked ? count[c] > 0 : estimated[c] != 0; }
  // Cell c's contact light this frame: its mean (tracked; in proportion to
  // its frames while it fades in after a cut) or its filtered estimate; zero
  // where none has reached it yet.
  [[nodiscard]] glm::vec3 contact_of(std::size_t c, bool tracked, int fade_frames) const {
    if (!tracked) return filtered[c];
    if (count[c] == 0) return glm::vec3(0.0f);
    return fading[c] ? mean[c] * (static_cast<float>(count[c]) / static_cast<float>(fade_frames)) : mean[c];
  }
};

struct RealtimeGiScratch::Impl {
  DielectricRays dielectric_rays;
  UpsamplingPlan up;
  std::vector<std::size_t> decode, slot_of_pixel;
  std::vector<glm::vec3> value, value_direct, shaded, shaded_direct;
  // Per decoded sample: what its contact light is multiplied by (its
  // diffuse reflectance over its base colour, over pi), taken while its
  // GSample is in cache.
  std::vector<glm::vec3> contact_gain;
  std::vector<std::size_t> decoded_cells;      // the grid cells decoded this frame
  std::vector<std::size_t> row_start;          // per row of cells: its first decoded cell's slot
  std::vector<std::uint8_t> row_has_own;       // per pixel row: it holds a pixel decoded on its own
  ContactScratch contact;
  std::vector<TransferQuery> queries;
  // Per network sample: where it is and its world normal, copied while its
  // GSample is in cache so the light fill does not miss on it a second time.
  std::vector<glm::vec3> net_position, net_normal;
  // Checkerboard reuse (RealtimeGiSettings::reuse_history): the previous
  // frame's cells, each cell's source, and this frame's cell values.
  GiHistory history;
  std::vector<std::int32_t> source;
  std::vector<std::uint8_t> fresh;
  // Kept transfer: per network sample, where its 75 values are and whether
  // they are decoded this frame; the pixels decoded on their own keep none,
  // theirs go to own_transfer.
  std::vector<float*> net_transfer;
  std::vector<std::uint32_t> net_slot;
  std::vector<std::uint8_t> net_decode;
  std::vector<float> own_transfer;
  std::vector<glm::vec3> cell_value, cell_value_direct;
  engine::image::ImageRGB recycled;  // RealtimeGiScratch::recycle
  // The split of decoded samples into network and diffuse ones.
  std::vector<engine::ecs::Entity> sample_entity;
  std::vector<std::uint8_t> sample_glossy;
  std::vector<std::size_t> net, diffuse;
  std::vector<int> rotation_of;
};
RealtimeGiScratch::RealtimeGiScratch() : impl(std::make_unique<Impl>()) {}
RealtimeGiScratch::~RealtimeGiScratch() = default;
RealtimeGiScratch::RealtimeGiScratch(RealtimeGiScratch&&) noexcept = default;
RealtimeGiScratch& RealtimeGiScratch::operator=(RealtimeGiScratch&&) noexcept = default;
void RealtimeGiScratch::recycle(engine::image::ImageRGB&& image) { impl->recycled = std::move(image); }
void RealtimeGiScratch::forget_histories() {
  impl->history.clear();
  impl->dielectric_rays.history.forget();
}

namespace {

// Probe SH rotated into object frames, one copy per distinct rotation and
// field; identity rotations read the field's own SH.
class RotatedProbes {
 public:
  RotatedProbes(std::span<const probes::ProbeField* const> fields) : fields_(fields) {}

  // Index of the rotation of `q` (object to world), or -1 for identity.
  int add(const glm::quat& q) {
    if (std::abs(std::abs(q.w) - 1.0f) < 1e-7f) return -1;
    const std::array<float, 4> key{q.x, q.y, q.z, q.w};
    auto [it, inserted] = index_.try_emplace(key, static_cast<int>(rotations_.size()));
    if (inserted) rotations_.push_back(q);
    return it->second;
  }
  void rotate_all() {
    copies_.assign(rotations_.size() * fields_.size() * 2, {});
    engine::jobs::parallel_for<std::size_t>(0, copies_.size(), 1, [&](std::size_t b, std::size_t e) {
      for (std::size_t c = b; c < e; ++c) {
        const std::size_t r = c / (2 * fields_.size()), f = c / 2 % fields_.size();
        const engine::math::ShRotation rot(glm::transpose(glm::mat3_cast(rotations_[r])));
        const std::vector<float>& src = c % 2 ? fields_[f]->direct_sh_all() : fields_[f]->light_sh_all();
        std::vector<float>& dst = copies_[c];
        dst.resize(src.size());
        for (std::size_t probe = 0; probe < src.size() / 75; ++probe)
          for (std::size_t ch = 0; ch < 3; ++ch) rot.apply(src.data() + probe * 75 + ch * 25, dst.data() + probe * 75 + ch * 25);
      }
    });
  }
  // The indirect (direct = false) or direct SH array of field f as seen in
  // rotation r's frame.
  [[nodiscard]] const float* sh(int r, const probes::ProbeField* f, bool direct = false) const {
    if (r < 0) return (direct ? f->direct_sh_all() : f->light_sh_all()).data();
    for (std::size_t i = 0; i < fields_.size(); ++i)
      if (fields_[i] == f) return copies_[(static_cast<std::size_t>(r) * fields_.size() + i) * 2 + (direct ? 1 : 0)].data();
    return nullptr;
  }
  [[nodiscard]] std::size_t count() const { return rotations_.size(); }

 private:
  std::span<const probes::ProbeField* const> fields_;
  std::map<std::array<float, 4>, int> index_;
  std::vector<glm::quat> rotations_;
  std::vector<std::vector<float>> copies_;
};

}  // namespace

GBuffer trace_gbuffer(const engine::rt::RtScene& scene, const engine::scene::SceneAssets& assets,
                      const engine::render::CameraRays& camera, int width, int height) {
  GBuffer g;
  trace_gbuffer(scene, assets, camera, width, height, g);
  return g;
}

void trace_gbuffer(const engine::rt::RtScene& scene, const engine::scene::SceneAssets& assets,
                   const engine::render::CameraRays& camera, int width, int height, GBuffer& g, DirectTileShader* direct,
                   engine::rt::RayBatchTracer* tracer, glm::vec2 jitter, float texture_lod_bias) {
  g.width = width;
  g.jitter = jitter;
  g.height = height;
  g.camera = camera;
  g.samples.resize(static_cast<std::size_t>(width) * height);
  g.guide.resize(g.samples.size());
  g.position.resize(g.samples.size());
  g.albedo.resize(g.samples.size());
  g.metal_roughness.resize(g.samples.size());
  g.dielectric_roughness.resize(g.samples.size());
  g.entity.resize(g.samples.size());
  // 4x4 pixel tiles as one Embree packet: neighbouring camera rays share
  // their traversal.
  const int tiles_x = (width + 3) / 4, tiles_y = (height + 3) / 4;
  g.tile_dielectric_roughness.resize(static_cast<std::size_t>(tiles_x) * tiles_y);
  // The cone that picks the textures' mip level (a level finer = half as wide).
  const float spread = camera.pixel_spread() * std::exp2(texture_lod_bias);
  // A backend traces every camera ray in one batch, in the tiles' order.
  std::vector<engine::rt::Ray>& batch_rays = g.batch.rays;
  std::vector<engine::rt::Hit>& batch_hits = g.batch.hits;
  std::vector<std::uint8_t>& batch_found = g.batch.found;
  std::vector<std::size_t>& tile_first = g.batch.tile_first;
  tile_first.clear();
  // A backend that rasterises the camera's view gives every pixel's hit in
  // image order; else it traces the camera rays.
  bool by_pixel = false;
  if (engine::render::CameraHitTracer* raster = tracer ? tracer->camera_hit_tracer() : nullptr) {
    batch_hits.resize(g.samples.size());
    batch_found.resize(g.samples.size());
    raster->camera_hits(scene, camera, glm::vec2(0.5f) + jitter, batch_hits, batch_found);
    by_pixel = true;
  }
  if (tracer && !by_pixel) {
    // Where each tile's rays start, then the rays in parallel (serially,
    // 1080p's 2 M rays cost more than the GPU's traversal of them).
    tile_first.resize(static_cast<std::size_t>(tiles_x) * tiles_y);
    std::size_t count = 0;
    for (int t = 0; t < tiles_x * tiles_y; ++t) {
      tile_first[static_cast<std::size_t>(t)] = count;
      const int tx = t % tiles_x * 4, ty = t / tiles_x * 4;
      count += static_cast<std::size_t>(std::min(4, width - tx) * std::min(4, height - ty));
    }
    batch_rays.resize(count);
    engine::jobs::parallel_for(0, tiles_x * tiles_y, 256, [&](int t0, int t1) {
      for (int t = t0; t < t1; ++t) {
        std::size_t i = tile_first[static_cast<std::size_t>(t)];
        const int tx = t % tiles_x * 4, ty = t / tiles_x * 4;
        for (int y = ty; y < std::min(ty + 4, height); ++y)
          for (int x = tx; x < std::min(tx + 4, width); ++x)
            batch_rays[i++] = camera.generate({static_cast<float>(x) + 0.5f + jitter.x, static_cast<float>(y) + 0.5f + jitter.y});
      }
    });
    batch_hits.resize(batch_rays.size());
    batch_found.resize(batch_rays.size());
    tracer->intersect(scene, batch_rays, batch_hits, batch_found);
  }
  engine::jobs::parallel_for(0, tiles_x * tiles_y, 16, [&](int t0, int t1) {
    engine::rt::Ray rays[16];
    engine::rt::Hit hits[16];
    bool found[16];
    std::size_t pixel[16];
    const GSampleSideArrays sides{.pixel = pixel,
                                  .guide = g.guide.data(),
                                  .position = g.position.data(),
                                  .albedo = g.albedo.data(),
                                  .metal_roughness = g.metal_roughness.data(),
                                  .dielectric_roughness = g.dielectric_roughness.data(),
                                  .entity = g.entity.data()};
    DirectTileShader::Scratch direct_scratch;
    for (int t = t0; t < t1; ++t) {
      const int tx = t % tiles_x * 4, ty = t / tiles_x * 4;
      int n = 0;
      for (int y = ty; y < std::min(ty + 4, height); ++y)
        for (int x = tx; x < std::min(tx + 4, width); ++x, ++n) {
          // Field by field: GCC assembles a whole Ray on the stack and copies
          // it with wider loads than its stores, a stall per pixel.
          const engine::rt::Ray ray = camera.generate({static_cast<float>(x) + 0.5f + jitter.x, static_cast<float>(y) + 0.5f + jitter.y});
          rays[n].origin = ray.origin;
          rays[n].direction = ray.direction;
          rays[n].tmin = ray.tmin;
          rays[n].tmax = ray.tmax;
          pixel[n] = static_cast<std::size_t>(y) * width + x;
        }
      // The tile's samples are 50 cache lines written below: fetched for
      // writing while Embree traverses, not one miss at a time after it.
      for (int i = 0; i < n; ++i) {
        const char* first_byte = reinterpret_cast<const char*>(&g.samples[pixel[i]]);
        for (std::size_t b = 0; b < sizeof(GSample); b += 64) __builtin_prefetch(first_byte + b, 1, 3);
        __builtin_prefetch(reinterpret_cast<const char*>(&g.samples[pixel[i]] + 1) - 1, 1, 3);
      }
      if (by_pixel) {
        for (int i = 0; i < n; ++i) {
          found[i] = batch_found[pixel[i]] != 0;
          hits[i] = batch_hits[pixel[i]];
        }
      } else if (tile_first.empty()) {
        scene.intersect16_coherent(rays, n, hits, found);
      } else {
        const std::size_t first = tile_first[static_cast<std::size_t>(t)];
        for (int i = 0; i < n; ++i) {
          found[i] = batch_found[first + static_cast<std::size_t>(i)] != 0;
          hits[i] = batch_hits[first + static_cast<std::size_t>(i)];
        }
      }
      GSample* out[kGSampleTile];
      for (int i = 0; i < n; ++i) out[i] = &g.samples[pixel[i]];
      make_gsamples(scene, assets, rays, hits, found, n, spread, out, &sides);
      float tile_least = std::numeric_limits<float>::infinity();
      for (int i = 0; i < n; ++i) tile_least = std::min(tile_least, g.dielectric_roughness[pixel[i]]);
      g.tile_dielectric_roughness[static_cast<std::size_t>(t)] = tile_least;
      if (direct) direct->shade_tile(g, tx, ty, direct_scratch);
    }
  });
}

namespace {

// Contact light may darken a cell to this fraction of its probe light, no
// further: it replaces what the probes hold for the near directions, and a
// noisy estimate against an over-bright probe (one entering a cascade) had
// taken cells to black.
constexpr float kContactFloor = 0.25f;

// Frames a moving object's own surface averages its contact light over
// while it moves (followed through the history's track; its surroundings
// restart instead, kContactResetCells): a restart every frame left a moving
// ball or a dragged cube mottled with one frame's noise, and the object's
// own points are the same points from frame to frame.
constexpr int kMovingContactFrames = 4;

// How far, in GI cells, from where a moved object is or was a cell's contact
// light restarts: about twice the filter's reach.
constexpr int kContactResetCells = 8;

// The share of the lit cells whose means start in one frame above which the
// frame is a cut (NearFieldRays::cut_fade_frames): the Living Room's
// fly-through starts 1-5 % of them a frame while it moves (the tracks kept
// under the jitter), 82 % where its path turns by 78 degrees.
constexpr float kCutShare = 0.25f;

// A pixel decoded on its own takes the contact light of the cells within
// this many cells of it whose guide is like its own: depth within this
// fraction, normals weighed by their cosine to this power (looser than the
// upsampling's 5 %, which such a pixel failed).
constexpr int kEdgeContactCells = 2;
constexpr float kEdgeContactDepthTolerance = 0.2f;
constexpr int kEdgeContactNormalPower = 8;

// Marks scratch.near_moved: the cells within kContactResetCells of where a
// moved object is or was (`moved`, GiHistory::plan's). The contact light
// there changed with the move, so their means restart (else the floor beside
// a moved object keeps its old light for frames: a ghost). False, with
// nothing marked, where nothing moved.
bool mark_near_moved(const UpsamplingPlan& up, std::span<const std::uint8_t> moved, ContactScratch& scratch) {
  const std::size_t grid = up.cell_pixel.size(), grid_w = static_cast<std::size_t>(up.grid_w);
  const std::size_t grid_h = static_cast<std::size_t>(up.grid_h);
  if (moved.size() != grid || std::none_of(moved.begin(), moved.end(), [](std::uint8_t m) { return m != 0; })) return false;
  const int radius = kContactResetCells;
  scratch.near_moved_row.assign(grid, 0);
  scratch.near_moved.assign(grid, 0);
  engine::jobs::parallel_for<std::size_t>(0, grid_h, 8, [&](std::size_t b, std::size_t e) {
    for (std::size_t j = b; j < e; ++j)
      for (std::size_t i = 0; i < grid_w; ++i)
        if (moved[j * grid_w + i])
          for (std::size_t x = i > static_cast<std::size_t>(radius) ? i - radius : 0; x <= std::min(grid_w - 1, i + radius); ++x)
            scratch.near_moved_row[j * grid_w + x] = 1;
  });
  engine::jobs::parallel_for<std::size_t>(0, grid_w, 64, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i)
      for (std::size_t j = 0; j < grid_h; ++j)
        if (scratch.near_moved_row[j * grid_w + i])
          for (std::size_t y = j > static_cast<std::size_t>(radius) ? j - radius : 0; y <= std::min(grid_h - 1, j + radius); ++y)
            scratch.near_moved[y * grid_w + i] = 1;
  });
  return true;
}

// The running mean over the last `history` frames of each cell's surface
// point, followed through the GI history's track (a point seen anew, or one
// near a moved object, starts from this frame's estimate; a moved object's
// own point keeps kMovingContactFrames); after a cut, the means that start
// fade in over fade_frames (NearFieldRays::cut_fade_frames).
void update_contact_means(const UpsamplingPlan& up, std::span<const std::int32_t> track, std::span<const std::uint8_t> moved,
                          bool reset_near_moved, int history, int fade_frames, ContactScratch& scratch) {
  const std::size_t grid = up.cell_pixel.size();
  scratch.mean_next.resize(grid);
  scratch.count_next.assign(grid, 0);
  scratch.fading_next.assign(grid, 0);
  if (scratch.fading.size() != grid) scratch.fading.assign(grid, 0);
  const auto knows = [&](std::size_t c) {
    const std::int32_t q = track[c];
    const bool on_moved = reset_near_moved && moved[c] == GiHistory::kMovedHere;
    return q >= 0 && static_cast<std::size_t>(q) < scratch.count.size() && scratch.count[static_cast<std::size_t>(q)] > 0 &&
           (on_moved || !(reset_near_moved && scratch.near_moved[c]));
  };
  // A cut (or a turn as sudden): most of the view starts its means at once.
  bool cut = false;
  if (fade_frames > 1) {
    std::atomic<std::size_t> lit{0}, starting{0};
    engine::jobs::parallel_for<std::size_t>(0, grid, 4096, [&](std::size_t b, std::size_t e) {
      std::size_t l = 0, n = 0;
      for (std::size_t c = b; c < e; ++c)
        if (up.cell_guide[c].w > 0) {
          ++l;
          if (scratch.estimated[c] && !knows(c)) ++n;
        }
      lit.fetch_add(l, std::memory_order_relaxed);
      starting.fetch_add(n, std::memory_order_relaxed);
    });
    cut = static_cast<float>(starting.load()) > kCutShare * static_cast<float>(lit.load());
  }
  // A cell that no estimate reached carries its point's mean unchanged.
  engine::jobs::parallel_for<std::size_t>(0, grid, 4096, [&](std::size_t b, std::size_t e) {
    for (std::size_t c = b; c < e; ++c) {
      const std::int32_t q = track[c];
      const bool on_moved = reset_near_moved && moved[c] == GiHistory::kMovedHere;
      const bool known = knows(c);
      if (!scratch.estimated[c]) {
        if (known) {
          scratch.mean_next[c] = scratch.mean[static_cast<std::size_t>(q)];
          scratch.count_next[c] = scratch.count[static_cast<std::size_t>(q)];
          scratch.fading_next[c] = scratch.fading[static_cast<std::size_t>(q)];
        }
        continue;
      }
      const int n = known ? std::min<int>(scratch.count[static_cast<std::size_t>(q)], (on_moved ? std::min(history, kMovingContactFrames) : history) - 1) : 0;
      scratch.mean_next[c] = n > 0 ? (scratch.mean[static_cast<std::size_t>(q)] * static_cast<float>(n) + scratch.filtered[c]) /
                                         static_cast<float>(n + 1)
                                   : scratch.filtered[c];
      scratch.count_next[c] = static_cast<std::uint8_t>(n + 1);
      const bool fading = known ? scratch.fading[static_cast<std::size_t>(q)] != 0 : cut;
      scratch.fading_next[c] = fading && n + 1 < fade_frames ? 1 : 0;
    }
  });
  std::swap(scratch.mean, scratch.mean_next);
  std::swap(scratch.count, scratch.count_next);
  std::swap(scratch.fading, scratch.fading_next);
  ++scratch.frame;
}

// The pixels decoded on their own (value slots first_slot on) lie where
// no cell of the grid is on their surface within the upsampling's
// tolerance: silhouettes, a window's muntins, a chair's rails. Contact
// light varies slowly along a surface, so each takes the mean of the cells
// around it on a surface like its own within a looser tolerance; without
// it they lacked the near field's share and read darker than the surfaces
// beside them (docs/image-quality.md, 2026-11-28).
void add_edge_contact(const GBuffer& g, const UpsamplingPlan& up, const ContactScratch& scratch, bool tracked, int fade_frames,
                      std::span<const std::size_t> edge_pixels, std::size_t first_slot, std::span<const glm::vec3> contact_gain,
                      std::vector<glm::vec3>& value) {
  const std::size_t width = static_cast<std::size_t>(up.width), grid_w = static_cast<std::size_t>(up.grid_w);
  engine::jobs::parallel_for<std::size_t>(0, edge_pixels.size(), 256, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      const std::size_t p = edge_pixels[i], k = first_slot + i;
      const int cx = up.col0[p % width], cy = up.row0[p / width];
      glm::vec3 sum(0.0f);
      float weight = 0;
      for (int y = std::max(0, cy - kEdgeContactCells); y <= std::min(up.grid_h - 1, cy + kEdgeContactCells); ++y)
        for (int x = std::max(0, cx - kEdgeContactCells); x <= std::min(up.grid_w - 1, cx + kEdgeContactCells); ++x) {
          const std::size_t c = static_cast<std::size_t>(y) * grid_w + static_cast<std::size_t>(x);
          if (!scratch.has_contact(c, tracked)) continue;
          const float w = guide_similarity(g.guide[p], up.cell_guide[c], kEdgeContactDepthTolerance, kEdgeContactNormalPower);
          sum += w * scratch.contact_of(c, tracked, fade_frames);
          weight += w;
        }
      if (weight > 0) value[k] = glm::max(value[k] + contact_gain[k] * (sum / weight), kContactFloor * value[k]);
    }
  });
}

// Adds the near field's contact light (near_field.h) to the cells decoded
// this frame (`cells`: cells[k]'s value is value[k]), times each one's
// contact gain. The rays leave a lattice of cells (NearFieldRays::
// cell_budget) whatever this frame decodes: the GI reuse decodes a
// checkerboard, alternating, and rays from its own colour's cells gave each
// colour its own noise, a frozen checkerboard in a still view. The
// lattice's estimates are filtered (a horizontal then a vertical bilateral
// pass) into every cell, so both colours read one field. `own_masked_within(p)`: where the
// transfer of the sample at pixel p masks its own object (near_field_irradiance; 0 where no
// transfer shades it).
void add_contact_light(const GBuffer& g, const engine::rt::RtScene& scene, std::span<const probes::ProbeField* const> fields,
                       const engine::render::LightSet* lights, const NearFieldRays& near_field, const UpsamplingPlan& up,
                       std::span<const std::size_t> cells, const std::function<float(std::size_t)>& own_masked_within, std::span<const glm::vec3> contact_gain,
                       std::span<const std::int32_t> track, std::span<const std::uint8_t> moved, ContactScratch& scratch,
                       std::span<const std::size_t> edge_pixels, std::vector<glm::vec3>& value) {
  const NearLightAt light_at = [&](const glm::vec3& p, const glm::vec3& n, float* out) { probes::interpolate_fields(fields, p, n, out); };
  const std::size_t grid = up.cell_pixel.size(), grid_w = static_cast<std::size_t>(up.grid_w);
  const std::size_t grid_h = static_cast<std::size_t>(up.grid_h);
  // The lattice: one cell in cols_k of one row in rows_k (cols_k even, the
  // rows offset by half of it), as dense as the budget allows, neither step
  // wider than the filter's window so every cell has estimates in reach.
  // Tracked, it shifts every frame, so over frames every cell traces.
  const std::size_t budget = static_cast<std::size_t>(std::max(0, near_field.cell_budget));
  const std::size_t widest = std::max<std::size_t>(2, 2 * static_cast<std::size_t>(std::max(0, near_field.filter_radius)) + 1);
  const std::size_t wanted_steps = budget > 0 ? (grid + budget - 1) / budget : 1;
  std::size_t cols_k = 2, rows_k = std::max<std::size_t>(1, (wanted_steps + 1) / 2);
  if (rows_k > widest) {
    rows_k = widest;
    cols_k = std::min(widest + 1, 2 * ((wanted_steps + 2 * rows_k - 1) / (2 * rows_k)));
  }
  const bool tracked = track.size() == grid;
  const std::uint64_t stream = tracked ? scratch.frame : 0;  // new directions every frame where a mean averages them
  scratch.wanted.assign(grid, 0);
  const std::size_t shift_j = static_cast<std::size_t>(stream % rows_k), shift_i = static_cast<std::size_t>((stream / rows_k) % cols_k);
  scratch.contact.resize(grid);
  scratch.valid.assign(grid, 0);
  // Tracked, every cell's mean takes every frame's field, whichever colour
  // the reuse decodes: a mean fed only on a cell's own decode frames would
  // give the two colours their own noise, a checkerboard again.
  if (tracked)
    engine::jobs::parallel_for<std::size_t>(0, grid, 16384, [&](std::size_t b, std::size_t e) {
      for (std::size_t c = b; c < e; ++c) scratch.wanted[c] = up.cell_guide[c].w > 0 ? 1 : 0;
    });
  else
    for (const std::size_t c : cells) scratch.wanted[c] = 1;
  // Near a moved object the means restart (mark_near_moved).
  const bool reset_near_moved = tracked && mark_near_moved(up, moved, scratch);
  // Cell c's contact estimate from its own rays (a cell that hits).
  const auto trace_cell = [&](std::size_t c) {
    const std::size_t p = up.cell_pixel[c];
    const GSample& s = g.samples[p];
    engine::math::Pcg32 rng = engine::math::make_rng(0x4EA2F1ull, p, stream);  // no seed: by frame, not by run
    const float reach = near_field.reach_cells * probes::fields_at(fields, s.position).field[0]->placement().min_spacing();
    scratch.contact[c] = near_field_irradiance(scene, lights, s, nullptr, reach, own_masked_within(p), near_field.rays, light_at, rng);
    scratch.valid[c] = 1;
  };
  const std::size_t lattice_rows = (grid_h + rows_k - 1) / rows_k, lattice_cols = (grid_w + cols_k - 1) / cols_k + 1;
  engine::jobs::parallel_for<std::size_t>(0, lattice_rows * lattice_cols, 64, [&](std::size_t b, std::size_t e) {
    for (std::size_t k = b; k < e; ++k) {
      const std::size_t r = k / lattice_cols, j = r * rows_k + shift_j;
      const std::size_t i = (k % lattice_cols) * cols_k + (r % 2) * (cols_k / 2) + shift_i;
      if (j >= grid_h || i >= grid_w) continue;
      const std::size_t c = j * grid_w + i;
      if (up.cell_guide[c].w > 0) trace_cell(c);
    }
  });
  // Where the means restart (near a moved object: near_moved), every other cell
  // traces (a checkerboard that alternates by frame), not only the
  // lattice's: a restarted mean is this frame's filtered estimate alone, and
  // from the lattice's few rays it mottled the wall behind a rolling ball
  // with dark blotches for the frames its mean took to settle.
  if (reset_near_moved)
    engine::jobs::parallel_for<std::size_t>(0, grid, 256, [&](std::size_t b, std::size_t e) {
      for (std::size_t c = b; c < e; ++c) {
        if ((c / grid_w + c % grid_w + stream) % 2 != 0) continue;
        if (scratch.near_moved[c] && !scratch.valid[c] && up.cell_guide[c].w > 0) trace_cell(c);
      }
    });
  filter_near_field_separable(up.cell_guide, up.grid_w, up.grid_h, scratch.contact, scratch.valid, scratch.wanted,
                              near_field.filter_radius, scratch.row, scratch.filtered, scratch.estimated);
  const int history = std::clamp(near_field.history_frames, 1, 255);  // counts are bytes
  // A mean that started in a cut counts in proportion to its frames until it
  // holds this many (no more than a mean holds).
  const int fade_frames = std::clamp(near_field.cut_fade_frames, 0, history);
  if (tracked) update_contact_means(up, track, moved, reset_near_moved, history, fade_frames, scratch);
  engine::jobs::parallel_for<std::size_t>(0, cells.size(), 1024, [&](std::size_t b, std::size_t e) {
    for (std::size_t k = b; k < e; ++k)
      value[k] = glm::max(value[k] + contact_gain[k] * scratch.contact_of(cells[k], tracked, fade_frames), kContactFloor * value[k]);
  });
  add_edge_contact(g, up, scratch, tracked, fade_frames, edge_pixels, cells.size(), contact_gain, value);
}

}  // namespace

namespace {

// What every stage of one real-time GI frame reads: the request, and the
// choices made once from it.
struct GiFrameInputs {
  const RealtimeGiRequest& request;
  bool reuse = false;        // cells may take the previous frame's value (GiHistory)
  bool keep_transfer = false;  // cells keep their decoded transfer (RealtimeGiSettings::transfer_max_age)
  bool with_direct = false;  // the probes' direct SH goes to the direct image too
  // Glossy dielectrics (MirrorRay::dielectric_max_roughness) take their
  // diffuse light from the probes' irradiance and their specular from a ray.
  bool reflections = false, glossy_dielectrics = false;

  const GBuffer& g = request.gbuffer;
  const engine::rt::RtScene& scene = request.scene;
  const engine::scene::SceneAssets& assets = request.assets;
  std::span<const probes::ProbeField* const> fields = request.fields;
  const RealtimeGiSettings& settings = request.settings;
  const MirrorRay& mirror = request.mirror;
  const NearFieldRays& near_field = request.near_field;

  [[nodiscard]] bool is_glossy_dielectric(std::size_t p) const {
    return glossy_dielectrics && g.dielectric_roughness[p] <= mirror.dielectric_max_roughness;
  }
  // Whether the network decodes entity e's samples (else they are lit diffusely).
  [[nodiscard]] bool network_decodes(engine::ecs::Entity e) const {
    return request.model && request.decoder && (!request.has_transfer || request.has_transfer(e));
  }
};

// Stage 1, plan. After it: sc.up is the upsampling plan; sc.decode lists the
// pixels to decode (the grid cells that hit and are not reused, in cell
// order, then the pixels decoded on their own), sc.decoded_cells the cell of
// each of the first ones, sc.slot_of_pixel each listed pixel's slot (kNone
// elsewhere); with the reuse, sc.source says where each cell's value comes from.
void plan_decode(const GiFrameInputs& in, RealtimeGiScratch::Impl& sc, RealtimeGiStats& stats) {
  const GBuffer& g = in.g;
  const std::vector<glm::vec4>& guide = g.guide;
  plan_upsampling(guide, g.width, g.height, in.settings, sc.up);
  const UpsamplingPlan& up = sc.up;
  std::vector<std::size_t>& decode = sc.decode;
  decode.clear();
  std::vector<std::size_t>& slot_of_pixel = sc.slot_of_pixel;
  slot_of_pixel.resize(g.samples.size());
  engine::jobs::parallel_for<std::size_t>(0, slot_of_pixel.size(), 16384, [&](std::size_t b, std::size_t e) {
    std::fill(slot_of_pixel.begin() + static_cast<std::ptrdiff_t>(b), slot_of_pixel.begin() + static_cast<std::ptrdiff_t>(e), kNone);
  });
  // With reuse, the cells that take the previous frame's value are not decoded.
  if (in.reuse) {
    TransferKeeping keeping;
    if (in.keep_transfer) {
      keeping.max_age = in.settings.transfer_max_age;
      keeping.min_view_cos = std::cos(glm::radians(in.settings.transfer_view_degrees));
      keeping.decoder = in.request.decoder;
      keeping.model = in.request.model;
      keeping.assets_generation = in.assets.generation;
      keeping.assets_edit = in.assets.edit_version;
    }
    sc.history.plan(up, g, in.scene, sc.source, in.near_field.rays > 0 ? &sc.contact.track : nullptr,
                    in.near_field.rays > 0 ? &sc.contact.moved : nullptr, keeping);
  }
  else
    sc.history.clear();
  // The cells in cell order, their slots by a prefix sum over rows of cells
  // (cells decode distinct pixels, so the rows fill their slots in parallel):
  // decoded_cells[k] is the cell whose value is value[k].
  const std::size_t grid_w = static_cast<std::size_t>(up.grid_w), grid_h = static_cast<std::size_t>(up.grid_h);
  const auto decodes = [&](std::size_t c) { return (!in.reuse || sc.source[c] == GiHistory::kDecode) && up.cell_guide[c].w > 0; };
  std::vector<std::size_t>& row_start = sc.row_start;
  row_start.assign(grid_h + 1, 0);
  engine::jobs::parallel_for<std::size_t>(0, grid_h, 8, [&](std::size_t b, std::size_t e) {
    for (std::size_t j = b; j < e; ++j) {
      std::size_t n = 0;
      for (std::size_t c = j * grid_w; c < (j + 1) * grid_w; ++c) n += decodes(c) ? 1 : 0;
      row_start[j + 1] = n;
    }
  });
  for (std::size_t j = 0; j < grid_h; ++j) row_start[j + 1] += row_start[j];
  decode.resize(row_start[grid_h]);
  sc.decoded_cells.resize(row_start[grid_h]);
  engine::jobs::parallel_for<std::size_t>(0, grid_h, 8, [&](std::size_t b, std::size_t e) {
    for (std::size_t j = b; j < e; ++j) {
      std::size_t slot = row_start[j];
      for (std::size_t c = j * grid_w; c < (j + 1) * grid_w; ++c)
        if (decodes(c)) {
          slot_of_pixel[up.cell_pixel[c]] = slot;
          decode[slot] = up.cell_pixel[c];
          sc.decoded_cells[slot++] = c;
        }
    }
  });
  stats.grid_samples = decode.size();
  // Pixels on their own: a few along silhouettes, found by rows in parallel.
  std::vector<std::uint8_t>& row_has_own = sc.row_has_own;
  row_has_own.assign(static_cast<std::size_t>(g.height), 0);
  const std::size_t width = static_cast<std::size_t>(g.width);
  engine::jobs::parallel_for<std::size_t>(0, row_has_own.size(), 8, [&](std::size_t b, std::size_t e) {
    for (std::size_t y = b; y < e; ++y)
      row_has_own[y] = std::find(up.kind.begin() + static_cast<std::ptrdiff_t>(y * width),
                                 up.kind.begin() + static_cast<std::ptrdiff_t>((y + 1) * width), UpsamplingPlan::kOwn) !=
                       up.kind.begin() + static_cast<std::ptrdiff_t>((y + 1) * width);
  });
  // guide[p].w > 0 is samples[p].hit, read from 16 bytes a pixel instead of a GSample.
  for (std::size_t y = 0; y < row_has_own.size(); ++y)
    if (row_has_own[y])
      for (std::size_t p = y * width; p < (y + 1) * width; ++p)
        if (up.kind[p] == UpsamplingPlan::kOwn && slot_of_pixel[p] == kNone && guide[p].w > 0) {
          slot_of_pixel[p] = decode.size();
          decode.push_back(p);
        }
  stats.edge_samples = decode.size() - stats.grid_samples;
}

// Stage 2, route. After it: sc.net (with sc.rotation_of) and sc.diffuse
// split the decoded samples (indices into sc.decode) into those the network
// decodes and those lit diffusely (glossy dielectrics, objects without
// transfer), and `rotated` holds the probes' SH in each moved object's frame.
void route_samples(const GiFrameInputs& in, RealtimeGiScratch::Impl& sc, RotatedProbes& rotated) {
  const std::vector<std::size_t>& decode = sc.decode;
  sc.net.clear();
  sc.diffuse.clear();
  sc.rotation_of.clear();
  // Each sample's entity and glossiness gathered in parallel (the reads
  // miss cache: the G-buffer was written long before), then routed in order.
  sc.sample_entity.resize(decode.size());
  sc.sample_glossy.resize(decode.size());
  engine::jobs::parallel_for<std::size_t>(0, decode.size(), 2048, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      sc.sample_entity[i] = in.g.entity[decode[i]];
      sc.sample_glossy[i] = in.is_glossy_dielectric(decode[i]) ? 1 : 0;
    }
  });
  std::unordered_map<engine::ecs::Entity, std::pair<bool, int>> per_entity;
  // Neighbouring samples mostly lie on one entity: look it up only when it changes.
  engine::ecs::Entity last{};
  std::pair<bool, int> last_route{false, -1};
  for (std::size_t i = 0; i < decode.size(); ++i) {
    const engine::ecs::Entity e = sc.sample_entity[i];
    if (i == 0 || !(e == last)) {
      auto [it, inserted] = per_entity.try_emplace(e, false, -1);
      if (inserted) {
        it->second.first = in.network_decodes(e);
        if (it->second.first) it->second.second = rotated.add(in.scene.instance_of(e)->to_world.rotation);
      }
      last = e;
      last_route = it->second;
    }
    if (last_route.first && !sc.sample_glossy[i]) {
      sc.net.push_back(i);
      sc.rotation_of.push_back(last_route.second);
    } else {
      sc.diffuse.push_back(i);
    }
  }
  rotated.rotate_all();
}

// Stage 3, light the diffuse samples. After it: sc.value (and
// sc.value_direct) hold each diffuse sample's light over its base colour,
// sc.queries and sc.net_position / net_normal each network sample's input,
// sc.contact_gain every decoded sample's.
void light_diffuse_samples(const GiFrameInputs& in, RealtimeGiScratch::Impl& sc) {
  const GBuffer& g = in.g;
  const std::vector<std::size_t>& decode = sc.decode;
  const std::vector<std::size_t>& net = sc.net;
  const std::vector<std::size_t>& diffuse = sc.diffuse;
  // Every entry below is written before it is read: resize, never refill.
  // With the reuse, the reused cells' values follow the decoded ones
  // (merge_reused_cells): sized once, so no frame shrinks and regrows (and
  // clears) them.
  const std::size_t value_slots = decode.size() + (in.reuse ? sc.up.cell_pixel.size() : 0);
  sc.value.resize(value_slots);
  sc.value_direct.resize(in.with_direct ? value_slots : 0);
  sc.queries.resize(net.size());
  sc.net_position.resize(net.size());
  sc.net_normal.resize(net.size());
  const bool with_contact = in.near_field.rays > 0;
  sc.contact_gain.resize(with_contact ? decode.size() : 0);
  engine::jobs::parallel_for<std::size_t>(0, net.size(), 1024, [&](std::size_t b, std::size_t e) {
    for (std::size_t k = b; k < e; ++k) {
      const GSample& s = g.samples[decode[net[k]]];
      sc.queries[k] = {s.mesh, s.triangle, s.bary, s.albedo, s.normal_obj, s.wo_obj};
      sc.net_position[k] = s.position;
      sc.net_normal[k] = s.normal_world;
      if (with_contact) sc.contact_gain[net[k]] = s.diffuse / model::demodulation(s.albedo) * engine::math::kInvPi;
    }
  });
  engine::jobs::parallel_for<std::size_t>(0, diffuse.size(), 256, [&](std::size_t b, std::size_t e) {
    // A tile of points' light at once (probes::interpolate_fields_many), then each one's.
    std::array<glm::vec3, kFusedTile> position, normal;
    std::array<float, kFusedTile * 75> light, light_direct;
    for (std::size_t t0 = b; t0 < e; t0 += kFusedTile) {
      const std::size_t t1 = std::min(e, t0 + kFusedTile);
      for (std::size_t k = t0; k < t1; ++k) {
        const GSample& s = g.samples[decode[diffuse[k]]];
        position[k - t0] = s.position;
        normal[k - t0] = s.normal_world;
      }
      probes::interpolate_fields_many(
          in.fields, position.data(), normal.data(), t1 - t0,
          [](std::size_t, const probes::ProbeField* f) { return f->light_sh_all().data(); },
          [](std::size_t, const probes::ProbeField* f) { return f->direct_sh_all().data(); }, light.data(),
          in.with_direct ? light_direct.data() : nullptr);
      for (std::size_t k = t0; k < t1; ++k) {
        const GSample& s = g.samples[decode[diffuse[k]]];
        const float* world = light.data() + (k - t0) * 75;
        const float* world_direct = in.with_direct ? light_direct.data() + (k - t0) * 75 : nullptr;
        // Over the base colour, as every sample is upsampled (below); a glossy
        // dielectric's diffuse lobe less what its specular layer reflects.
        glm::vec3 over = s.diffuse / model::demodulation(s.albedo) * engine::math::kInvPi;
        // (1 - s E(wo): brdf.h's layer coupling averaged over the incoming light).
        if (in.is_glossy_dielectric(decode[diffuse[k]])) over *= glm::vec3(1.0f) - specular_layer_albedo(s);
        sc.value[diffuse[k]] = over * sh_irradiance(world, s.normal_world);
        if (with_contact) sc.contact_gain[diffuse[k]] = over;
        if (in.with_direct) sc.value_direct[diffuse[k]] = over * sh_irradiance(world_direct, s.normal_world);
      }
    }
  });
}

// The network samples' shaded light into their value slots, over the base
// colour as every sample is upsampled (issue 37): a demodulated model's
// already is; a format-1 model's is divided here.
void store_network_values(const GiFrameInputs& in, RealtimeGiScratch::Impl& sc) {
  const std::vector<std::size_t>& net = sc.net;
  const bool demodulated = in.request.model->demodulated;
  engine::jobs::parallel_for<std::size_t>(0, net.size(), 1024, [&](std::size_t b, std::size_t e) {
    for (std::size_t k = b; k < e; ++k) {
      const glm::vec3 inv = demodulated ? glm::vec3(1.0f) : 1.0f / model::demodulation(in.g.albedo[sc.decode[net[k]]]);
      sc.value[net[k]] = inv * sc.shaded[k];
      if (in.with_direct) sc.value_direct[net[k]] = inv * sc.shaded_direct[k];
    }
  });
}

// Stage 4 with kept transfer: each network sample on a grid cell takes the
// transfer its cell kept, or decodes into a new slot of the history's pool;
// the pixels decoded on their own decode into own_transfer. Then all are lit.
double decode_or_keep_transfer(const GiFrameInputs& in, RealtimeGiScratch::Impl& sc, const TileLightFill& fill, RealtimeGiStats& stats) {
  const std::vector<std::size_t>& net = sc.net;
  const std::size_t grid = sc.decoded_cells.size();  // sc.decode lists the grid cells first
  sc.net_decode.resize(net.size());
  // Slots first (the pool may grow), then pointers into it.
  std::vector<std::uint32_t>& slot = sc.net_slot;
  slot.assign(net.size(), GiHistory::kNoSlot);
  std::size_t own = 0, kept = 0;
  for (std::size_t k = 0; k < net.size(); ++k) {
    if (net[k] >= grid) {
      sc.net_decode[k] = 1;
      ++own;
      continue;
    }
    const std::size_t cell = sc.decoded_cells[net[k]];
    slot[k] = sc.history.kept_slot(cell);
    sc.net_decode[k] = slot[k] == GiHistory::kNoSlot;
    if (sc.net_decode[k])
      slot[k] = sc.history.new_transfer_slot(cell);
    else
      ++kept;
  }
  sc.own_transfer.resize(own * 75);
  sc.net_transfer.resize(net.size());
  own = 0;
  for (std::size_t k = 0; k < net.size(); ++k)
    sc.net_transfer[k] = slot[k] != GiHistory::kNoSlot ? sc.history.transfer(slot[k]) : sc.own_transfer.data() + 75 * own++;
  stats.kept_transfers = kept;
  const double fill_seconds = shade_transfer_kept(*in.request.decoder, *in.request.model, in.assets, sc.queries, sc.net_transfer,
                                                  sc.net_decode, fill, sc.shaded.data(), in.with_direct ? sc.shaded_direct.data() : nullptr);
  store_network_values(in, sc);
  return fill_seconds;
}

// Stage 4, decode. After it: sc.value (and sc.value_direct) hold each
// network sample's light over its base colour. Returns the seconds the
// decoder's threads spent interpolating light (for the stage times).
double decode_network_samples(const GiFrameInputs& in, RealtimeGiScratch::Impl& sc, const RotatedProbes& rotated,
                              RealtimeGiStats& stats) {
  const std::vector<std::size_t>& net = sc.net;
  if (net.empty()) return 0.0;
  std::vector<glm::vec3>& shaded = sc.shaded;
  std::vector<glm::vec3>& shaded_direct = sc.shaded_direct;
  shaded.resize(net.size());
  shaded_direct.resize(in.with_direct ? net.size() : 0);
  const auto fill = [&](std::size_t b, std::size_t e, float* light, float* light_direct) {
    probes::interpolate_fields_many(
        in.fields, sc.net_position.data() + b, sc.net_normal.data() + b, e - b,
        [&](std::size_t k, const probes::ProbeField* f) { return rotated.sh(sc.rotation_of[b + k], f); },
        [&](std::size_t k, const probes::ProbeField* f) { return rotated.sh(sc.rotation_of[b + k], f, true); }, light, light_direct);
  };
  double fill_seconds = 0;
  if (in.keep_transfer) return decode_or_keep_transfer(in, sc, fill, stats);
  ProbeLightMaker* maker = in.request.batch_decoder && in.settings.device_lights ? in.request.batch_decoder->probe_lights() : nullptr;
  if (maker && !maker->set_probes(in.fields, static_cast<int>(rotated.count()),
                                  [&](int r, const probes::ProbeField* f, bool direct) { return rotated.sh(r, f, direct); }))
    maker = nullptr;  // more fields than the device takes: the CPU makes the lights
  if (maker)
    shade_transfer_device_lights(
        *in.request.batch_decoder, *maker, *in.request.model, in.assets, sc.queries,
        [&](std::size_t k) { return ProbeLightMaker::Point{sc.net_position[k], sc.rotation_of[k], sc.net_normal[k], 0.0f}; },
        shaded.data(), in.with_direct ? shaded_direct.data() : nullptr, &stats.inference_device_ms);
  else if (in.request.batch_decoder)
    fill_seconds = shade_transfer_batched(*in.request.batch_decoder, *in.request.model, in.assets, sc.queries, fill, shaded.data(),
                                          in.with_direct ? shaded_direct.data() : nullptr, &stats.inference_device_ms);
  else
    fill_seconds = shade_transfer_fused(*in.request.decoder, *in.request.model, in.assets, sc.queries, fill, shaded.data(),
                                        in.with_direct ? shaded_direct.data() : nullptr);
  store_network_values(in, sc);
  return fill_seconds;
}

// The decoded values' boundary: nothing non-finite reaches the upsampling.
// Returns how many samples it zeroed.
std::size_t zero_nonfinite_values(const GiFrameInputs& in, RealtimeGiScratch::Impl& sc) {
  const auto finite = [](const glm::vec3& v) { return std::isfinite(v.r) && std::isfinite(v.g) && std::isfinite(v.b); };
  std::size_t zeroed = 0;
  for (std::size_t i = 0; i < sc.decode.size(); ++i) {
    const bool ok = finite(sc.value[i]) && (!in.with_direct || finite(sc.value_direct[i]));
    if (ok) continue;
    sc.value[i] = glm::vec3(0.0f);
    if (in.with_direct) sc.value_direct[i] = glm::vec3(0.0f);
    ++zeroed;
  }
  return zeroed;
}

// Stage 5, with the reuse: the reused cells' values go after the decoded
// ones, a reused cell's slot at its cell index past them, so the cells are
// independent (no cell's pixel is another's). After it: every cell's value
// is in sc.cell_value and stored as the next frame's history. Returns the
// number of cells reused.
std::size_t merge_reused_cells(const GiFrameInputs& in, RealtimeGiScratch::Impl& sc) {
  const UpsamplingPlan& up = sc.up;
  const std::size_t cells = up.cell_pixel.size(), base = sc.decode.size();
  sc.cell_value.resize(cells);
  sc.cell_value_direct.resize(in.with_direct ? cells : 0);
  sc.fresh.resize(cells);
  std::atomic<std::size_t> reused{0};
  engine::jobs::parallel_for<std::size_t>(0, cells, 4096, [&](std::size_t b, std::size_t e) {
    std::size_t n = 0;
    for (std::size_t c = b; c < e; ++c) {
      const std::int32_t src = sc.source[c];
      const std::size_t p = up.cell_pixel[c];
      std::size_t slot = sc.slot_of_pixel[p];
      if (src != GiHistory::kDecode && slot == kNone) {
        slot = sc.slot_of_pixel[p] = base + c;
        sc.value[slot] = sc.history.value(src);
        if (in.with_direct) sc.value_direct[slot] = sc.history.value_direct(src);
        ++n;
      }
      const bool hit = slot != kNone;
      sc.cell_value[c] = hit ? sc.value[slot] : glm::vec3(0.0f);
      if (in.with_direct) sc.cell_value_direct[c] = hit ? sc.value_direct[slot] : glm::vec3(0.0f);
      sc.fresh[c] = hit && src == GiHistory::kDecode;
    }
    reused.fetch_add(n, std::memory_order_relaxed);
  });
  sc.history.store(sc.cell_value, sc.cell_value_direct, sc.fresh);
  return reused.load();
}

// Stage 6, upsample and composite. After it: every pixel of `image` holds
// its GI (zero where the camera missed), times its base colour, and
// direct_out has the probes' direct light added, except on the metals the
// reflection pass traces (their direct light comes from its ray).
void upsample_and_composite(const GiFrameInputs& in, RealtimeGiScratch::Impl& sc, engine::image::ImageRGB& image,
                            engine::image::ImageRGB* direct_out) {
  const GBuffer& g = in.g;
  const UpsamplingPlan& up = sc.up;
  const float metal_ray_roughness = in.reflections ? std::max(in.mirror.max_roughness, in.mirror.glossy_max_roughness) : -1.0f;
  // Every cell's value in one dense array (zero for a miss cell, whose taps
  // have zero weight), so a tap is one load: with the reuse, the history's
  // (this frame's, stored by merge_reused_cells); else gathered here.
  std::span<const glm::vec3> cell_values, cell_values_direct;
  if (in.reuse) {
    cell_values = sc.history.values();
    cell_values_direct = sc.history.values_direct();
  } else {
    const std::size_t cells = up.cell_pixel.size();
    sc.cell_value.resize(cells);
    sc.cell_value_direct.resize(in.with_direct ? cells : 0);
    engine::jobs::parallel_for<std::size_t>(0, cells, 4096, [&](std::size_t b, std::size_t e) {
      for (std::size_t c = b; c < e; ++c) {
        const std::size_t slot = sc.slot_of_pixel[up.cell_pixel[c]];
        sc.cell_value[c] = slot != kNone ? sc.value[slot] : glm::vec3(0.0f);
        if (in.with_direct) sc.cell_value_direct[c] = slot != kNone ? sc.value_direct[slot] : glm::vec3(0.0f);
      }
    });
    cell_values = sc.cell_value;
    cell_values_direct = sc.cell_value_direct;
  }
  engine::jobs::parallel_for(0, g.height, 8, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < g.width; ++x) {
        const std::size_t p = static_cast<std::size_t>(y) * g.width + x;
        if (up.kind[p] == UpsamplingPlan::kMiss) {
          image.pixels[p] = glm::vec3(0.0f);
          continue;
        }
        const glm::vec3 albedo = model::demodulation(g.albedo[p]);
        const bool add_direct = in.with_direct && !(g.metal_roughness[p] <= metal_ray_roughness);
        if (up.kind[p] == UpsamplingPlan::kOwn) {
          image.pixels[p] = albedo * sc.value[sc.slot_of_pixel[p]];
          if (add_direct) direct_out->pixels[p] += albedo * sc.value_direct[sc.slot_of_pixel[p]];
          continue;
        }
        glm::vec3 sum(0.0f), sum_direct(0.0f);
        for (int k = 0; k < 4; ++k) {
          const float w = up.weight[static_cast<std::size_t>(k)][p];
          if (!(w > 0)) continue;
          const std::size_t c = up.cell(k, x, y);
          sum += w * cell_values[c];
          if (add_direct) sum_direct += w * cell_values_direct[c];
        }
        image.pixels[p] = albedo * sum;
        if (add_direct) direct_out->pixels[p] += albedo * sum_direct;
      }
  });
}

}  // namespace

engine::image::ImageRGB shade_gi_realtime(const RealtimeGiRequest& request, const RealtimeGiOutputs& out) {
  const GBuffer& g = request.gbuffer;
  const std::span<const probes::ProbeField* const> fields = request.fields;
  RealtimeGiStats* const stats_out = out.stats;
  engine::image::ImageRGB* const direct_out = out.direct;
  RealtimeGiScratch* const scratch = out.scratch;
  RealtimeGiStats stats;
  // A recycled image of the right size is not cleared: the upsampling below
  // writes every pixel.
  engine::image::ImageRGB image;
  const bool writes_every_pixel = !fields.empty() && !g.samples.empty();
  if (scratch && writes_every_pixel && scratch->impl->recycled.width == g.width && scratch->impl->recycled.height == g.height)
    image = std::move(scratch->impl->recycled);
  else
    image = engine::image::ImageRGB(g.width, g.height);
  // The probes' direct light is added to what direct_out holds (the rest of
  // the frame's direct light): one pass over it, not an image and a sum.
  if (direct_out && (direct_out->width != g.width || direct_out->height != g.height)) *direct_out = engine::image::ImageRGB(g.width, g.height);
  if (!writes_every_pixel) {
    if (stats_out) *stats_out = stats;
    return image;
  }
  if (g.guide.size() != g.samples.size() || g.entity.size() != g.samples.size() || g.metal_roughness.size() != g.samples.size() ||
      g.dielectric_roughness.size() != g.samples.size())
    throw std::invalid_argument("shade_gi_realtime: the G-buffer lacks its per-pixel arrays; make it with trace_gbuffer");
  RealtimeGiScratch local;
  RealtimeGiScratch::Impl& sc = *(scratch ? scratch : &local)->impl;
  const bool reuse = request.settings.reuse_history && scratch != nullptr && g.camera.has_value();
  const GiFrameInputs in{request,
                        reuse,
                        reuse && request.settings.transfer_max_age > 0 && !request.batch_decoder && request.decoder && request.model,
                        direct_out != nullptr,
                        request.mirror.max_roughness >= 0,
                        request.mirror.max_roughness >= 0 && request.mirror.dielectric_max_roughness >= 0};

  auto t0 = Clock::now();
  plan_decode(in, sc, stats);
  const double plan_ms = ms_since(t0);

  t0 = Clock::now();
  RotatedProbes rotated(fields);
  route_samples(in, sc, rotated);
  stats.rotations = rotated.count();
  stats.rotate_ms = ms_since(t0);

  // Light per decoded sample: irradiance for the diffuse samples, object-
  // space SH for the network, whose SH is interpolated tile by tile inside
  // the fused decoder, so it stays in cache instead of going through memory.
  t0 = Clock::now();
  light_diffuse_samples(in, sc);
  const double diffuse_light_ms = ms_since(t0);
  t0 = Clock::now();
  const double fill_seconds = decode_network_samples(in, sc, rotated, stats);
  // The decoder's wall time, split by the share its threads spent
  // interpolating light (reported as SH light) and decoding (inference).
  const double fused_ms = ms_since(t0);
  const double fill_ms = std::min(fused_ms, 1e3 * fill_seconds / std::max(1, engine::jobs::current_thread_count()));
  stats.light_ms = diffuse_light_ms + fill_ms;
  stats.inference_ms = fused_ms - fill_ms;
  stats.inferred = sc.net.size() - stats.kept_transfers;
  stats.diffuse = sc.diffuse.size();
  stats.nonfinite_samples = zero_nonfinite_values(in, sc);

  // The contact light, on the cells decoded this frame, before their values
  // become the next frame's history: a reused cell keeps the contact light
  // it was given when it was decoded, so the reuse still halves the work.
  if (in.near_field.rays > 0) {
    t0 = Clock::now();
    // The lattice's cells need not be decoded this frame: their route as route_samples decides it.
    const std::function<float(std::size_t)> own_masked_within = [&](std::size_t p) {
      const GSample& s = g.samples[p];
      if (!s.hit || !in.network_decodes(g.entity[p]) || in.is_glossy_dielectric(p)) return 0.0f;
      const engine::rt::InstanceRecord* instance = in.scene.instance_of(s.entity);
      return instance ? in.request.model->self_masked_within(*in.assets.meshes[s.mesh]) * instance->to_world.scale : 0.0f;
    };
    add_contact_light(g, in.scene, fields, request.mirror_lights, in.near_field, sc.up, sc.decoded_cells, own_masked_within, sc.contact_gain,
                      in.reuse ? std::span<const std::int32_t>(sc.contact.track) : std::span<const std::int32_t>(),
                      in.reuse ? std::span<const std::uint8_t>(sc.contact.moved) : std::span<const std::uint8_t>(), sc.contact,
                      std::span<const std::size_t>(sc.decode).subspan(sc.decoded_cells.size()), sc.value);
    stats.near_ms = ms_since(t0);
  }
  if (in.reuse) stats.reused_cells = merge_reused_cells(in, sc);

  t0 = Clock::now();
  upsample_and_composite(in, sc, image, direct_out);
  stats.upsample_ms = plan_ms + ms_since(t0);

  if (in.reflections) {
    t0 = Clock::now();
    stats.reflection_rays = shade_metal_reflections(g, in.scene, fields, in.mirror, request.mirror_lights, image, direct_out);
    if (in.glossy_dielectrics)
      stats.reflection_rays += shade_dielectric_reflections(g, in.scene, fields, request.mirror_lights, in.mirror.dielectric_max_roughness,
                                                            sc.dielectric_rays, image, direct_out);
    stats.reflect_ms = ms_since(t0);
  }
  if (stats_out) *stats_out = stats;
  return image;
}

}  // namespace transgi::shading
