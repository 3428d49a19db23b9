#pragma once
// A decoder with every layer random at He scale, for kernel tests:
// Mlp::initialise keeps the output layer tiny, which would let a wrong
// kernel pass.
#include <cmath>
#include <cstdint>

#include "engine/math/rng.h"
#include "model/mlp.h"

inline transgi::model::Mlp random_mlp(transgi::model::MlpLayout layout, std::uint64_t seed) {
  transgi::model::Mlp mlp(layout);
  engine::math::Pcg32 rng(seed, 7);
  for (int l = 0; l < layout.layer_count(); ++l) {
    const float bound = std::sqrt(6.0f / static_cast<float>(layout.in_of(l)));
    float* w = mlp.params().data() + layout.weight_offset(l);
    for (int i = 0; i < layout.out_of(l) * layout.in_of(l); ++i) w[i] = bound * (2 * rng.next_float() - 1);
    float* b = mlp.params().data() + layout.bias_offset(l);
    for (int i = 0; i < layout.out_of(l); ++i) b[i] = 0.1f * (2 * rng.next_float() - 1);
  }
  return mlp;
}
