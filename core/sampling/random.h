// Counter-based random numbers: a value is a pure function of (seed, pixel, stream), so the
// bits never depend on which thread computed a pixel or in which order.
#pragma once

#include <cstdint>

namespace aolab {

/// PCG output permutation (O'Neill 2014) used as an integer hash; passes the usual
/// avalanche tests and costs a few multiplies.
inline std::uint32_t pcg_hash(std::uint32_t v) {
  const std::uint32_t state = v * 747796405u + 2891336453u;
  const std::uint32_t word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
  return (word >> 22u) ^ word;
}

/// The per-pixel part of pixel_random's hash chain, for callers that draw many streams at one
/// pixel: pixel_random(seed, x, y, s) == pixel_stream_random(pixel_hash(seed, x, y), s).
inline std::uint32_t pixel_hash(std::uint32_t seed, int x, int y) {
  std::uint32_t h = pcg_hash(seed ^ 0x9E3779B9u);
  h = pcg_hash(h ^ std::uint32_t(x));
  return pcg_hash(h ^ std::uint32_t(y) * 0x85EBCA6Bu);
}

/// Stream `stream` of the pixel whose pixel_hash is `pixel`: a uniform float in [0, 1).
inline float pixel_stream_random(std::uint32_t pixel, std::uint32_t stream) {
  const std::uint32_t h = pcg_hash(pixel + stream * 0xC2B2AE35u);
  return float(h >> 8) * (1.0f / 16777216.0f);  // 24 bits: exact in float, < 1
}

/// A uniform float in [0, 1) for pixel (x, y), stream `stream` (one per random quantity).
inline float pixel_random(std::uint32_t seed, int x, int y, std::uint32_t stream) {
  return pixel_stream_random(pixel_hash(seed, x, y), stream);
}

}  // namespace aolab
