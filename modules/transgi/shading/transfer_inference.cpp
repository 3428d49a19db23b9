#include "shading/transfer_inference.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <stdexcept>
#include <vector>

#include "engine/jobs/parallel_for.h"

namespace transgi::shading {

namespace {
using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

// Large enough to keep the GEMM efficient, small enough that the activations
// (width x chunk floats per layer) stay in the last-level cache.
constexpr std::size_t kChunk = 8192;
static_assert(sizeof(glm::vec3) == 3 * sizeof(float), "shade_tile writes RGB triples into glm::vec3 arrays");

// Query q's network input at `dst`: its latent interpolated over its
// triangle (z: latent_dim floats of scratch), then albedo, normal, view.
void network_input(const model::TransferModel& model, const engine::scene::SceneAssets& assets, const TransferQuery& q,
                   float* z, float* dst) {
  model.meshes[q.mesh].latents.interpolate(*assets.meshes[q.mesh], q.triangle, q.barycentric, z);
  model::assemble_input(z, model.latent_dim, q.albedo, q.normal, q.wo, dst);
}

// fill(b, e, ...) with its time added to ns.
void timed_fill(const TileLightFill& fill, std::size_t b, std::size_t e, float* light, float* light2, std::int64_t& ns) {
  const auto t0 = Clock::now();
  fill(b, e, light, light2);
  ns += std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - t0).count();
}
}  // namespace

InferenceTimings infer_transfer(const model::TransferModel& model, const engine::scene::SceneAssets& assets,
                                std::span<const TransferQuery> queries, float* out) {
  InferenceTimings t;
  if (queries.empty()) return t;
  auto t0 = Clock::now();
  const int in_size = model.decoder.layout().inputs;
  std::vector<float> inputs(queries.size() * static_cast<std::size_t>(in_size));
  engine::jobs::parallel_for<std::size_t>(0, queries.size(), 1024, [&](std::size_t b, std::size_t e) {
    std::vector<float> z(static_cast<std::size_t>(model.latent_dim));
    for (std::size_t i = b; i < e; ++i)
      network_input(model, assets, queries[i], z.data(), inputs.data() + i * static_cast<std::size_t>(in_size));
  });
  t.inputs_ms = ms_since(t0);
  t0 = Clock::now();
  model::MlpWorkspace ws;
  const int outputs = model.decoder.layout().outputs;
  for (std::size_t b = 0; b < queries.size(); b += kChunk) {
    const std::size_t count = std::min(kChunk, queries.size() - b);
    model.decoder.forward(inputs.data() + b * static_cast<std::size_t>(in_size), static_cast<int>(count),
                          out + b * static_cast<std::size_t>(outputs), ws, model::default_gemm_backend());
  }
  t.inference_ms = ms_since(t0);
  return t;
}

double shade_transfer_fused(const FusedDecoder& decoder, const model::TransferModel& model,
                            const engine::scene::SceneAssets& assets, std::span<const TransferQuery> queries,
                            const TileLightFill& fill, glm::vec3* out, glm::vec3* out2) {
  const int in_size = decoder.layout().inputs;
  const std::size_t tiles = (queries.size() + kFusedTile - 1) / kFusedTile;
  std::atomic<std::int64_t> fill_ns{0};
  engine::jobs::parallel_for<std::size_t>(0, tiles, 4, [&](std::size_t tb, std::size_t te) {
    std::vector<float> inputs(static_cast<std::size_t>(kFusedTile) * static_cast<std::size_t>(in_size));
    std::vector<float> z(static_cast<std::size_t>(model.latent_dim));
    std::vector<float> light(static_cast<std::size_t>(kFusedTile) * 75), light2(out2 ? light.size() : 0);
    std::int64_t ns = 0;
    for (std::size_t tile = tb; tile < te; ++tile) {
      const std::size_t b = tile * kFusedTile, e = std::min(b + kFusedTile, queries.size());
      timed_fill(fill, b, e, light.data(), out2 ? light2.data() : nullptr, ns);
      for (std::size_t i = b; i < e; ++i)
        network_input(model, assets, queries[i], z.data(), inputs.data() + (i - b) * static_cast<std::size_t>(in_size));
      decoder.shade_tile(inputs.data(), light.data(), static_cast<int>(e - b), &out[b].x, out2 ? light2.data() : nullptr,
                         out2 ? &out2[b].x : nullptr);
    }
    fill_ns.fetch_add(ns, std::memory_order_relaxed);
  });
  return static_cast<double>(fill_ns.load()) * 1e-9;
}

glm::vec3 dot_transfer(const float* transfer, const float* light) {
  // Five partial sums a channel (k mod 5), added in a fixed order: fifteen
  // independent chains instead of three of 25 dependent adds, which kept the
  // lighting of a kept transfer waiting on add latency.
  glm::vec3 rgb(0.0f);
  for (int c = 0; c < 3; ++c) {
    const float* t = transfer + c * 25;
    const float* l = light + c * 25;
    float part[5] = {0.0f, 0.0f, 0.0f, 0.0f, 0.0f};
    for (int k = 0; k < 25; k += 5)
      for (int j = 0; j < 5; ++j) part[j] += t[k + j] * l[k + j];
    rgb[c] = ((part[0] + part[1]) + (part[2] + part[3])) + part[4];
  }
  return rgb;
}

double shade_transfer_kept(const FusedDecoder& decoder, const model::TransferModel& model,
                           const engine::scene::SceneAssets& assets, std::span<const TransferQuery> queries,
                           std::span<float* const> transfer, std::span<const std::uint8_t> decode, const TileLightFill& fill,
                           glm::vec3* out, glm::vec3* out2) {
  if (transfer.size() != queries.size() || decode.size() != queries.size())
    throw std::invalid_argument("shade_transfer_kept: one transfer pointer and one decode flag a query");
  // The queries to decode, gathered so that the decoder's tiles are full.
  std::vector<std::size_t> todo;
  for (std::size_t i = 0; i < queries.size(); ++i)
    if (decode[i]) todo.push_back(i);
  const int in_size = decoder.layout().inputs;
  const std::size_t decode_tiles = (todo.size() + kFusedTile - 1) / kFusedTile;
  engine::jobs::parallel_for<std::size_t>(0, decode_tiles, 2, [&](std::size_t tb, std::size_t te) {
    std::vector<float> inputs(static_cast<std::size_t>(kFusedTile) * static_cast<std::size_t>(in_size));
    std::vector<float> z(static_cast<std::size_t>(model.latent_dim));
    std::vector<float> decoded(static_cast<std::size_t>(kFusedTile) * 75);
    for (std::size_t tile = tb; tile < te; ++tile) {
      const std::size_t b = tile * kFusedTile, e = std::min(b + kFusedTile, todo.size());
      for (std::size_t t = b; t < e; ++t)
        network_input(model, assets, queries[todo[t]], z.data(), inputs.data() + (t - b) * static_cast<std::size_t>(in_size));
      decoder.decode_tile(inputs.data(), static_cast<int>(e - b), decoded.data());
      for (std::size_t t = b; t < e; ++t) std::copy_n(decoded.data() + (t - b) * 75, 75, transfer[todo[t]]);
    }
  });
  // Every query lit, tile by tile, its light made just before its dot.
  const std::size_t tiles = (queries.size() + kFusedTile - 1) / kFusedTile;
  std::atomic<std::int64_t> fill_ns{0};
  engine::jobs::parallel_for<std::size_t>(0, tiles, 4, [&](std::size_t tb, std::size_t te) {
    std::vector<float> light(static_cast<std::size_t>(kFusedTile) * 75), light2(out2 ? light.size() : 0);
    std::int64_t ns = 0;
    for (std::size_t tile = tb; tile < te; ++tile) {
      const std::size_t b = tile * kFusedTile, e = std::min(b + kFusedTile, queries.size());
      // The tile's transfers lie anywhere in the pool: fetched while its
      // light is made, not one miss at a time in the dots after.
      for (std::size_t i = b; i < e; ++i)
        for (std::size_t byte = 0; byte < 75 * sizeof(float); byte += 64) __builtin_prefetch(reinterpret_cast<const char*>(transfer[i]) + byte);
      timed_fill(fill, b, e, light.data(), out2 ? light2.data() : nullptr, ns);
      for (std::size_t i = b; i < e; ++i) {
        out[i] = dot_transfer(transfer[i], light.data() + (i - b) * 75);
        if (out2) out2[i] = dot_transfer(transfer[i], light2.data() + (i - b) * 75);
      }
    }
    fill_ns.fetch_add(ns, std::memory_order_relaxed);
  });
  return static_cast<double>(fill_ns.load()) * 1e-9;
}

double shade_transfer_batched(TransferBatchDecoder& decoder, const model::TransferModel& model,
                              const engine::scene::SceneAssets& assets, std::span<const TransferQuery> queries,
                              const TileLightFill& fill, glm::vec3* out, glm::vec3* out2, double* device_ms) {
  if (device_ms) *device_ms = 0.0;
  if (queries.empty()) return 0.0;
  const auto in_size = static_cast<std::size_t>(decoder.inputs());
  const TransferBatchDecoder::Batch batch = decoder.begin(queries.size(), out2 != nullptr);
  const std::size_t tiles = (queries.size() + kFusedTile - 1) / kFusedTile;
  std::atomic<std::int64_t> fill_ns{0};
  engine::jobs::parallel_for<std::size_t>(0, tiles, 4, [&](std::size_t tb, std::size_t te) {
    std::vector<float> z(static_cast<std::size_t>(model.latent_dim));
    std::int64_t ns = 0;
    for (std::size_t tile = tb; tile < te; ++tile) {
      const std::size_t b = tile * kFusedTile, e = std::min(b + kFusedTile, queries.size());
      timed_fill(fill, b, e, batch.light.data() + b * 75, out2 ? batch.light2.data() + b * 75 : nullptr, ns);
      for (std::size_t i = b; i < e; ++i) network_input(model, assets, queries[i], z.data(), batch.inputs.data() + i * in_size);
    }
    fill_ns.fetch_add(ns, std::memory_order_relaxed);
  });
  const double ms = decoder.run(out, out2);
  if (device_ms) *device_ms = ms;
  return static_cast<double>(fill_ns.load()) * 1e-9;
}

void shade_transfer_device_lights(TransferBatchDecoder& decoder, ProbeLightMaker& lights, const model::TransferModel& model,
                                    const engine::scene::SceneAssets& assets, std::span<const TransferQuery> queries,
                                    const std::function<ProbeLightMaker::Point(std::size_t)>& point_of, glm::vec3* out,
                                    glm::vec3* out2, double* device_ms) {
  if (device_ms) *device_ms = 0.0;
  if (queries.empty()) return;
  const auto in_size = static_cast<std::size_t>(decoder.inputs());
  const TransferBatchDecoder::Batch batch = decoder.begin(queries.size(), out2 != nullptr);
  const std::span<ProbeLightMaker::Point> points = lights.points(queries.size());
  const std::size_t tiles = (queries.size() + kFusedTile - 1) / kFusedTile;
  engine::jobs::parallel_for<std::size_t>(0, tiles, 4, [&](std::size_t tb, std::size_t te) {
    std::vector<float> z(static_cast<std::size_t>(model.latent_dim));
    for (std::size_t tile = tb; tile < te; ++tile) {
      const std::size_t b = tile * kFusedTile, e = std::min(b + kFusedTile, queries.size());
      for (std::size_t i = b; i < e; ++i) {
        points[i] = point_of(i);
        network_input(model, assets, queries[i], z.data(), batch.inputs.data() + i * in_size);
      }
    }
  });
  const double ms = decoder.run(out, out2);
  if (device_ms) *device_ms = ms;
}

void shade_transfer_fused(const FusedDecoder& decoder, const model::TransferModel& model,
                          const engine::scene::SceneAssets& assets, std::span<const TransferQuery> queries,
                          const float* light, glm::vec3* out, const float* light2, glm::vec3* out2) {
  const bool second = light2 && out2;
  shade_transfer_fused(
      decoder, model, assets, queries,
      [&](std::size_t b, std::size_t e, float* l, float* l2) {
        std::copy(light + b * 75, light + e * 75, l);
        if (second) std::copy(light2 + b * 75, light2 + e * 75, l2);
      },
      out, second ? out2 : nullptr);
}

void infer_transfer_reference(const model::TransferModel& model, const engine::scene::SceneAssets& assets,
                              const TransferQuery& q, float* out75) {
  const model::MlpLayout& layout = model.decoder.layout();
  const std::vector<float>& p = model.decoder.params();
  std::vector<float> z(static_cast<std::size_t>(model.latent_dim));
  model.meshes[q.mesh].latents.interpolate(*assets.meshes[q.mesh], q.triangle, q.barycentric, z.data());
  std::vector<float> x(static_cast<std::size_t>(layout.inputs));
  model::assemble_input(z.data(), model.latent_dim, q.albedo, q.normal, q.wo, x.data());
  for (int l = 0; l < layout.layer_count(); ++l) {
    const int n_in = layout.in_of(l), n_out = layout.out_of(l);
    std::vector<float> y(static_cast<std::size_t>(n_out));
    for (int o = 0; o < n_out; ++o) {
      double s = p[layout.bias_offset(l) + static_cast<std::size_t>(o)];
      for (int i = 0; i < n_in; ++i)
        s += static_cast<double>(p[layout.weight_offset(l) + static_cast<std::size_t>(o) * n_in + static_cast<std::size_t>(i)]) *
             x[static_cast<std::size_t>(i)];
      y[static_cast<std::size_t>(o)] = l < layout.hidden_layers ? std::max(0.0f, static_cast<float>(s)) : static_cast<float>(s);
    }
    x = std::move(y);
  }
  std::copy(x.begin(), x.end(), out75);
}

}  // namespace transgi::shading
