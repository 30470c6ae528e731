#include "core/sampling/poisson_disk.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <mutex>
#include <numbers>

#include "core/base/check.h"
#include "core/sampling/random.h"

namespace aolab {

namespace {

// Dart throwing starts from the radius of a dense random packing of 9n discs in the unit
// disc (n·9·π(r/2)² = η·π with η = 0.75) and shrinks it by kShrink whenever kTries
// candidates in a row are rejected, restarting the set: the largest radius the generator
// finds within the budget. Deterministic: the candidates are one fixed sequence.
constexpr double kPackingDensity = 0.75;
constexpr double kShrink = 0.95;
constexpr int kTries = 4000;

struct Sequence {
  std::uint32_t counter = 0;
  double next() {
    const std::uint32_t h = pcg_hash(pcg_hash(counter++ ^ 0x5EED5EEDu) + 0x9E3779B9u);
    return double(h >> 8) * (1.0 / 16777216.0);
  }
};

double distance(const DiskPoint& a, const DiskPoint& b) {
  return std::hypot(double(a.x) - b.x, double(a.y) - b.y);
}

// Dart throwing with rotations (§4.5): the stored points include every rotation of every
// accepted point, and a candidate must also clear its own rotations (2ρ sin(π/9) >= r).
bool throw_darts(int n, double r, Sequence& seq, std::vector<DiskPoint>& out) {
  out.clear();
  std::vector<DiskPoint> stored;
  const double min_rho = r / (2.0 * std::sin(std::numbers::pi / kPoissonRotations));
  for (int i = 0; i < n; ++i) {
    bool placed = false;
    for (int t = 0; t < kTries && !placed; ++t) {
      const double rho = std::sqrt(seq.next()), phi = 2.0 * std::numbers::pi * seq.next();
      if (rho < min_rho) continue;
      const DiskPoint c{float(rho * std::cos(phi)), float(rho * std::sin(phi))};
      bool ok = true;
      for (const DiskPoint& q : stored)
        if (distance(c, q) < r) {
          ok = false;
          break;
        }
      if (!ok) continue;
      out.push_back(c);
      for (int k = 0; k < kPoissonRotations; ++k) stored.push_back(rotate_point(c, k));
      placed = true;
    }
    if (!placed) return false;
  }
  return true;
}

// Best rotation per point of one group (indices [begin, end)), the earlier points fixed:
// a depth-first search over the partial permutations of the nine rotations maximising the
// sum of distances within the group and to the earlier points (§4.5). The first group fixes
// its first point's rotation: turning a whole set leaves its distances unchanged.
class GroupSearch {
 public:
  GroupSearch(std::vector<DiskPoint>& points, int begin, int end)
      : points_(points),
        begin_(begin),
        m_(end - begin),
        choice_(std::size_t(m_)),
        best_(std::size_t(m_)) {
    constexpr int R = kPoissonRotations;
    std::vector<DiskPoint> rot(std::size_t(m_ * R));
    for (int j = 0; j < m_; ++j)
      for (int k = 0; k < R; ++k)
        rot[std::size_t(j * R + k)] = rotate_point(points[std::size_t(begin + j)], k);
    fixed_.assign(std::size_t(m_ * R), 0.0);
    for (int jk = 0; jk < m_ * R; ++jk)
      for (int i = 0; i < begin; ++i)
        fixed_[std::size_t(jk)] += distance(rot[std::size_t(jk)], points[std::size_t(i)]);
    pair_.assign(std::size_t(m_ * R * m_ * R), 0.0);
    for (int a = 0; a < m_ * R; ++a)
      for (int b = 0; b < m_ * R; ++b)
        pair_[std::size_t(a * m_ * R + b)] = distance(rot[std::size_t(a)], rot[std::size_t(b)]);
    rot_ = std::move(rot);
  }

  void run() {
    search(0, 0u, 0.0);
    for (int j = 0; j < m_; ++j)
      points_[std::size_t(begin_ + j)] =
          rot_[std::size_t(j * kPoissonRotations + best_[std::size_t(j)])];
  }

 private:
  void search(int j, unsigned used, double score) {
    constexpr int R = kPoissonRotations;
    if (j == m_) {
      if (score > best_score_) best_score_ = score, best_ = choice_;
      return;
    }
    const int last_k = (begin_ == 0 && j == 0) ? 0 : R - 1;
    for (int k = 0; k <= last_k; ++k) {
      if (used & (1u << k)) continue;
      const int a = j * R + k;
      double add = fixed_[std::size_t(a)];
      for (int l = 0; l < j; ++l)
        add += pair_[std::size_t(a * m_ * R + l * R + choice_[std::size_t(l)])];
      choice_[std::size_t(j)] = k;
      search(j + 1, used | (1u << k), score + add);
    }
  }

  std::vector<DiskPoint>& points_;
  int begin_, m_;
  std::vector<int> choice_, best_;
  std::vector<DiskPoint> rot_;
  std::vector<double> fixed_, pair_;  // distance sums to earlier points; pairwise in the group
  double best_score_ = -1.0;
};

}  // namespace

DiskPoint rotate_point(const DiskPoint& p, int k) {
  const double a = 2.0 * std::numbers::pi * k / kPoissonRotations;
  const double c = std::cos(a), s = std::sin(a);
  return {float(c * p.x - s * p.y), float(s * p.x + c * p.y)};
}

float min_rotated_distance(const std::vector<DiskPoint>& points) {
  std::vector<DiskPoint> all;
  for (const auto& p : points)
    for (int k = 0; k < kPoissonRotations; ++k) all.push_back(rotate_point(p, k));
  double best = INFINITY;
  for (std::size_t i = 0; i < all.size(); ++i)
    for (std::size_t j = i + 1; j < all.size(); ++j)
      best = std::min(best, distance(all[i], all[j]));
  return float(best);
}

std::uint32_t morton_key(const DiskPoint& p) {
  auto quantise = [](float v) {
    const double u = std::clamp((double(v) + 1.0) * 0.5, 0.0, 1.0);
    return std::uint32_t(std::lround(u * 65535.0));
  };
  auto spread = [](std::uint32_t v) {  // 16 bits -> even bit positions
    v = (v | (v << 8)) & 0x00FF00FFu;
    v = (v | (v << 4)) & 0x0F0F0F0Fu;
    v = (v | (v << 2)) & 0x33333333u;
    v = (v | (v << 1)) & 0x55555555u;
    return v;
  };
  return spread(quantise(p.x)) | (spread(quantise(p.y)) << 1);
}

PoissonDiskSet generate_rotation_aware_poisson_disk(int n, bool choose_rotations) {
  if (n < 1 || n > kPoissonMaxSamples)
    throw_invalid("samples", "must be in [1, " + std::to_string(kPoissonMaxSamples) + "]", n);
  PoissonDiskSet set;
  Sequence seq;
  double r = 2.0 * std::sqrt(kPackingDensity / (kPoissonRotations * n));
  while (!throw_darts(n, r, seq, set.points)) r *= kShrink;
  set.radius = float(r);
  // Best permutation of rotations, in groups of 8 with the earlier groups fixed (§4.5).
  for (int begin = 0; choose_rotations && begin < n; begin += kPoissonPermutationGroup)
    GroupSearch(set.points, begin, std::min(n, begin + kPoissonPermutationGroup)).run();
  // z-order (§4.5): samples near in the disc are near in memory.
  std::stable_sort(
      set.points.begin(), set.points.end(),
      [](const DiskPoint& a, const DiskPoint& b) { return morton_key(a) < morton_key(b); });
  return set;
}

const PoissonDiskSet& rotation_aware_poisson_disk(int n) {
  if (n < 1 || n > kPoissonMaxSamples)
    throw_invalid("samples", "must be in [1, " + std::to_string(kPoissonMaxSamples) + "]", n);
  static std::mutex mutex;
  static std::array<std::unique_ptr<PoissonDiskSet>, kPoissonMaxSamples + 1> cache;
  std::lock_guard<std::mutex> lock(mutex);
  auto& slot = cache[std::size_t(n)];
  if (!slot) slot = std::make_unique<PoissonDiskSet>(generate_rotation_aware_poisson_disk(n));
  return *slot;
}

}  // namespace aolab
