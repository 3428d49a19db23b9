#pragma once
// Decoding transfer for shading points: the batched path the renderer uses
// (inputs assembled in parallel, the decoder run on large batches through the
// GEMM backend, which is SIMD and multi-threaded), and a plain scalar
// reference that decodes one point with ordinary loops, to test it against.
#include <cstdint>
#include <functional>
#include <span>

#include <glm/glm.hpp>

#include "model/transfer_model.h"
#include "shading/fused_decoder.h"
#include "shading/probe_light_maker.h"
#include "shading/transfer_batch_decoder.h"

namespace transgi::shading {

// One shading point, all in its object's space.
struct TransferQuery {
  std::uint32_t mesh = 0, triangle = 0;
  glm::vec2 barycentric{0.0f};  // Embree's (b1, b2)
  glm::vec3 albedo{0.0f}, normal{0.0f, 0.0f, 1.0f}, wo{0.0f, 0.0f, 1.0f};
};

struct InferenceTimings {
  double inputs_ms = 0, inference_ms = 0;
};

// out: queries.size() x 75 transfer values ([c * 25 + k] per point).
InferenceTimings infer_transfer(const model::TransferModel& model, const engine::scene::SceneAssets& assets,
                                std::span<const TransferQuery> queries, float* out);

// The fused path (issue 10): per tile of kFusedTile queries, gathers and
// interpolates the latents, builds the inputs and runs decoder.shade_tile,
// which dots the decoded transfer with each query's object-space SH light
// (light: queries.size() x 75) without storing it. Tiles run in parallel on
// the job system. out: one RGB radiance per query. With light2 and out2,
// the same transfer is also dotted with a second light into out2.
void shade_transfer_fused(const FusedDecoder& decoder, const model::TransferModel& model,
                          const engine::scene::SceneAssets& assets, std::span<const TransferQuery> queries,
                          const float* light, glm::vec3* out, const float* light2 = nullptr, glm::vec3* out2 = nullptr);

// The same with each tile's light computed by `fill` just before the tile
// is decoded (fill(begin, end, light, light2) writes (end - begin) x 75
// values into each, light2 only when out2 is given), so the lights of a
// frame never go to memory as a whole: they stay in the cache of the core
// that decodes them. Returns the seconds spent in fill, summed over threads.
using TileLightFill = std::function<void(std::size_t begin, std::size_t end, float* light, float* light2)>;
double shade_transfer_fused(const FusedDecoder& decoder, const model::TransferModel& model,
                            const engine::scene::SceneAssets& assets, std::span<const TransferQuery> queries,
                            const TileLightFill& fill, glm::vec3* out, glm::vec3* out2 = nullptr);

// The fused decoder with the transfer kept across frames (gi_history.h):
// query i is decoded into transfer[i] (75 values) only where decode[i] is
// set; elsewhere transfer[i] already holds what an earlier frame decoded.
// Then out[i] = transfer[i] . light (dot_transfer), the light made by fill
// tile by tile as above; out2 with the second light. The same transfer gives
// the same out[i], decoded this frame or kept. Returns the seconds spent in
// fill, summed over threads.
double shade_transfer_kept(const FusedDecoder& decoder, const model::TransferModel& model,
                           const engine::scene::SceneAssets& assets, std::span<const TransferQuery> queries,
                           std::span<float* const> transfer, std::span<const std::uint8_t> decode, const TileLightFill& fill,
                           glm::vec3* out, glm::vec3* out2 = nullptr);

// sum over k of transfer[c * 25 + k] * light[c * 25 + k], channel c per component.
glm::vec3 dot_transfer(const float* transfer, const float* light);

// The same for one point: latent interpolation, input assembly and every
// layer as scalar loops (no GEMM library, no threads).
void infer_transfer_reference(const model::TransferModel& model, const engine::scene::SceneAssets& assets,
                              const TransferQuery& query, float* out75);

// The same through a batch decoder (a GPU kernel): fill and the inputs are
// written in parallel tiles straight into the decoder's batch, which is then
// decoded at once. Returns the seconds spent in fill, summed over threads;
// device_ms: the decoder's own time (-1 where unknown).
double shade_transfer_batched(TransferBatchDecoder& decoder, const model::TransferModel& model,
                              const engine::scene::SceneAssets& assets, std::span<const TransferQuery> queries,
                              const TileLightFill& fill, glm::vec3* out, glm::vec3* out2 = nullptr,
                              double* device_ms = nullptr);

// The same where the decoder makes the lights itself (probe_lights() after
// set_probes): each query's network input and its point (where the probes
// are interpolated) go into the batch instead of a light.
void shade_transfer_device_lights(TransferBatchDecoder& decoder, ProbeLightMaker& lights, const model::TransferModel& model,
                                    const engine::scene::SceneAssets& assets, std::span<const TransferQuery> queries,
                                    const std::function<ProbeLightMaker::Point(std::size_t)>& point_of, glm::vec3* out,
                                    glm::vec3* out2 = nullptr, double* device_ms = nullptr);

}  // namespace transgi::shading
