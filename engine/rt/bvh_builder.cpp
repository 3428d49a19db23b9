#include "engine/rt/bvh_builder.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace engine::rt {
namespace {

BvhBox empty_box() {
  const float inf = std::numeric_limits<float>::infinity();
  return {glm::vec3(inf), glm::vec3(-inf)};
}
void grow(BvhBox& b, const BvhBox& o) {
  b.min = glm::min(b.min, o.min);
  b.max = glm::max(b.max, o.max);
}
float area(const BvhBox& b) {
  const glm::vec3 e = glm::max(b.max - b.min, glm::vec3(0.0f));
  return e.x * e.y + e.y * e.z + e.z * e.x;
}

constexpr int kBins = 12;

struct Builder {
  std::span<const BvhBox> boxes;
  std::uint32_t max_leaf;
  std::vector<glm::vec3> centre;
  Bvh out;

  // Splits order[begin, end) into node `at`; children are appended in pairs.
  void build(std::uint32_t at, std::uint32_t begin, std::uint32_t end) {
    BvhBox bounds = empty_box(), cbounds = empty_box();
    for (std::uint32_t i = begin; i < end; ++i) {
      const std::uint32_t item = out.order[i];
      grow(bounds, boxes[item]);
      grow(cbounds, {centre[item], centre[item]});
    }
    out.nodes[at].bounds = bounds;
    const std::uint32_t n = end - begin;
    auto make_leaf = [&] {
      out.nodes[at].first = begin;
      out.nodes[at].count = n;
    };
    if (n <= max_leaf) return make_leaf();

    // Binned SAH over the widest axis of the centres.
    const glm::vec3 extent = cbounds.max - cbounds.min;
    const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
    std::uint32_t mid = begin + n / 2;
    if (extent[axis] > 0 && std::isfinite(extent[axis])) {
      std::array<BvhBox, kBins> bin_box;
      std::array<std::uint32_t, kBins> bin_count{};
      bin_box.fill(empty_box());
      const float scale = kBins / extent[axis];
      auto bin_of = [&](std::uint32_t item) {
        return std::clamp(static_cast<int>((centre[item][axis] - cbounds.min[axis]) * scale), 0, kBins - 1);
      };
      for (std::uint32_t i = begin; i < end; ++i) {
        const int b = bin_of(out.order[i]);
        ++bin_count[static_cast<std::size_t>(b)];
        grow(bin_box[static_cast<std::size_t>(b)], boxes[out.order[i]]);
      }
      float best = std::numeric_limits<float>::infinity();
      int best_split = -1;
      for (int split = 1; split < kBins; ++split) {
        BvhBox l = empty_box(), r = empty_box();
        std::uint32_t nl = 0, nr = 0;
        for (int b = 0; b < split; ++b) grow(l, bin_box[static_cast<std::size_t>(b)]), nl += bin_count[static_cast<std::size_t>(b)];
        for (int b = split; b < kBins; ++b) grow(r, bin_box[static_cast<std::size_t>(b)]), nr += bin_count[static_cast<std::size_t>(b)];
        if (nl == 0 || nr == 0) continue;
        const float cost = area(l) * static_cast<float>(nl) + area(r) * static_cast<float>(nr);
        if (cost < best) best = cost, best_split = split;
      }
      if (best_split > 0) {
        auto* first = out.order.data() + begin;
        auto* last = out.order.data() + end;
        mid = static_cast<std::uint32_t>(std::partition(first, last, [&](std::uint32_t item) { return bin_of(item) < best_split; }) -
                                         out.order.data());
      }
    }
    if (mid == begin || mid == end) {  // all centres in one bin: split by position along the axis
      std::nth_element(out.order.begin() + begin, out.order.begin() + begin + n / 2, out.order.begin() + end,
                       [&](std::uint32_t a, std::uint32_t b) { return centre[a][axis] < centre[b][axis]; });
      mid = begin + n / 2;
    }
    const auto left = static_cast<std::uint32_t>(out.nodes.size());
    out.nodes.resize(out.nodes.size() + 2);
    out.nodes[at].first = left;
    out.nodes[at].count = 0;
    build(left, begin, mid);
    build(left + 1, mid, end);
  }
};

}  // namespace

Bvh build_bvh(std::span<const BvhBox> boxes, std::uint32_t max_leaf) {
  Builder b{boxes, std::max<std::uint32_t>(1, max_leaf), {}, {}};
  const auto n = static_cast<std::uint32_t>(boxes.size());
  b.centre.resize(n);
  std::vector<std::uint32_t> finite, broken;
  for (std::uint32_t i = 0; i < n; ++i) {
    const glm::vec3 c = 0.5f * (boxes[i].min + boxes[i].max);
    b.centre[i] = c;
    (std::isfinite(c.x) && std::isfinite(c.y) && std::isfinite(c.z) ? finite : broken).push_back(i);
  }
  b.out.order = finite;
  b.out.nodes.resize(1);
  if (finite.empty()) {
    b.out.nodes[0].bounds = empty_box();  // no ray enters; count 0 with no children would be interior, so a leaf of 0
    b.out.nodes[0].first = 0;
    b.out.nodes[0].count = 0;
    b.out.order.insert(b.out.order.end(), broken.begin(), broken.end());
    return b.out;
  }
  b.build(0, 0, static_cast<std::uint32_t>(finite.size()));
  // Items with non-finite boxes are left out of the tree (no ray can hit
  // them); they are kept at the end of `order` so the caller can count them.
  b.out.order.insert(b.out.order.end(), broken.begin(), broken.end());
  return std::move(b.out);
}

}  // namespace engine::rt
