#pragma once
// Directional albedo of the GGX specular lobe with Schlick Fresnel, used to
// couple the diffuse and specular layers without gaining or losing energy.
//
// Schlick is linear in F0, so E(mu, alpha, F0) = F0 A(mu, alpha) + B(mu, alpha)
// with A = integral (1 - (1 - wo.h)^5) D V cos_i and B = integral (1 - wo.h)^5 D V cos_i.
// A and B are tabulated once (deterministically) on first use, as are their
// cosine-weighted hemispherical averages.
namespace engine::material {

struct SpecularAlbedo {
  float a = 0, b = 0;
  [[nodiscard]] float with_f0(float f0) const { return f0 * a + b; }
};

// Directional albedo terms at cos_o = mu.
SpecularAlbedo ggx_albedo(float mu, float alpha);
// Cosine-weighted average over the hemisphere: 2 * integral E(mu) mu dmu.
SpecularAlbedo ggx_average_albedo(float alpha);

// The tables the two functions above interpolate, for kernels that read
// them: directional[j * 64 + i] at sqrt(mu) = i / 63 and sqrt(alpha) at node
// j of 64 from sqrt(kMinAlpha) to 1; average[j] likewise.
inline constexpr int kAlbedoTableMu = 64;
inline constexpr int kAlbedoTableAlpha = 64;
const SpecularAlbedo* ggx_albedo_directional_table();  // kAlbedoTableMu x kAlbedoTableAlpha
const SpecularAlbedo* ggx_albedo_average_table();      // kAlbedoTableAlpha

}  // namespace engine::material
