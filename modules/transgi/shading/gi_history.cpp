#include "shading/gi_history.h"

#include <algorithm>
#include <cmath>

#include "engine/jobs/parallel_for.h"
#include "shading/realtime_gi.h"

namespace transgi::shading {

namespace {
// Cosine of the largest angle between the object-space normals of a cell and
// the previous cell it takes its value from.
constexpr float kMinNormalCos = 0.9f;
constexpr float kNormalScale = 32767.0f;

// A kept transfer's lifetime in frames, between half and all of max_age,
// spread over cells and frames so that a view decoded at once (a cut) does
// not expire at once.
std::uint64_t transfer_lifetime(int max_age, std::size_t cell, std::uint64_t frame) {
  std::uint64_t h = (static_cast<std::uint64_t>(cell) << 20) ^ frame;
  h ^= h >> 33;
  h *= 0xff51afd7ed558ccdull;
  h ^= h >> 33;
  const std::uint64_t longest = static_cast<std::uint64_t>(max_age), shortest = (longest + 1) / 2;
  return shortest + h % (longest - shortest + 1);
}

}  // namespace

void GiHistory::clear() {
  prev_ = Cells{};
  cur_ = Cells{};
  pool_ = TransferPool{};
  keeping_ = TransferKeeping{};
  frame_ = 0;
}

std::uint32_t GiHistory::new_transfer_slot(std::size_t c) {
  if (pool_.free.empty()) {
    const std::size_t old = pool_.slots, grown = old + std::max<std::size_t>(4096, old / 2);
    pool_.slots = grown;
    pool_.values.resize(grown * 75);
    for (std::size_t s = grown; s-- > old;) pool_.free.push_back(static_cast<std::uint32_t>(s));
  }
  const std::uint32_t slot = pool_.free.back();
  pool_.free.pop_back();
  Anchor& a = cur_.anchor[c];
  a.object_position = cur_.key[c].object_position;
  for (int k = 0; k < 3; ++k) a.wo[k] = cur_.wo[c][static_cast<std::size_t>(k)];
  a.expires = frame_ + transfer_lifetime(keeping_.max_age, c, frame_);
  cur_.slot[c] = slot;
  return slot;
}

void GiHistory::collect_free_slots() {
  std::vector<std::uint8_t> held(pool_.slots, 0);
  for (const std::uint32_t s : prev_.slot)
    if (s != kNoSlot) held[s] = 1;
  pool_.free.clear();
  for (std::size_t s = held.size(); s-- > 0;)
    if (!held[s]) pool_.free.push_back(static_cast<std::uint32_t>(s));
}

void GiHistory::plan(const UpsamplingPlan& up, const GBuffer& g, const engine::rt::RtScene& scene, std::vector<std::int32_t>& source,
                     std::vector<std::int32_t>* track, std::vector<std::uint8_t>* moved, const TransferKeeping& keeping) {
  using engine::ecs::Entity;
  using engine::transform::Similarity;
  const std::size_t cells = up.cell_pixel.size();
  cur_.width = up.width;
  cur_.height = up.height;
  cur_.grid_w = up.grid_w;
  cur_.grid_h = up.grid_h;
  cur_.sx = up.sx;
  cur_.sy = up.sy;
  cur_.camera = g.camera;
  cur_.key.resize(cells);
  // Kept transfer: none is taken from another decoder or model, or once off.
  const bool keeps = keeping.max_age > 0;
  if (!keeps || keeping.decoder != keeping_.decoder || keeping.model != keeping_.model ||
      keeping.assets_generation != keeping_.assets_generation || keeping.assets_edit != keeping_.assets_edit) {
    pool_ = TransferPool{};
    prev_.slot.clear();
  }
  keeping_ = keeping;
  cur_.slot.assign(keeps ? cells : 0, kNoSlot);
  cur_.anchor.resize(keeps ? cells : 0);
  cur_.wo.resize(keeps ? cells : 0);
  source.assign(cells, kDecode);
  if (track) track->assign(cells, kDecode);
  if (moved) moved->assign(cells, 0);
  // The objects in view, numbered in the order their first cells come; a
  // handful, so found by a linear search once per run of cells on one object.
  // Each chunk of cells lists its objects in parallel, the lists are merged in
  // chunk order, then each cell is numbered in parallel.
  cur_.objects.clear();
  object_of_cell_.resize(cells);
  constexpr std::size_t kChunk = 4096;
  const std::size_t chunks = (cells + kChunk - 1) / kChunk;
  std::vector<std::vector<Entity>> seen(chunks);
  const auto entity_of = [&](std::size_t c) { return g.entity[up.cell_pixel[c]]; };
  engine::jobs::parallel_for<std::size_t>(0, chunks, 1, [&](std::size_t b, std::size_t e) {
    for (std::size_t k = b; k < e; ++k) {
      Entity last{};
      bool any = false;
      for (std::size_t c = k * kChunk; c < std::min(cells, (k + 1) * kChunk); ++c) {
        if (!(up.cell_guide[c].w > 0)) continue;
        const Entity en = entity_of(c);
        if (any && en == last) continue;
        any = true;
        last = en;
        if (std::find(seen[k].begin(), seen[k].end(), en) == seen[k].end()) seen[k].push_back(en);
      }
    }
  });
  for (const std::vector<Entity>& list : seen)
    for (const Entity en : list)
      if (std::none_of(cur_.objects.begin(), cur_.objects.end(), [&](const auto& o) { return o.first == en; })) {
        const engine::rt::InstanceRecord* inst = scene.instance_of(en);
        cur_.objects.emplace_back(en, inst ? inst->to_world : Similarity{});
      }
  engine::jobs::parallel_for<std::size_t>(0, cells, kChunk, [&](std::size_t b, std::size_t e) {
    Entity last{};
    std::uint32_t last_index = kNoObject;
    for (std::size_t c = b; c < e; ++c) {
      if (!(up.cell_guide[c].w > 0)) {
        object_of_cell_[c] = kNoObject;
        continue;
      }
      const Entity en = entity_of(c);
      if (!(en == last) || last_index == kNoObject) {
        last = en;
        last_index = 0;
        while (!(cur_.objects[last_index].first == en)) ++last_index;  // listed above
      }
      object_of_cell_[c] = last_index;
    }
  });
  // Per object in view, as matrices so a cell costs a few multiply-adds:
  // from a cell's camera-space direction (sx, sy, -1) and depth to the point
  // in the object's frame (c0 + depth / |dir| A dir); the world normal into
  // that frame; and, if the object was in view last frame (its number then),
  // from that point to last frame's camera space (prev_m p + prev_t).
  struct Motion {
    glm::mat3 a{1.0f}, normal{1.0f}, prev_m{1.0f};
    glm::vec3 c0{0.0f}, prev_t{0.0f};
    float to_object_scale = 1.0f;
    std::uint32_t prev_object = kNoObject;
    bool moved = false;  // its transform changed since the previous frame
  };
  const bool comparable = g.camera && prev_.camera && prev_.grid_w == up.grid_w && prev_.grid_h == up.grid_h &&
                          prev_.width == up.width && prev_.height == up.height && prev_.key.size() == cells;
  if (!g.camera) return;  // nothing to place the cells with: every cell is decoded
  const engine::render::CameraRays& cam = *g.camera;
  const glm::mat3 cam_rotation = glm::mat3_cast(cam.to_world().rotation);
  std::vector<Motion> motion(cur_.objects.size());
  for (std::size_t k = 0; k < motion.size(); ++k) {
    Motion& m = motion[k];
    const Similarity& to_world = cur_.objects[k].second;
    m.normal = glm::mat3_cast(glm::conjugate(to_world.rotation));
    m.to_object_scale = 1.0f / to_world.scale;
    m.a = m.to_object_scale * (m.normal * cam_rotation);
    m.c0 = m.to_object_scale * (m.normal * (cam.position() - to_world.translation));
    for (std::size_t q = 0; comparable && q < prev_.objects.size(); ++q)
      if (prev_.objects[q].first == cur_.objects[k].first) {
        const Similarity& prev_to_world = prev_.objects[q].second;
        const glm::mat3 prev_camera_from_world = glm::transpose(glm::mat3_cast(prev_.camera->to_world().rotation));
        m.prev_object = static_cast<std::uint32_t>(q);
        m.prev_m = prev_to_world.scale * (prev_camera_from_world * glm::mat3_cast(prev_to_world.rotation));
        m.prev_t = prev_camera_from_world * (prev_to_world.translation - prev_.camera->position());
        m.moved = !(prev_to_world == to_world);
      }
  }
  if (moved && comparable) {
    // Where a moved object is now, and where it was (the previous frame's
    // cell at the same place on screen).
    std::vector<std::uint8_t> prev_moved(prev_.objects.size(), 0);
    for (const Motion& m : motion)
      if (m.prev_object != kNoObject && m.moved) prev_moved[m.prev_object] = 1;
    engine::jobs::parallel_for<std::size_t>(0, cells, 4096, [&](std::size_t b, std::size_t e) {
      for (std::size_t c = b; c < e; ++c) {
        const std::uint32_t now = object_of_cell_[c], was = prev_.key[c].object;
        (*moved)[c] = now != kNoObject && motion[now].moved ? kMovedHere : (was < prev_moved.size() && prev_moved[was]) ? kMovedFrom : 0;
      }
    });
  }
  const float spread = cam.pixel_spread();
  const float cell_pixels = std::max(up.sx, up.sy);
  const unsigned parity = static_cast<unsigned>(frame_ & 1);
  // Film to camera space now, and last frame's camera space to its cells.
  const float dx = 2.0f * cam.tan_half_x() / static_cast<float>(cam.width()), dy = -2.0f * cam.tan_half_y() / static_cast<float>(cam.height());
  const float x0 = -cam.tan_half_x(), y0 = cam.tan_half_y();
  const float prev_kx = comparable ? 0.5f * static_cast<float>(prev_.camera->width()) / prev_.camera->tan_half_x() / prev_.sx : 0.0f;
  const float prev_ky = comparable ? 0.5f * static_cast<float>(prev_.camera->height()) / prev_.camera->tan_half_y() / prev_.sy : 0.0f;
  const float prev_u0 = comparable ? 0.5f * static_cast<float>(prev_.camera->width()) / prev_.sx - 0.5f : 0.0f;
  const float prev_v0 = comparable ? 0.5f * static_cast<float>(prev_.camera->height()) / prev_.sy - 0.5f : 0.0f;
  const std::size_t width = static_cast<std::size_t>(g.width);
  // Among the (up to four) previous cells around where the point was seen,
  // within `reach` in the object's frame, on the same object, normals alike:
  // the nearest fresh one (a value to reuse; only for reuse_colour) and the
  // nearest of any (the kept transfer). Where nothing moved, the same cell is
  // as good as the nearest. The track: the nearest of any within
  // `track_reach`, from the 4 x 4 cells around where none of the four is.
  struct Picks {
    std::int32_t fresh = kDecode, any = kDecode, track = kDecode;
  };
  const auto previous_cells = [&](std::size_t c, const Motion& m, const glm::vec3& p_obj, const glm::vec3& n_obj, float reach,
                                  float track_reach, bool reuse_colour) -> Picks {
    const auto matches = [&](const Key& k, float& d2) {
      if (k.object != m.prev_object) return false;
      const float cos_normal =
          (static_cast<float>(k.normal[0]) * n_obj.x + static_cast<float>(k.normal[1]) * n_obj.y + static_cast<float>(k.normal[2]) * n_obj.z) /
          kNormalScale;
      if (cos_normal < kMinNormalCos) return false;
      const glm::vec3 d = k.object_position - p_obj;
      d2 = glm::dot(d, d);
      return true;
    };
    float d2 = 0;
    if (!reuse_colour && matches(prev_.key[c], d2) && d2 <= reach * reach)
      return {kDecode, static_cast<std::int32_t>(c), static_cast<std::int32_t>(c)};
    const glm::vec3 local = m.prev_m * p_obj + m.prev_t;
    if (!(local.z < 0)) return {};  // behind last frame's camera
    // The previous cells around where the point was seen (cell centres at integers).
    const float inv = -1.0f / local.z;
    const float u = prev_u0 + prev_kx * local.x * inv, v = prev_v0 - prev_ky * local.y * inv;
    if (!(u > -1.0f && v > -1.0f && u < static_cast<float>(prev_.grid_w) && v < static_cast<float>(prev_.grid_h))) return {};
    const int i0 = static_cast<int>(u + 1.0f) - 1, j0 = static_cast<int>(v + 1.0f) - 1;  // floor, as u, v > -1
    float best = reach * reach, best_any = reach * reach, best_track = track_reach * track_reach;
    Picks picks;
    const auto look = [&](int di, int dj, bool inner) {
      const int pi = i0 + di, pj = j0 + dj;
      if (pi < 0 || pj < 0 || pi >= prev_.grid_w || pj >= prev_.grid_h) return;
      const std::size_t q = static_cast<std::size_t>(pj) * static_cast<std::size_t>(prev_.grid_w) + static_cast<std::size_t>(pi);
      const Key& k = prev_.key[q];
      if (!matches(k, d2)) return;
      if (inner && reuse_colour && k.fresh && d2 <= best) {
        best = d2;
        picks.fresh = static_cast<std::int32_t>(q);
      }
      if (inner && d2 <= best_any) {
        best_any = d2;
        picks.any = static_cast<std::int32_t>(q);
      }
      if (d2 <= best_track) {
        best_track = d2;
        picks.track = static_cast<std::int32_t>(q);
      }
    };
    for (int dj = 0; dj < 2; ++dj)
      for (int di = 0; di < 2; ++di) look(di, dj, true);
    // At an edge the jitter can put a cell's point on the far side of the
    // 2 x 2 cells around it, on the surface the last frame's cells beyond
    // them saw: the track looks one cell further.
    if (track && picks.track == kDecode)
      for (int dj = -1; dj < 3; ++dj)
        for (int di = -1; di < 3; ++di)
          if (dj < 0 || dj > 1 || di < 0 || di > 1) look(di, dj, false);
    return picks;
  };
  // A kept transfer is taken while the point is within a footprint of where
  // it was decoded (it does not creep cell by cell), the view direction
  // within the threshold, and the transfer within its lifetime.
  // The footprint is the cell's on its surface: wider by 1 / cos where the
  // surface is seen at a grazing angle (to 4x), where the antialiasing's
  // jitter moves a cell's point that much further along it.
  const auto transfer_still_holds = [&](const Anchor& a, const glm::vec3& p_obj, const glm::vec3& n_obj, const glm::vec3& wo_obj,
                                        float reach) {
    if (frame_ >= a.expires) return false;
    const glm::vec3 d = a.object_position - p_obj;
    const float on_surface = reach / std::max(std::abs(glm::dot(n_obj, wo_obj)), 0.25f);
    if (glm::dot(d, d) > on_surface * on_surface) return false;
    const float cos_view = (static_cast<float>(a.wo[0]) * wo_obj.x + static_cast<float>(a.wo[1]) * wo_obj.y +
                            static_cast<float>(a.wo[2]) * wo_obj.z) /
                           kNormalScale;
    return cos_view >= keeping_.min_view_cos;
  };
  auto body = [&](std::size_t b, std::size_t e_end) {
    for (std::size_t c = b; c < e_end; ++c) {
      Key& key = cur_.key[c];
      const std::uint32_t object = object_of_cell_[c];
      if (object == kNoObject) {
        key = Key{};
        continue;
      }
      const Motion& m = motion[object];
      // From the cell's guide and its camera ray, not its GSample: the
      // cells' 16-byte guides are in cache, their GSamples far apart.
      const glm::vec4& guide = up.cell_guide[c];
      const std::size_t pixel = up.cell_pixel[c];
      const glm::vec3 dir(x0 + dx * (static_cast<float>(pixel % width) + 0.5f + g.jitter.x),
                          y0 + dy * (static_cast<float>(pixel / width) + 0.5f + g.jitter.y), -1.0f);
      const float depth = guide.w;
      const glm::vec3 p_obj = m.c0 + (depth / std::sqrt(glm::dot(dir, dir))) * (m.a * dir);
      const glm::vec3 n_obj = m.normal * glm::vec3(guide);
      key.object_position = p_obj;
      key.object = object;
      for (int a = 0; a < 3; ++a) key.normal[a] = static_cast<std::int16_t>(std::clamp(n_obj[a], -1.0f, 1.0f) * kNormalScale);  // truncation: 3e-5 off at most
      key.fresh = 0;
      glm::vec3 wo_obj(0.0f);
      if (keeps) {
        wo_obj = -glm::normalize(m.a * dir);
        for (int a = 0; a < 3; ++a) cur_.wo[c][static_cast<std::size_t>(a)] = static_cast<std::int16_t>(std::clamp(wo_obj[a], -1.0f, 1.0f) * kNormalScale);
      }
      const int i = static_cast<int>(c % static_cast<std::size_t>(up.grid_w)), j = static_cast<int>(c / static_cast<std::size_t>(up.grid_w));
      const bool reuse_colour = ((static_cast<unsigned>(i + j) + parity) & 1) != 0;  // else this frame's colour: decoded
      if (m.prev_object == kNoObject || (!reuse_colour && !track && !keeps)) continue;
      // Within a cell's footprint at the point's depth, in object units.
      const float reach = depth * spread * cell_pixels * m.to_object_scale;
      // The track's reach is the cell's footprint on its surface, as a kept
      // transfer's (transfer_still_holds): where the surface is seen at a
      // grazing angle the jitter moves the point up to 1 / cos further along
      // it. With the cell's own footprint and the 2 x 2 cells alone, a tenth
      // to a fifth of the Living Room's cells lost their track every frame of
      // a still view, their near field's mean restarting from one frame's noise.
      const glm::vec3 wo_track = keeps ? wo_obj : -glm::normalize(m.a * dir);
      const float track_reach = reach / std::max(std::abs(glm::dot(n_obj, wo_track)), 0.25f);
      const Picks picks = previous_cells(c, m, p_obj, n_obj, reach, track_reach, reuse_colour);
      if (reuse_colour) source[c] = picks.fresh;
      if (track) (*track)[c] = picks.track;
      if (keeps && picks.any != kDecode) {
        const auto q = static_cast<std::size_t>(picks.any);
        const std::uint32_t slot = prev_.slot.empty() ? kNoSlot : prev_.slot[q];
        if (slot != kNoSlot && transfer_still_holds(prev_.anchor[q], p_obj, n_obj, wo_obj, reach)) {
          cur_.slot[c] = slot;
          cur_.anchor[c] = prev_.anchor[q];
        }
      }
    }
  };
  engine::jobs::parallel_for<std::size_t>(0, cells, 1024, body);
}

void GiHistory::store(std::vector<glm::vec3>& value, std::vector<glm::vec3>& value_direct, const std::vector<std::uint8_t>& fresh) {
  std::swap(cur_.value, value);
  std::swap(cur_.value_direct, value_direct);
  if (cur_.value_direct.size() != cur_.value.size()) cur_.value_direct.assign(cur_.value.size(), glm::vec3(0.0f));
  engine::jobs::parallel_for<std::size_t>(0, std::min(cur_.key.size(), fresh.size()), 4096, [&](std::size_t b, std::size_t e) {
    for (std::size_t c = b; c < e; ++c) cur_.key[c].fresh = fresh[c];
  });
  std::swap(prev_, cur_);
  if (keeping_.max_age > 0) collect_free_slots();
  ++frame_;
}

}  // namespace transgi::shading
