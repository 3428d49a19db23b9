// engine::math::to_half (Giesen's float_to_half_fast3_rtne), bit for bit:
// round to nearest even, the same bits as the CPU stores, whatever rounding
// the device's packHalf2x16 has. Half to float (unpackHalf2x16) is exact.
uint to_half_bits(float f) {
  uint x = floatBitsToUint(f);
  const uint sign = x & 0x80000000u;
  x ^= sign;
  uint o;
  if (x >= 0x47800000u) {
    o = x > 0x7f800000u ? 0x7e00u : 0x7c00u;
  } else if (x < 0x38800000u) {
    const float t = uintBitsToFloat(x) + 0.5;
    o = floatBitsToUint(t) - 0x3f000000u;
  } else {
    const uint mantissa_odd = (x >> 13) & 1u;
    x += 0xc8000fffu;
    x += mantissa_odd;
    o = x >> 13;
  }
  return (o | (sign >> 16)) & 0xffffu;
}
float from_half_bits(uint h) { return unpackHalf2x16(h & 0xffffu).x; }
