#pragma once
// A transfer decoder that takes a frame's points in one batch: a GPU kernel
// (gpu::VulkanFusedDecoder) rather than the CPU's tile-at-a-time
// FusedDecoder. The CPU writes each point's network input and light straight
// into the spans begin() hands out (mapped device-visible memory), in
// parallel, and run() decodes the whole batch. The contract is
// FusedDecoder::shade_tile's: out[i] = sum_o transfer(inputs[i])[o] *
// light[i][o], per colour channel (light [c * 25 + k]).
#include <cstddef>
#include <span>

#include <glm/glm.hpp>

namespace transgi::shading {

class ProbeLightMaker;

class TransferBatchDecoder {
 public:
  struct Batch {
    std::span<float> inputs;  // n x inputs()
    std::span<float> light;   // n x 75
    std::span<float> light2;  // n x 75 when a second light was asked for, else empty
  };
  virtual ~TransferBatchDecoder() = default;
  [[nodiscard]] virtual int inputs() const = 0;
  // Room for n points; valid until the next begin().
  virtual Batch begin(std::size_t n, bool second) = 0;
  // Decodes the batch begin() handed out: out[n], and out2[n] when it asked
  // for a second light. Returns the device's milliseconds (-1 where unknown).
  virtual double run(glm::vec3* out, glm::vec3* out2) = 0;
  // Where the decoder can also make the lights from the probes: its maker
  // (probe_light_maker.h); null = the caller writes the lights.
  virtual ProbeLightMaker* probe_lights() { return nullptr; }
};

}  // namespace transgi::shading
