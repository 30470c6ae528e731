#include "core/sampling/blue_noise.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/base/check.h"
#include "core/sampling/random.h"

namespace aolab {

namespace {

// The binary pattern of void-and-cluster and its energy: energy[p] = Σ over minority
// pixels q of the toroidal Gaussian f(p − q) (Ulichney's "cluster/void finding filter").
// Energies are kept up to date incrementally as pixels are set and cleared; every update and
// every search visits pixels in the same order, so the result is deterministic.
class Pattern {
 public:
  Pattern(int size, double sigma)
      : size_(size),
        ones_(std::size_t(size) * size, 0),
        energy_(std::size_t(size) * size, 0.0),
        kernel_(std::size_t(size) * size) {
    // Kernel over toroidal offsets: the shortest wrapped distance along each axis.
    for (int dy = 0; dy < size; ++dy)
      for (int dx = 0; dx < size; ++dx) {
        const int wx = std::min(dx, size - dx), wy = std::min(dy, size - dy);
        kernel_[std::size_t(dy) * size + dx] =
            std::exp(-double(wx * wx + wy * wy) / (2.0 * sigma * sigma));
      }
  }

  int pixels() const { return size_ * size_; }
  bool one(int p) const { return ones_[p] != 0; }

  void set(int p, bool value) {
    if (one(p) == value) return;
    ones_[p] = value ? 1 : 0;
    const double sign = value ? 1.0 : -1.0;
    const int px = p % size_, py = p / size_;
    for (int y = 0; y < size_; ++y) {
      const int dy = (y - py + size_) % size_;
      for (int x = 0; x < size_; ++x) {
        const int dx = (x - px + size_) % size_;
        energy_[std::size_t(y) * size_ + x] += sign * kernel_[std::size_t(dy) * size_ + dx];
      }
    }
  }

  // The minority pixel with the highest energy (the tightest cluster); ties go to the first.
  int tightest_cluster() const {
    int best = -1;
    for (int p = 0; p < pixels(); ++p)
      if (one(p) && (best < 0 || energy_[p] > energy_[best])) best = p;
    return best;
  }

  // The majority pixel with the lowest energy (the largest void); ties go to the first.
  int largest_void() const {
    int best = -1;
    for (int p = 0; p < pixels(); ++p)
      if (!one(p) && (best < 0 || energy_[p] < energy_[best])) best = p;
    return best;
  }

 private:
  int size_;
  std::vector<unsigned char> ones_;
  std::vector<double> energy_;
  std::vector<double> kernel_;
};

}  // namespace

std::vector<std::uint32_t> void_and_cluster(int size, double sigma, std::uint32_t seed) {
  if (size < 2 || size > 256) throw_invalid("size", "must be in [2, 256]", size);
  if (!(sigma > 0.0 && sigma <= double(size)))
    throw_invalid("sigma", "must be in (0, " + std::to_string(size) + "] px", sigma);
  const int n = size * size;

  // Initial binary pattern (Ulichney §3): a sparse random pattern, then repeatedly move the
  // pixel of the tightest cluster to the largest void until the two coincide, which leaves
  // the minority pixels homogeneously spread.
  Pattern initial(size, sigma);
  const int minority = std::max(1, int(std::lround(kBlueNoiseInitialDensity * n)));
  int placed = 0;
  for (std::uint32_t i = 0; placed < minority; ++i) {
    const int p = int(pcg_hash(pcg_hash(seed) ^ i) % std::uint32_t(n));
    if (!initial.one(p)) initial.set(p, true), ++placed;
  }
  // Ulichney finds this converges after a few swaps per minority pixel; the bound only
  // guards against a cycle between patterns of equal energy.
  for (int swaps = 0; swaps < 16 * n; ++swaps) {
    const int cluster = initial.tightest_cluster();
    initial.set(cluster, false);
    const int hole = initial.largest_void();
    initial.set(hole, true);
    if (hole == cluster) break;
  }

  std::vector<std::uint32_t> rank(n, 0);
  // Phase 1: ranks minority−1 … 0, removing the tightest cluster each time.
  Pattern shrinking = initial;
  for (int r = minority - 1; r >= 0; --r) {
    const int p = shrinking.tightest_cluster();
    shrinking.set(p, false);
    rank[p] = std::uint32_t(r);
  }
  // Phases 2 and 3: ranks minority … n−1, filling the largest void each time. Ulichney's
  // phase 3 (past half full) fills "the tightest cluster of 0s" instead; the energy of the 0s
  // at a 0 pixel is Σ_all f − (energy of the 1s), so that is the same pixel.
  Pattern growing = initial;
  for (int r = minority; r < n; ++r) {
    const int p = growing.largest_void();
    growing.set(p, true);
    rank[p] = std::uint32_t(r);
  }
  return rank;
}

const std::array<std::uint16_t, kBlueNoiseSize * kBlueNoiseSize>& blue_noise_ranks() {
  static const auto texture = [] {
    std::array<std::uint16_t, kBlueNoiseSize * kBlueNoiseSize> out{};
    const auto ranks = void_and_cluster(kBlueNoiseSize, kBlueNoiseSigma, kBlueNoiseSeed);
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = std::uint16_t(ranks[i]);
    return out;
  }();
  return texture;
}

}  // namespace aolab
