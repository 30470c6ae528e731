// Per-frame seeds: every method's per-pixel random numbers vary from frame to frame without
// code of its own, for temporal accumulation (core/filters/temporal.h, docs/temporal.md).
#pragma once

#include <cstdint>

#include "core/sampling/random.h"

namespace aolab {

/// The largest seed a method's `seed` setting takes, 2^31 − 1.
constexpr std::uint32_t kMaxSeed = 0x7FFFFFFFu;

/// The seed of frame `frame` of a sequence run at `seed` (both in [0, kMaxSeed]). Frame 0
/// keeps `seed`, so a single frame is the method as it is; every later frame is a hash of
/// both in [1, kMaxSeed]: the range of every `seed` setting, never 0 (VAO++'s seed 0 means
/// "no rotation"). Like any two seeds, two frames draw independent per-pixel patterns, so
/// the mean of N frames has 1/N of one frame's variance.
inline std::uint32_t frame_seed(std::uint32_t seed, std::uint32_t frame) {
  if (frame == 0) return seed;
  const std::uint32_t h = pcg_hash(pcg_hash(seed ^ 0x68E31DA4u) + frame * 0x9E3779B9u);
  return h % kMaxSeed + 1u;
}

}  // namespace aolab
