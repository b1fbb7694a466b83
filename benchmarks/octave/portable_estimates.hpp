// dcfkit's portable SSE estimates (dcfkit/components/features/sse_estimates.py) for the authors' gradientMex
// under Octave: benchmarks/authors_octave.sh includes this from sse.hpp in place of the
// processor's rcpps/rsqrtps, so that a run gives the same boxes on every machine. The rule:
// the reciprocal (square root) of the middle of the input's 2^-11 (2^-10) mantissa interval,
// rounded to nearest at 12 fraction bits.
#pragma once
#include <xmmintrin.h>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

namespace dcfkit_estimates {
inline uint32_t bits(float x) { uint32_t b; std::memcpy(&b, &x, 4); return b; }
inline float value(uint32_t b) { float x; std::memcpy(&x, &b, 4); return x; }

inline float rcp(float x) {
  const uint32_t b = bits(x), sign = b & 0x80000000u;
  const int exp = (b >> 23) & 0xFF;
  if (std::isnan(x)) return x;
  if (exp == 0) return std::copysign(std::numeric_limits<float>::infinity(), x);
  const int out_exp = 253 - exp;
  if (exp == 255 || out_exp <= 0) return value(sign);
  const double mid = 1.0 + (2.0 * ((b >> 12) & 0x7FF) + 1.0) / 4096.0;
  const uint32_t mant = (uint32_t)std::nearbyint((2.0 / mid - 1.0) * 4096.0) << 11;
  return value(sign | ((uint32_t)out_exp << 23) | mant);
}

inline float rsqrt(float x) {
  const uint32_t b = bits(x);
  const int exp = (b >> 23) & 0xFF;
  if (std::isnan(x) || (x < 0 && exp > 0)) return std::numeric_limits<float>::quiet_NaN();
  if (exp == 0) return std::copysign(std::numeric_limits<float>::infinity(), x);
  if (exp == 255) return 0.0f;
  const double mid = 1.0 + (2.0 * ((b >> 13) & 0x3FF) + 1.0) / 2048.0;
  const double root = (exp & 1) ? 2.0 / std::sqrt(mid) : 2.0 / std::sqrt(2.0 * mid);
  const uint32_t mant = (uint32_t)std::nearbyint((root - 1.0) * 4096.0) << 11;
  return value((uint32_t)(0x7E - ((exp - 0x7F) >> 1)) << 23 | mant);
}

template <float (*F)(float)> inline __m128 each(__m128 x) {
  alignas(16) float v[4];
  _mm_store_ps(v, x);
  for (float &e : v) e = F(e);
  return _mm_load_ps(v);
}
}  // namespace dcfkit_estimates
