#pragma once
// The neural transfer decoder: a fully connected MLP with ReLU hidden layers
// and a linear output (paper Section 4.1: 16 -> 3 x 128 -> 75 by default).
// Parameters live in one flat vector (per layer: weights, out x in
// row-major, then biases), so optimisers and the model file see one array.
#include <cstdint>
#include <span>
#include <vector>

#include "model/gemm.h"

namespace transgi::model {

struct MlpLayout {
  int inputs = 16;
  int width = 128;         // higher = more capacity, at the cost of time and memory per pixel
  int hidden_layers = 3;   // higher = more capacity, at the cost of time per pixel
  int outputs = 75;

  [[nodiscard]] int layer_count() const { return hidden_layers + 1; }
  [[nodiscard]] int in_of(int layer) const { return layer == 0 ? inputs : width; }
  [[nodiscard]] int out_of(int layer) const { return layer == hidden_layers ? outputs : width; }
  [[nodiscard]] std::size_t parameter_count() const;
  [[nodiscard]] std::size_t weight_offset(int layer) const;
  [[nodiscard]] std::size_t bias_offset(int layer) const { return weight_offset(layer) + static_cast<std::size_t>(out_of(layer)) * in_of(layer); }
  [[nodiscard]] double flops_per_sample() const;  // forward multiply-adds x 2
  friend bool operator==(const MlpLayout&, const MlpLayout&) = default;
};

// Activations kept by forward() for backward().
struct MlpWorkspace {
  std::vector<std::vector<float>> activations;  // per layer output (post-ReLU for hidden)
  std::vector<float> grad_a, grad_b;
};

class Mlp {
 public:
  Mlp() = default;
  explicit Mlp(MlpLayout layout);

  // He-uniform initialisation from a seed (deterministic).
  void initialise(std::uint64_t seed);

  // y (batch x outputs) = MLP(x (batch x inputs)).
  void forward(const float* x, int batch, float* y, MlpWorkspace& ws, GemmBackend backend) const;
  // Given dL/dy, accumulates dL/dparams into grad (same layout as params) and
  // writes dL/dx (batch x inputs) if dx is non-null. Needs forward()'s ws.
  void backward(const float* x, int batch, const float* dy, MlpWorkspace& ws, std::span<float> grad, float* dx,
                GemmBackend backend) const;

  [[nodiscard]] const MlpLayout& layout() const { return layout_; }
  [[nodiscard]] std::vector<float>& params() { return params_; }
  [[nodiscard]] const std::vector<float>& params() const { return params_; }

 private:
  MlpLayout layout_;
  std::vector<float> params_;
};

}  // namespace transgi::model
