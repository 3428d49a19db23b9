#pragma once
// A binned-SAH BVH over boxes, built on the CPU for the GPU's traversal
// (engine/gpu/gpu_rt_scene): per mesh once (a BLAS over its triangles) and
// per frame over the instances (the TLAS). Embree keeps its own trees for
// the CPU queries; this one exists because a compute shader needs a tree it
// can read, in a layout we own.
#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

namespace engine::rt {

struct BvhBox {
  glm::vec3 min{0.0f}, max{0.0f};
};

struct BvhNode {
  BvhBox bounds;
  std::uint32_t first = 0;  // interior: left child (right = first + 1); leaf: first item in `order`
  std::uint32_t count = 0;  // 0 = interior
};

struct Bvh {
  std::vector<BvhNode> nodes;        // nodes[0] is the root
  std::vector<std::uint32_t> order;  // item indices, leaves' ranges point into it
};

// max_leaf: items a leaf may hold (higher = shallower tree and fewer nodes,
// at the cost of more triangle tests per leaf). Items with a non-finite box
// are left out of the tree (no ray could hit them) and listed at the end of
// `order`, past every leaf's range. With no finite item the root's box is
// empty, so no ray enters it.
Bvh build_bvh(std::span<const BvhBox> boxes, std::uint32_t max_leaf = 4);

}  // namespace engine::rt
