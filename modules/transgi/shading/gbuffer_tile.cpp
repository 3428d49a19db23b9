#include "shading/gbuffer.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "engine/core/cpu_isa.h"
#include "engine/render/surface.h"

// make_gsamples: a camera tile's G-buffer samples at once. make_gsample is a
// long chain of dependent divisions and square roots per pixel (normalise,
// rotate, normalise again), which a core runs one pixel at a time; here the
// tile's loads come first, then that arithmetic as structure-of-arrays loops
// over the lanes, which the compiler turns into 8- or 16-wide vectors, then
// the material reads (set_gsample_material, shared with make_gsample) and the
// stores. This file is built without FMA contraction (CMakeLists.txt), and
// the loops state glm's arithmetic in glm's order (normalize = v * (1 /
// sqrt(dot)), dot = (x x + y y) + z z, q * v = v + ((cross(q, v) w) +
// cross(q, cross(q, v))) 2), so every lane rounds as make_gsample does: the
// samples are bit-identical (tested).

namespace transgi::shading {

namespace {

constexpr int kLanes = kGSampleTile;

// The tile's inputs and the arithmetic's results, one array a component.
struct TileGeometry {
  float b1[kLanes], b2[kLanes], t[kLanes];
  float n[3][3][kLanes];  // vertex normal k, component c
  float p[3][3][kLanes];  // vertex position k, component c
  float origin[3][kLanes], dir[3][kLanes];
  float qw[kLanes], qx[kLanes], qy[kLanes], qz[kLanes];  // the instance's rotation
  float nobj[3][kLanes], wo[3][kLanes], wo_world[3][kLanes], nworld[3][kLanes], ng[3][kLanes], position[3][kLanes];
  float ng_dot_wo[kLanes];
};

// v rotated by the quaternion (w, x, y, z), as glm's q * v.
ENGINE_INLINE_BODY void rotate(float w, float x, float y, float z, float vx, float vy, float vz, float& ox, float& oy, float& oz) {
  const float ux = y * vz - vy * z, uy = z * vx - vz * x, uz = x * vy - vx * y;      // cross(q, v)
  const float uux = y * uz - uy * z, uuy = z * ux - uz * x, uuz = x * uy - ux * y;  // cross(q, u)
  ox = vx + ((ux * w) + uux) * 2.0f;
  oy = vy + ((uy * w) + uuy) * 2.0f;
  oz = vz + ((uz * w) + uuz) * 2.0f;
}

ENGINE_INLINE_BODY void tile_geometry_body(TileGeometry& g) {
  for (int i = 0; i < kLanes; ++i) {
    const float b1 = g.b1[i], b2 = g.b2[i], b0 = 1 - b1 - b2;
    // The object-space shading normal, normalised.
    float nx = b0 * g.n[0][0][i] + b1 * g.n[1][0][i] + b2 * g.n[2][0][i];
    float ny = b0 * g.n[0][1][i] + b1 * g.n[1][1][i] + b2 * g.n[2][1][i];
    float nz = b0 * g.n[0][2][i] + b1 * g.n[1][2][i] + b2 * g.n[2][2][i];
    const float n_inv = 1.0f / std::sqrt(nx * nx + ny * ny + nz * nz);
    nx *= n_inv;
    ny *= n_inv;
    nz *= n_inv;
    // The direction back to the camera, in the world and the object.
    const float dx = -g.dir[0][i], dy = -g.dir[1][i], dz = -g.dir[2][i];
    const float d_inv = 1.0f / std::sqrt(dx * dx + dy * dy + dz * dz);
    const float wx = dx * d_inv, wy = dy * d_inv, wz = dz * d_inv;
    float ox, oy, oz;
    rotate(g.qw[i], -g.qx[i], -g.qy[i], -g.qz[i], wx, wy, wz, ox, oy, oz);
    // Seen from the back of a two-sided surface: the normal turns.
    const bool back = nx * ox + ny * oy + nz * oz < 0;
    nx = back ? -nx : nx;
    ny = back ? -ny : ny;
    nz = back ? -nz : nz;
    float wnx, wny, wnz;
    rotate(g.qw[i], g.qx[i], g.qy[i], g.qz[i], nx, ny, nz, wnx, wny, wnz);
    // The geometric normal, in the world; the shading normal where the
    // triangle has no area.
    const float e1x = g.p[1][0][i] - g.p[0][0][i], e1y = g.p[1][1][i] - g.p[0][1][i], e1z = g.p[1][2][i] - g.p[0][2][i];
    const float e2x = g.p[2][0][i] - g.p[0][0][i], e2y = g.p[2][1][i] - g.p[0][1][i], e2z = g.p[2][2][i] - g.p[0][2][i];
    const float cx = e1y * e2z - e2y * e1z, cy = e1z * e2x - e2z * e1x, cz = e1x * e2y - e2x * e1y;
    const float length = std::sqrt(cx * cx + cy * cy + cz * cz);
    const float divisor = length > 0 ? length : 1.0f;
    float gx, gy, gz;
    rotate(g.qw[i], g.qx[i], g.qy[i], g.qz[i], cx / divisor, cy / divisor, cz / divisor, gx, gy, gz);
    gx = length > 0 ? gx : wnx;
    gy = length > 0 ? gy : wny;
    gz = length > 0 ? gz : wnz;
    g.nobj[0][i] = nx;
    g.nobj[1][i] = ny;
    g.nobj[2][i] = nz;
    g.wo[0][i] = ox;
    g.wo[1][i] = oy;
    g.wo[2][i] = oz;
    g.wo_world[0][i] = wx;
    g.wo_world[1][i] = wy;
    g.wo_world[2][i] = wz;
    g.nworld[0][i] = wnx;
    g.nworld[1][i] = wny;
    g.nworld[2][i] = wnz;
    g.ng[0][i] = gx;
    g.ng[1][i] = gy;
    g.ng[2][i] = gz;
    g.ng_dot_wo[i] = gx * wx + gy * wy + gz * wz;
    g.position[0][i] = g.origin[0][i] + g.t[i] * g.dir[0][i];
    g.position[1][i] = g.origin[1][i] + g.t[i] * g.dir[1][i];
    g.position[2][i] = g.origin[2][i] + g.t[i] * g.dir[2][i];
  }
}
ENGINE_ISA_DISPATCH(void, tile_geometry, (TileGeometry & g), (g))

}  // namespace

void make_gsamples(const engine::rt::RtScene& scene, const engine::scene::SceneAssets& assets, const engine::rt::Ray* rays,
                   const engine::rt::Hit* hits, const bool* found, int n, float spread, GSample* const* out,
                   const GSampleSideArrays* sides) {
  using namespace engine;
  TileGeometry g;
  // Each lane's instance and mesh, found once for the loads and the stores.
  const rt::InstanceRecord* instance[kLanes];
  const scene::MeshAsset* meshes[kLanes];
  // The loads. A missed lane computes on zeros, and its result is dropped.
  for (int i = 0; i < kLanes; ++i) {
    const bool lane = i < n && found[i];
    const rt::Hit* hit = lane ? &hits[i] : nullptr;
    const scene::MeshAsset* mesh = meshes[i] = lane ? assets.meshes[hit->mesh].get() : nullptr;
    instance[i] = lane ? scene.instance_of(*hit) : nullptr;
    const glm::uvec3 tri = lane ? mesh->triangles[hit->primitive] : glm::uvec3(0);
    const glm::quat q = lane ? instance[i]->to_world.rotation : glm::quat(1.0f, 0.0f, 0.0f, 0.0f);
    g.b1[i] = lane ? hit->barycentric.x : 0.0f;
    g.b2[i] = lane ? hit->barycentric.y : 0.0f;
    g.t[i] = lane ? hit->t : 0.0f;
    for (int k = 0; k < 3; ++k) {
      const glm::vec3 nk = lane ? mesh->normals[tri[k]] : glm::vec3(0.0f, 0.0f, 1.0f);
      const glm::vec3 pk = lane ? mesh->positions[tri[k]] : glm::vec3(0.0f);
      for (int c = 0; c < 3; ++c) {
        g.n[k][c][i] = nk[c];
        g.p[k][c][i] = pk[c];
      }
    }
    const glm::vec3 o = i < n ? rays[i].origin : glm::vec3(0.0f), d = i < n ? rays[i].direction : glm::vec3(0.0f, 0.0f, -1.0f);
    for (int c = 0; c < 3; ++c) {
      g.origin[c][i] = o[c];
      g.dir[c][i] = d[c];
    }
    g.qw[i] = q.w;
    g.qx[i] = q.x;
    g.qy[i] = q.y;
    g.qz[i] = q.z;
  }
  tile_geometry(g);
  // The materials and the stores.
  for (int i = 0; i < n; ++i) {
    GSample& s = *out[i];
    if (!found[i]) {
      s = GSample{};
      if (sides) {
        const std::size_t p = sides->pixel[i];
        sides->guide[p] = glm::vec4(0.0f);
        sides->position[p] = glm::vec3(0.0f);
        sides->albedo[p] = glm::vec3(0.0f);
        sides->metal_roughness[p] = std::numeric_limits<float>::infinity();
        sides->dielectric_roughness[p] = std::numeric_limits<float>::infinity();
        sides->entity[p] = engine::ecs::Entity{};
      }
      continue;
    }
    const rt::Hit& hit = hits[i];
    const float ng_dot_wo = g.ng_dot_wo[i];
    set_gsample_material(assets, hit, *meshes[i], instance[i]->to_world.scale, spread, ng_dot_wo, s);
    s.normal_obj = {g.nobj[0][i], g.nobj[1][i], g.nobj[2][i]};
    s.wo_obj = {g.wo[0][i], g.wo[1][i], g.wo[2][i]};
    s.position = {g.position[0][i], g.position[1][i], g.position[2][i]};
    s.normal_world = {g.nworld[0][i], g.nworld[1][i], g.nworld[2][i]};
    s.wo_world = {g.wo_world[0][i], g.wo_world[1][i], g.wo_world[2][i]};
    const glm::vec3 ng(g.ng[0][i], g.ng[1][i], g.ng[2][i]);
    s.geometric_normal = ng_dot_wo < 0 ? -ng : ng;
    if (sides) {
      const std::size_t p = sides->pixel[i];
      const material::BrdfParams& brdf = s.brdf;
      sides->guide[p] = glm::vec4(g.nworld[0][i], g.nworld[1][i], g.nworld[2][i], std::max(hit.t, 1e-30f));
      sides->position[p] = glm::vec3(g.position[0][i], g.position[1][i], g.position[2][i]);
      sides->albedo[p] = brdf.base_color;
      sides->metal_roughness[p] = brdf.metallic >= 0.5f ? brdf.roughness : std::numeric_limits<float>::infinity();
      sides->dielectric_roughness[p] = brdf.metallic < 0.5f && brdf.specular > 0 ? brdf.roughness : std::numeric_limits<float>::infinity();
      sides->entity[p] = hit.entity;
    }
  }
}

}  // namespace transgi::shading
