// Rotation-aware Poisson-disk sample sets in the unit disc (Bokšanský, Pospíšil, Bittner,
// "VAO++: Practical Volumetric Ambient Occlusion for Games", EGSR 2017, §4.5). A set of n
// points is generated so that it stays a Poisson-disk distribution after being rotated by the
// nine angles 2πk/9 of the 3×3 interleaving tile: every candidate keeps its distance to every
// stored point *and to all their rotations* (and to its own rotations). Then, in groups of 8, each
// point is given the rotation (a partial permutation of the nine) that maximises the sum of
// distances between the chosen points, and the set is sorted in z-order.
// Everything is deterministic (a fixed counter-based random sequence), so the sets are the
// same on every machine; they are computed once per size and cached in memory.
#pragma once

#include <cstdint>
#include <vector>

namespace aolab {

/// The nine rotation angles 2πk/9 of the 3×3 interleaving tile (§4.5).
constexpr int kPoissonRotations = 9;
/// §4.5: "we incrementally add groups of 8 samples and look for best permutation of last
/// group with fixed previous groups" (all permutations of up to 8 are tested).
constexpr int kPoissonPermutationGroup = 8;
/// The largest set the generator accepts (VAO++ uses 2…32, §4.1).
constexpr int kPoissonMaxSamples = 64;

struct DiskPoint {
  float x = 0, y = 0;
};

/// A generated set: the points (rotation 0, best rotations chosen, z-ordered) and the
/// Poisson radius r they were generated with: every pair of the 9·n rotated points, and
/// every point and its own rotations, are at least r apart.
struct PoissonDiskSet {
  std::vector<DiskPoint> points;
  float radius = 0;
};

/// Generates the set of n points, n in [1, kPoissonMaxSamples] (uncached; ~ms for n = 32).
/// `choose_rotations` = false skips the best permutation (for the tests).
/// Throws std::invalid_argument naming `samples` for another n.
PoissonDiskSet generate_rotation_aware_poisson_disk(int n, bool choose_rotations = true);

/// The cached set of n points: generated on first use, thread-safe, never freed.
const PoissonDiskSet& rotation_aware_poisson_disk(int n);

/// (x, y) rotated by 2πk/kPoissonRotations.
DiskPoint rotate_point(const DiskPoint& p, int k);

/// The smallest distance between any two of the kPoissonRotations rotations of all points
/// (a point's own rotations included). Used by the tests.
float min_rotated_distance(const std::vector<DiskPoint>& points);

/// Morton (z-order) key of a point of [-1, 1]²: 16 bits per axis, interleaved, x lowest.
std::uint32_t morton_key(const DiskPoint& p);

}  // namespace aolab
