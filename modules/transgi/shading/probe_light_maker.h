#pragma once
// A batch decoder that also makes its points' lights (the probes interpolated
// on its device, as probes::interpolate_fields_with does on the CPU): the
// frame hands it each point's position, normal and rotation, 32 bytes,
// instead of 150 floats of light. On a discrete GPU those floats crossing
// the bus cost more than the decoding saved (docs/gpu-h100.md).
#include <cstddef>
#include <functional>
#include <span>

#include <glm/glm.hpp>

#include "probes/probe_field.h"

namespace transgi::shading {

class ProbeLightMaker {
 public:
  // A point as the device reads it: world position, the index of the
  // rotated SH copy its object's frame takes (-1: the world's), world normal.
  struct Point {
    glm::vec3 position;
    int rotation = -1;
    glm::vec3 normal;
    float pad = 0.0f;
  };
  // Field f's indirect (direct = false) or direct SH array, probes x 75, as
  // seen in rotation r's frame (r = -1: the world's own arrays).
  using ShOf = std::function<const float*(int r, const probes::ProbeField* f, bool direct)>;

  virtual ~ProbeLightMaker() = default;
  // This frame's fields, in the order shading consults them, and their SH
  // copies for rotations -1 .. rotations - 1. False where the device cannot
  // take them (more fields than it holds): the caller makes the lights.
  virtual bool set_probes(std::span<const probes::ProbeField* const> fields, int rotations, const ShOf& sh) = 0;
  // After TransferBatchDecoder::begin(n, second) and set_probes: room for the
  // n points, valid until run(), which makes their lights before decoding.
  virtual std::span<Point> points(std::size_t n) = 0;
};

}  // namespace transgi::shading
