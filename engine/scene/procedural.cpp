#include "engine/scene/procedural.h"

#include <cmath>

#include "engine/math/sampling.h"

namespace engine::scene {

MeshAsset make_uv_sphere(float radius, int segments, int rings, std::uint32_t material) {
  MeshAsset m;
  m.name = "sphere";
  for (int r = 0; r <= rings; ++r) {
    const float v = static_cast<float>(r) / static_cast<float>(rings);
    const float theta = math::kPi * v;
    for (int s = 0; s <= segments; ++s) {
      const float u = static_cast<float>(s) / static_cast<float>(segments);
      const float phi = math::kTwoPi * u;
      const glm::vec3 n(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
      m.positions.push_back(radius * n);
      m.normals.push_back(n);
      m.uvs.emplace_back(u, v);
    }
  }
  const int row = segments + 1;
  for (int r = 0; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      const auto a = static_cast<std::uint32_t>(r * row + s), b = a + 1, c = a + static_cast<std::uint32_t>(row), d = c + 1;
      // Counter-clockwise seen from outside.
      if (r != 0) m.triangles.emplace_back(a, b, c);
      if (r != rings - 1) m.triangles.emplace_back(b, d, c);
    }
  m.triangle_material.assign(m.triangles.size(), material);
  m.compute_bounds();
  return m;
}

MeshAsset make_box(glm::vec3 h, bool inward, std::uint32_t material) {
  MeshAsset m;
  m.name = inward ? "room" : "box";
  const glm::vec3 axes[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (int a = 0; a < 3; ++a)
    for (float sign : {1.0f, -1.0f}) {
      const glm::vec3 n = sign * axes[a];
      const glm::vec3 t = axes[(a + 1) % 3] * sign, b = glm::cross(n, t);
      const glm::vec3 c = n * h[a];
      const glm::vec3 ht = t * glm::dot(glm::abs(t), h), hb = b * glm::dot(glm::abs(b), h);
      const auto base = static_cast<std::uint32_t>(m.positions.size());
      for (glm::vec2 q : {glm::vec2(-1, -1), glm::vec2(1, -1), glm::vec2(1, 1), glm::vec2(-1, 1)}) {
        m.positions.push_back(c + q.x * ht + q.y * hb);
        m.normals.push_back(inward ? -n : n);
        m.uvs.emplace_back(0.5f * (q.x + 1), 0.5f * (q.y + 1));
      }
      if (inward) {
        m.triangles.emplace_back(base, base + 2, base + 1);
        m.triangles.emplace_back(base, base + 3, base + 2);
      } else {
        m.triangles.emplace_back(base, base + 1, base + 2);
        m.triangles.emplace_back(base, base + 2, base + 3);
      }
    }
  m.triangle_material.assign(m.triangles.size(), material);
  m.compute_bounds();
  return m;
}

MeshAsset make_quad(glm::vec2 h, std::uint32_t material) {
  MeshAsset m;
  m.name = "quad";
  m.positions = {{-h.x, 0, -h.y}, {-h.x, 0, h.y}, {h.x, 0, h.y}, {h.x, 0, -h.y}};
  m.normals.assign(4, {0, 1, 0});
  m.uvs = {{0, 0}, {0, 1}, {1, 1}, {1, 0}};
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  m.triangle_material.assign(2, material);
  m.compute_bounds();
  return m;
}

}  // namespace engine::scene

namespace engine::scene {

MeshAsset make_torus(float major, float minor, int segments, int sides, std::uint32_t material) {
  MeshAsset m;
  m.name = "torus";
  for (int i = 0; i <= segments; ++i) {
    const float u = static_cast<float>(i) / static_cast<float>(segments), phi = math::kTwoPi * u;
    const glm::vec3 ring(std::cos(phi), 0, std::sin(phi));
    for (int j = 0; j <= sides; ++j) {
      const float v = static_cast<float>(j) / static_cast<float>(sides), theta = math::kTwoPi * v;
      const glm::vec3 n = std::cos(theta) * ring + std::sin(theta) * glm::vec3(0, 1, 0);
      m.positions.push_back(major * ring + minor * n);
      m.normals.push_back(n);
      m.uvs.emplace_back(u, v);
    }
  }
  const int row = sides + 1;
  for (int i = 0; i < segments; ++i)
    for (int j = 0; j < sides; ++j) {
      const auto a = static_cast<std::uint32_t>(i * row + j), b = a + static_cast<std::uint32_t>(row), c = a + 1, d = b + 1;
      m.triangles.emplace_back(a, c, b);
      m.triangles.emplace_back(c, d, b);
    }
  m.triangle_material.assign(m.triangles.size(), material);
  m.compute_bounds();
  return m;
}

MeshAsset make_tube(float radius, float height, int segments, float taper, std::uint32_t material) {
  MeshAsset m;
  m.name = "tube";
  const float slope = radius * (1.0f - taper) / height;  // radial shrink per unit height
  for (int i = 0; i <= segments; ++i) {
    const float u = static_cast<float>(i) / static_cast<float>(segments), phi = math::kTwoPi * u;
    const glm::vec3 dir(std::cos(phi), 0, std::sin(phi));
    const glm::vec3 n = glm::normalize(dir + glm::vec3(0, slope, 0));
    m.positions.push_back(radius * dir);
    m.positions.push_back(radius * taper * dir + glm::vec3(0, height, 0));
    m.normals.push_back(n);
    m.normals.push_back(n);
    m.uvs.emplace_back(u, 0);
    m.uvs.emplace_back(u, 1);
  }
  for (int i = 0; i < segments; ++i) {
    const auto a = static_cast<std::uint32_t>(2 * i), b = a + 1, c = a + 2, d = a + 3;
    m.triangles.emplace_back(a, b, c);
    m.triangles.emplace_back(b, d, c);
  }
  m.triangle_material.assign(m.triangles.size(), material);
  m.compute_bounds();
  return m;
}

void append_mesh(MeshAsset& a, const MeshAsset& b) {
  const auto base = static_cast<std::uint32_t>(a.positions.size());
  a.positions.insert(a.positions.end(), b.positions.begin(), b.positions.end());
  a.normals.insert(a.normals.end(), b.normals.begin(), b.normals.end());
  if (!a.uvs.empty() || !b.uvs.empty()) {
    a.uvs.resize(base, glm::vec2(0.0f));
    if (b.uvs.empty()) a.uvs.resize(a.positions.size(), glm::vec2(0.0f));
    else a.uvs.insert(a.uvs.end(), b.uvs.begin(), b.uvs.end());
  }
  for (const glm::uvec3& t : b.triangles) a.triangles.push_back(t + glm::uvec3(base));
  a.triangle_material.insert(a.triangle_material.end(), b.triangle_material.begin(), b.triangle_material.end());
  a.compute_bounds();
}

}  // namespace engine::scene
