// The SIMD kernel of the volumetric obscurance (pipes_simd.cpp): vao_pixel of pipes.h on Lanes
// pixels of a row at once, with the sample sets and counts it reads, run by VAO (vao.cpp) and
// VAO++ (vao_pp.cpp, vao_pp_simd.cpp). The scalar vao_pixel stays the oracle it is tested
// against (docs/methods/vao.md, "SIMD kernel").
#pragma once

#include <cstdint>
#include <vector>

#include "core/volumetric/pipes.h"

namespace aolab {

/// The disc sample sets a run draws from, concatenated: the set of n samples starts at
/// offset[n]. Each pixel turns its set: with `tiled` by VAO++'s tile angle k = (x mod 3) +
/// 3 (y mod 3) (§4.5; cos and sin in rotation_cos/sin[k], as `rotated` makes the nine sets),
/// with `random_rotation` by 2π·pixel_random(seed, x, y, 0) (vao_random_rotation).
struct VaoSimdSets {
  std::vector<float> x, y, h;
  std::vector<int> offset = std::vector<int>(kVaoMaxSamples + 1, 0);
  bool tiled = false;
  float rotation_cos[9] = {}, rotation_sin[9] = {};
  bool random_rotation = false;
  std::uint32_t seed = 0;
  /// Appends a base set and sets offset[k.size()].
  void add(const VaoKernel& k);
};

/// How many samples each pixel gets: `samples`, or with `adaptive` VAO++'s §4.1 count
/// (vao_pp_adaptive_samples of the disc's projected diameter, at most `samples`), cut where
/// `culled` (a row of 0/1 per pixel, or null) is 1: to 0 (`greedy`) or to at most `careful`.
struct VaoSimdCounts {
  int samples = kVaoDefaultSamples;
  bool adaptive = false;
  float adaptive_min_diameter = 0.0f;
  const float* culled = nullptr;
  bool greedy = false;
  int careful = 0;
};

/// What a span did (VaoPpStats' counts).
struct VaoSimdStats {
  std::int64_t pixels = 0, culled = 0, samples = 0;
};

/// Outputs k in [k_begin, k_end) of row `y`: the pixel at column min(k·stride + offset, w − 1)
/// of row y, written to out[k·channels + c] for c = 0 (A) and, with o.bleeding_step, 1..3 (B,
/// the mean of the bleeding terms, where the pixel gathered any). Background pixels, those
/// with 0 samples and those whose disc is not in front of the camera keep what out held
/// (1), as in the scalar loops. k_begin must be a multiple of the vector length (0 will do).
void vao_simd_span(const VaoFrame& f, const VaoPixelOptions& o, const VaoSimdSets& sets,
                   const VaoSimdCounts& counts, int y, int k_begin, int k_end, int stride,
                   int offset, float* out, int channels, VaoSimdStats* stats);

}  // namespace aolab
