#include "core/methods/lsao/line_sweep_directions.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>

#include "core/base/check.h"

namespace aolab {

double SweepDirection::step_length() const { return std::hypot(step_x, step_y); }

namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

double view_azimuth(double step_x, double step_y, const CameraIntrinsics& cam) {
  // Image rows go down, view-space y goes up.
  double a = std::atan2(-step_y / cam.fy, step_x / cam.fx);
  if (a < 0.0) a += kTwoPi;
  return a;
}

// §5.2: "contribution along directions should be weighted according to the azimuthal
// coverage of each direction": each direction covers half the gap to each neighbour.
// `set` must be sorted by azimuth.
void set_coverage_weights(std::vector<SweepDirection>& set) {
  const int k = int(set.size());
  for (int i = 0; i < k; ++i) {
    const double prev = set[(i + k - 1) % k].azimuth, next = set[(i + 1) % k].azimuth;
    double gap_prev = set[i].azimuth - prev, gap_next = next - set[i].azimuth;
    if (gap_prev <= 0.0) gap_prev += kTwoPi;  // wraps past 2π (and k = 1: the whole circle)
    if (gap_next <= 0.0) gap_next += kTwoPi;
    set[i].weight = 0.5 * (gap_prev + gap_next) / kTwoPi;
  }
}

void set_opposites(std::vector<SweepDirection>& set) {
  for (auto& d : set) {
    d.opposite = -1;
    for (std::size_t j = 0; j < set.size(); ++j)
      if (set[j].step_x == -d.step_x && set[j].step_y == -d.step_y) d.opposite = int(j);
  }
}

}  // namespace

std::vector<SweepDirection> aligned_sweep_directions(int n, int stride,
                                                     const CameraIntrinsics& cam) {
  CHECK_GE(n, 1);
  CHECK_GE(stride, 1);
  // The outer ring of the (2n+1)×(2n+1) template (Figure 10): 8n texel offsets.
  std::vector<std::pair<int, int>> ring;
  for (int j = -n; j <= n; ++j)
    for (int i = -n; i <= n; ++i)
      if (std::max(std::abs(i), std::abs(j)) == n) ring.emplace_back(i, j);
  CHECK_EQ(int(ring.size()), 8 * n);

  // Axis-aligned directions take the mean length of the others (Figure 10), which keeps the
  // density of obscurance values the same in every direction.
  double sum = 0.0;
  int off_axis = 0;
  for (auto [i, j] : ring)
    if (i != 0 && j != 0) sum += std::hypot(double(i), double(j)), ++off_axis;
  const double axis_length = sum / off_axis;

  std::vector<SweepDirection> set;
  for (auto [i, j] : ring) {
    SweepDirection d;
    const int g = std::gcd(std::abs(i), std::abs(j));
    d.lattice_x = i / g;
    d.lattice_y = j / g;
    if (i != 0 && j != 0) {
      d.step_x = double(stride * i);
      d.step_y = double(stride * j);
    } else {
      d.step_x = stride * axis_length * double(d.lattice_x);
      d.step_y = stride * axis_length * double(d.lattice_y);
    }
    d.integer_step = d.step_x == std::round(d.step_x) && d.step_y == std::round(d.step_y);
    d.azimuth = view_azimuth(d.step_x, d.step_y, cam);
    set.push_back(d);
  }
  std::sort(set.begin(), set.end(),
            [](const SweepDirection& a, const SweepDirection& b) { return a.azimuth < b.azimuth; });
  set_coverage_weights(set);
  set_opposites(set);
  return set;
}

std::vector<SweepDirection> uniform_sweep_directions(int k, double step,
                                                     const CameraIntrinsics& cam) {
  CHECK_GE(k, 1);
  std::vector<SweepDirection> set(k);
  // For even K the second half is the exact negation of the first, so that opposite sweeps
  // share their lines and mirror each other bit for bit (core/methods/lsao/lsao.cpp relies on it).
  const int own = k % 2 == 0 ? k / 2 : k;
  for (int i = 0; i < k; ++i) {
    SweepDirection& d = set[i];
    if (i < own) {
      const double theta = kTwoPi * i / k;
      // A view-space azimuth θ is the image direction (fx cos θ, −fy sin θ).
      const double x = cam.fx * std::cos(theta), y = -cam.fy * std::sin(theta);
      const double len = std::hypot(x, y);
      d.step_x = step * x / len;
      d.step_y = step * y / len;
    } else {
      d.step_x = -set[i - own].step_x;
      d.step_y = -set[i - own].step_y;
    }
    d.integer_step = d.step_x == std::round(d.step_x) && d.step_y == std::round(d.step_y);
    d.azimuth = view_azimuth(d.step_x, d.step_y, cam);
  }
  // θ = 2πk/K increases with k, so the set is already in azimuth order.
  set_coverage_weights(set);
  set_opposites(set);
  return set;
}

double mean_step_length(const std::vector<SweepDirection>& directions) {
  double sum = 0.0;
  for (const auto& d : directions) sum += d.step_length();
  return directions.empty() ? 0.0 : sum / double(directions.size());
}

}  // namespace aolab
