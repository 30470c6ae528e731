// Blue noise by the void-and-cluster method (R. Ulichney, "The void-and-cluster method for
// dither array generation", Proc. SPIE 1913, 1993): a square, toroidal array holding every
// rank 0 … size²−1 once, arranged so that every threshold of it is an evenly spread point set
// — little energy at low spatial frequencies. Pyramid HBAO rotates its directions per pixel
// by a value of a 32×32 blue-noise texture (Astapov et al. 2021, §3.5).
//
// The array is generated here, deterministically (no stored data, no global mutable state):
// the same bits on every machine for a given size, sigma and seed.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

namespace aolab {

/// Side of the texture Pyramid HBAO tiles over the image (§3.5: "32x32 pixels").
constexpr int kBlueNoiseSize = 32;

/// σ of the Gaussian energy filter, pixels. Ulichney finds 1.5 the best compromise: smaller
/// values leave visible clusters, larger ones low-frequency structure.
constexpr double kBlueNoiseSigma = 1.5;

/// Share of minority pixels in the initial binary pattern. Ulichney starts from a sparse
/// random pattern (at most half the pixels; he uses about 10 %) so that the first
/// cluster-to-void swaps converge quickly to a homogeneous pattern.
constexpr double kBlueNoiseInitialDensity = 0.1;

/// Seed of the initial random pattern of the cached texture.
constexpr std::uint32_t kBlueNoiseSeed = 1993;

/// Void-and-cluster ranks of a size×size toroidal array, row-major: a permutation of
/// 0 … size²−1. Throws std::invalid_argument unless size is in [2, 256] and sigma in
/// (0, size]. Cost O(size⁴): ~10⁷ operations for 32×32.
std::vector<std::uint32_t> void_and_cluster(int size, double sigma, std::uint32_t seed);

/// The 32×32 texture of Pyramid HBAO: void_and_cluster(kBlueNoiseSize, kBlueNoiseSigma,
/// kBlueNoiseSeed), computed on first use and cached (a function-local static, so the first
/// use from several threads at once is safe and computes it once).
const std::array<std::uint16_t, kBlueNoiseSize * kBlueNoiseSize>& blue_noise_ranks();

/// The texture's value at pixel (x, y), tiled over the plane (any x, y, negative included):
/// (rank + 0.5) / 1024, in (0, 1).
inline float blue_noise_value(
    const std::array<std::uint16_t, kBlueNoiseSize * kBlueNoiseSize>& ranks, int x, int y) {
  const int tx = ((x % kBlueNoiseSize) + kBlueNoiseSize) % kBlueNoiseSize;
  const int ty = ((y % kBlueNoiseSize) + kBlueNoiseSize) % kBlueNoiseSize;
  return (float(ranks[std::size_t(ty) * kBlueNoiseSize + tx]) + 0.5f) *
         (1.0f / float(kBlueNoiseSize * kBlueNoiseSize));
}

}  // namespace aolab
