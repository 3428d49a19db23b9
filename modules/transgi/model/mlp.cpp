#include "model/mlp.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "engine/math/rng.h"

namespace transgi::model {

std::size_t MlpLayout::weight_offset(int layer) const {
  std::size_t off = 0;
  for (int l = 0; l < layer; ++l) off += static_cast<std::size_t>(out_of(l)) * in_of(l) + out_of(l);
  return off;
}

std::size_t MlpLayout::parameter_count() const { return weight_offset(layer_count()); }

double MlpLayout::flops_per_sample() const {
  double f = 0;
  for (int l = 0; l < layer_count(); ++l) f += 2.0 * in_of(l) * out_of(l);
  return f;
}

Mlp::Mlp(MlpLayout layout) : layout_(layout), params_(layout.parameter_count(), 0.0f) {
  if (layout.inputs <= 0 || layout.width <= 0 || layout.hidden_layers < 0 || layout.outputs <= 0)
    throw std::invalid_argument("MLP layout must have positive sizes");
}

void Mlp::initialise(std::uint64_t seed) {
  engine::math::Pcg32 rng(seed, 0x4d4c50);
  for (int l = 0; l < layout_.layer_count(); ++l) {
    const int fan_in = layout_.in_of(l);
    const float bound = std::sqrt(6.0f / static_cast<float>(fan_in));  // He uniform for ReLU
    float* w = params_.data() + layout_.weight_offset(l);
    for (int i = 0; i < layout_.out_of(l) * fan_in; ++i) w[i] = bound * (2.0f * rng.next_float() - 1.0f);
    std::fill_n(params_.data() + layout_.bias_offset(l), layout_.out_of(l), 0.0f);
  }
  // A small output layer keeps the initial predictions near zero.
  const int last = layout_.hidden_layers;
  float* w = params_.data() + layout_.weight_offset(last);
  for (int i = 0; i < layout_.outputs * layout_.in_of(last); ++i) w[i] *= 0.1f;
}

void Mlp::forward(const float* x, int batch, float* y, MlpWorkspace& ws, GemmBackend backend) const {
  ws.activations.resize(static_cast<std::size_t>(layout_.layer_count()));
  const float* in = x;
  for (int l = 0; l < layout_.layer_count(); ++l) {
    const int n_in = layout_.in_of(l), n_out = layout_.out_of(l);
    const bool last = l == layout_.hidden_layers;
    std::vector<float>& act = ws.activations[static_cast<std::size_t>(l)];
    act.resize(static_cast<std::size_t>(batch) * n_out);
    float* out = last ? y : act.data();
    const float* b = params_.data() + layout_.bias_offset(l);
    for (int i = 0; i < batch; ++i) std::copy_n(b, n_out, out + static_cast<std::size_t>(i) * n_out);
    // out (batch x n_out) += in (batch x n_in) * W^T (n_in x n_out)
    gemm(backend, false, true, batch, n_out, n_in, 1.0f, in, n_in, params_.data() + layout_.weight_offset(l), n_in, 1.0f,
         out, n_out);
    if (!last) {
      for (float& v : act) v = std::max(v, 0.0f);
      in = act.data();
    } else {
      std::copy_n(out, static_cast<std::size_t>(batch) * n_out, act.data());
    }
  }
}

void Mlp::backward(const float* x, int batch, const float* dy, MlpWorkspace& ws, std::span<float> grad, float* dx,
                   GemmBackend backend) const {
  if (grad.size() != params_.size()) throw std::invalid_argument("gradient buffer has the wrong size");
  ws.grad_a.assign(dy, dy + static_cast<std::size_t>(batch) * layout_.outputs);
  for (int l = layout_.hidden_layers; l >= 0; --l) {
    const int n_in = layout_.in_of(l), n_out = layout_.out_of(l);
    std::vector<float>& g = ws.grad_a;  // dL/d(pre-activation) of layer l, batch x n_out
    if (l != layout_.hidden_layers) {
      const std::vector<float>& act = ws.activations[static_cast<std::size_t>(l)];
      for (std::size_t i = 0; i < g.size(); ++i)
        if (act[i] <= 0.0f) g[i] = 0.0f;  // ReLU gate
    }
    const float* in = l == 0 ? x : ws.activations[static_cast<std::size_t>(l - 1)].data();
    // dW (n_out x n_in) += g^T (n_out x batch) * in (batch x n_in)
    gemm(backend, true, false, n_out, n_in, batch, 1.0f, g.data(), n_out, in, n_in, 1.0f,
         grad.data() + layout_.weight_offset(l), n_in);
    float* db = grad.data() + layout_.bias_offset(l);
    for (int i = 0; i < batch; ++i)
      for (int j = 0; j < n_out; ++j) db[j] += g[static_cast<std::size_t>(i) * n_out + j];
    if (l == 0 && !dx) break;
    // d(in) (batch x n_in) = g (batch x n_out) * W (n_out x n_in)
    ws.grad_b.assign(static_cast<std::size_t>(batch) * n_in, 0.0f);
    gemm(backend, false, false, batch, n_in, n_out, 1.0f, g.data(), n_out, params_.data() + layout_.weight_offset(l), n_in,
         0.0f, ws.grad_b.data(), n_in);
    if (l == 0) {
      std::copy(ws.grad_b.begin(), ws.grad_b.end(), dx);
      break;
    }
    std::swap(ws.grad_a, ws.grad_b);
  }
}

}  // namespace transgi::model
