// The azimuthal directions of line-sweep ambient obscurance (Timonen, "Line-Sweep Ambient
// Obscuration", EGSR 2013, §5): which way each sweep goes, how long its steps are, and how
// much of the azimuth it stands for.
//
// Two kinds of sets:
//  - aligned (§5.2): the 8n vectors from the centre of a (2n+1)×(2n+1) texel template to the
//    centres of its outer texels. Stepping by such a vector from a texel centre lands on texel
//    centres only, so snapping never moves a sample and every receiver along a line sees the
//    same pattern of earlier samples (the artefact of Figure 9 cannot occur);
//  - uniform (§5.1): K directions evenly spaced in azimuth with a free step D_S; samples are
//    snapped to texels or interpolated (core/methods/lsao/lsao.h, setting `sampling`).
// Azimuths are view-space angles around the view axis (x right, y up), so the coverage
// weights stay right for non-square pixels.
#pragma once

#include <vector>

#include "core/base/camera.h"

namespace aolab {

/// One sweep direction.
struct SweepDirection {
  double step_x = 0;  ///< image-space step, pixels, x to the right
  double step_y = 0;  ///< image-space step, pixels, y down (rows)
  /// The direction in the view-space image plane, radians in [0, 2π), from +x towards +y
  /// (up): atan2(−step_y/fy, step_x/fx).
  double azimuth = 0;
  /// Share of the azimuth this direction stands for (§5.2, last paragraph: "weighted
  /// according to the azimuthal coverage"): half the angular gap to each neighbour, over
  /// 2π. The weights of a set sum to 1.
  double weight = 0;
  /// Aligned sets only: the primitive integer vector along the direction (gcd 1), e.g.
  /// (1, 1) for the template vector (2, 2); (0, 0) for uniform sets.
  int lattice_x = 0, lattice_y = 0;
  /// True if the step is a whole number of texels in x and y: a sample that starts on a
  /// texel centre stays on texel centres.
  bool integer_step = false;
  /// Index of the direction whose step is exactly −step (its sweeps run the same lines
  /// backwards), or −1 if the set has none.
  int opposite = -1;

  double step_length() const;
};

/// The §5.2 aligned set of template size n ≥ 1: K = 8n directions, the vectors (i, j) with
/// max(|i|, |j|) = n, each scaled by `stride` (≥ 1; Figure 1 steps two template vectors at a
/// time: D_S = 2.83 for K = 8). The four axis-aligned directions have no template vector of
/// their own length: they use the mean length of the others ("The axis aligned directions use
/// D_S that is the average of the rest of the directions", Figure 10). Sorted by azimuth,
/// starting at +x.
std::vector<SweepDirection> aligned_sweep_directions(int n, int stride,
                                                     const CameraIntrinsics& cam);

/// K ≥ 1 directions evenly spaced in view-space azimuth, 2π k/K from +x, with steps of
/// `step` pixels. For even K direction k + K/2 is exactly the negation of direction k.
std::vector<SweepDirection> uniform_sweep_directions(int k, double step,
                                                     const CameraIntrinsics& cam);

/// Mean step length D_S of a set, pixels (the paper's "average step length", Figure 10).
double mean_step_length(const std::vector<SweepDirection>& directions);

}  // namespace aolab
