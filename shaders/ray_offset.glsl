// rt::offset_ray_origin (Waechter and Binder 2019): p pushed off its surface
// along the geometric normal n, by a few floats' steps away from the origin
// and by scale / 65536 near it.
vec3 offset_ray_origin(vec3 p, vec3 n, float scale) {
  const float origin = scale / 32.0, float_scale = scale / 65536.0, int_scale = 256.0;
  vec3 out_p;
  for (int i = 0; i < 3; ++i) {
    const int of_i = int(int_scale * n[i]);
    const float p_i = intBitsToFloat(floatBitsToInt(p[i]) + (p[i] < 0.0 ? -of_i : of_i));
    out_p[i] = abs(p[i]) < origin ? p[i] + float_scale * n[i] : p_i;
  }
  return out_p;
}
