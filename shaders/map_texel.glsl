// The texel of a probe's lat-long map that holds a direction: the GLSL twin
// of probes::MapLayout::texel_of, the same polynomial atan2 and acos
// (probes/radiance_map.h), so GPU and CPU pick the same texel.
float fast_atan2(float y, float x) {
  const float ax = abs(x), ay = abs(y);
  const float hi = max(ax, ay), lo = min(ax, ay);
  const float z = hi > 0.0 ? lo / hi : 0.0, z2 = z * z;
  float a = z * (0.99997726 + z2 * (-0.33262347 + z2 * (0.19354346 + z2 * (-0.11643287 + z2 * (0.05265332 + z2 * -0.01172120)))));
  a = ay > ax ? 1.57079633 - a : a;
  a = (floatBitsToUint(x) >> 31) != 0u ? 3.14159265 - a : a;
  return (floatBitsToUint(y) >> 31) != 0u ? -a : a;
}

float fast_acos(float x) {
  const float ax = min(abs(x), 1.0);
  const float q = 1.5707963050 + ax * (-0.2145988016 + ax * (0.0889789874 + ax * (-0.0501743046 + ax * (0.0308918810 +
                  ax * (-0.0170881256 + ax * (0.0066700901 + ax * -0.0012624911))))));
  const float r = sqrt(1.0 - ax) * q;
  return x < 0.0 ? 3.14159265 - r : r;
}

// Where a direction falls on the map, in texels (MapLayout::texel_position).
vec2 map_texel_position(vec3 d, uint width, uint height) {
  const float u = fast_atan2(d.x, -d.z) * 0.15915494, v = fast_acos(d.y) * 0.31830989;
  const float uw = u < 0.0 ? u + 1.0 : u;
  return vec2(uw * float(width), v * float(height));
}

int map_texel_of(vec3 d, uint width, uint height) {
  const vec2 at = map_texel_position(d, width, height);
  const int x = min(int(width) - 1, max(0, int(at.x)));
  const int y = min(int(height) - 1, max(0, int(at.y)));
  return y * int(width) + x;
}
