// Volumetric ambient occlusion: Szirmay-Kalos, Umenhoffer, Tóth, Szécsi, Sbert, "Volumetric
// Ambient Occlusion for Real-Time Rendering and Games", IEEE CG&A 2010, as outlined in VAO++
// (Bokšanský, Pospíšil, Bittner, "VAO++: Practical Volumetric Ambient Occlusion for Games",
// EGSR 2017, §3).
//
// The tangent sphere of radius r = R/2 sits on the surface, its centre C = P + r·n. Samples
// (x_i, y_i) of the unit disc are placed on the sphere's great disc perpendicular to the view
// axis, S_i = C + r (x_i, y_i, 0). Each sample stands for a pipe through the sphere; the
// depth buffer at the sample's pixel decides how much of the pipe is open (Figure 3):
//   case A: the surface lies inside the sphere   -> the part in front of it is open;
//   case B: no surface, or a surface behind it   -> the whole pipe is open;
//   case C: the surface lies in front of it      -> nothing is open.
//   V = Σ Δz_i / F,   F = R Σ sqrt(1 - x_i² - y_i²)                        (eq. 1, eq. 2)
// V is the open fraction of the sphere: A = V (1 = unoccluded). docs/methods/vao.md.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/base/gbuffer.h"
#include "core/base/image.h"
#include "core/base/settings.h"
#include "core/methods/registry.h"
#include "core/volumetric/pipes.h"

namespace aolab {

struct VaoSettings {
  /// R: radius of influence in view-space units; the tangent sphere has radius R/2 (§3).
  /// [1e-12, 1e30].
  float radius = 1.0f;
  /// n: samples on the disc (eq. 1). [1, 64].
  int samples = kVaoDefaultSamples;
  /// Rotate the sample set by a random angle per pixel (interleaved sampling, [SKUT*10]).
  bool random_rotation = true;
  /// true: each pipe runs along the view ray through its sample's texel centre, F is the
  /// sum of those pipes' full lengths (eq. 2's principle), and an unoccluded plane is exactly
  /// 1 at any perspective. false: pipes parallel to the view axis through the disc points,
  /// Δz_i against the depth at the sample's texel, F by eq. 2 (the paper's words; perspective
  /// makes tilted planes occlude themselves slightly off-axis).
  bool view_ray_pipes = true;
  /// Seed of the per-pixel rotation. [0, 2^31 - 1].
  int seed = 0;
};

inline const SettingField<VaoSettings> kVaoFields[] = {
    {"radius", &VaoSettings::radius, 1e-12, 1e30, "view-space units",
     "R, radius of influence; the tangent sphere has radius R/2"},
    {"samples", &VaoSettings::samples, 1, kVaoMaxSamples, "", "n, samples on the disc"},
    {"random_rotation", &VaoSettings::random_rotation, 0, 1, "",
     "rotate the sample set by a random angle per pixel"},
    {"view_ray_pipes", &VaoSettings::view_ray_pipes, 0, 1, "",
     "pipes along the view rays of the samples' texels (exact on planes); off: parallel to "
     "the view axis, F by eq. 2"},
    {"seed", &VaoSettings::seed, 0, 2147483647, "", "seed of the per-pixel rotation"},
};

/// VAO of a G-buffer with normals. Returns a 1-channel image in [0, 1]; background = 1.
/// Throws std::invalid_argument for invalid settings, a G-buffer without normals or an
/// invalid G-buffer; Cancelled if cancelled.
Image vao(const GBuffer& g, const VaoSettings& settings, const RunOptions& options = {});

/// The registry entry.
Method vao_method();

}  // namespace aolab
