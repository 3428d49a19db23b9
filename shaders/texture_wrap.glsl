// scene::wrap_index: texel i of a row of n under a glTF wrap mode (0 repeat,
// 1 clamp to edge, 2 mirrored repeat). Guarded: the ray traversal and the
// surface shading both include it.
#ifndef TEXTURE_WRAP_GLSL
#define TEXTURE_WRAP_GLSL
int texture_wrap(int i, int n, uint mode) {
  if (mode == 1u) return clamp(i, 0, n - 1);
  if (mode == 2u) {
    const int period = 2 * n;
    int m = i % period;
    if (m < 0) m += period;
    return m < n ? m : period - 1 - m;
  }
  int m = i % n;
  return m < 0 ? m + n : m;
}
#endif
