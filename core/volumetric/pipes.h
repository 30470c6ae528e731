// The volumetric obscurance of VAO (Szirmay-Kalos, Umenhoffer, Tóth, Szécsi, Sbert, "Volumetric
// Ambient Occlusion for Real-Time Rendering and Games", IEEE CG&A 2010) that VAO and VAO++
// (Bokšanský, Pospíšil, Bittner, EGSR 2017, which runs VAO's per-sample code with extensions)
// share: the disc sample sets, the pipes through the tangent sphere and their open lengths
// (Figure 3's cases), the frame the per-pixel code reads and the per-pixel sums.
// core/methods/vao/vao.h states the method; docs/methods/vao.md gives the details.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/base/camera.h"
#include "core/base/gbuffer.h"
#include "core/base/image.h"
#include "core/base/working_memory.h"
#include "core/sampling/poisson_disk.h"

namespace aolab {

/// 16 samples: the middle of the 2…32 sample counts of VAO++ Table 1.
constexpr int kVaoDefaultSamples = 16;
/// The largest sample count (VAO++ goes to 32; twice that leaves room for studies).
constexpr int kVaoMaxSamples = 64;

/// Float32 rounding must not create occlusion: a surface counts as in front of a pipe's far
/// end only by more than 2^-24 · kVaoDepthUlps · (the magnitudes entering both depths, and
/// the conditioning of the ray-sphere intersection), so an unoccluded plane gives exactly 1.
constexpr float kVaoDepthUlps = 16.0f;

/// u of the depth range check (VAO++ eq. 4): "We use empirically selected value of 0.03".
constexpr float kVaoRangeCheckU = 0.03f;

/// Unit-disc samples with h_i = sqrt(1 - x_i² - y_i²), the half pipe length over r.
struct VaoKernel {
  std::vector<float> x, y, h;
  int size() const { return int(x.size()); }
};

/// A kernel from disc points (h computed in double, clamped at 0 on the rim).
VaoKernel vao_kernel(const std::vector<DiskPoint>& points);

/// n points uniform in the unit disc: the Vogel (golden-angle) spiral, point i at radius
/// sqrt((i + 0.5)/n) and angle i·π(3 - √5). VAO's own sample set (the paper only asks for
/// uniform disc samples).
VaoKernel vao_spiral_kernel(int n);

/// The kernel rotated by `angle` radians about the disc centre (h unchanged).
VaoKernel rotated(const VaoKernel& k, float angle);

/// VAO's interleaving: `base` turned by the per-pixel random angle 2π·pixel_random(seed, x, y,
/// 0) into `out` (whose h is base's).
void vao_random_rotation(const VaoKernel& base, std::uint32_t seed, int x, int y, VaoKernel& out);

/// F of eq. 2: R Σ sqrt(1 - x_i² - y_i²) (in double). For n uniform samples it tends to the
/// closed form |S| / (R²π/(4n)) = 2Rn/3 of eq. 1.
double vao_eq2_normaliser(const VaoKernel& k, double radius);

/// s(d) = u / max(u, d/radius) (VAO++ eq. 4): the weight of occlusion by a surface d in front
/// of the sample (d <= u·radius: 1).
inline float vao_range_falloff(float d, float radius) {
  return kVaoRangeCheckU / std::max(kVaoRangeCheckU, d / radius);
}

/// A pipe's extent inside the tangent sphere as depths along it: front < back.
struct VaoPipe {
  float front, back;
};

enum class VaoCase { A, B, C };

/// Figure 3's case for a surface at `surface_depth` on the pipe (NaN = background: case B).
/// `tolerance`: a surface within it in front of `back` still counts as behind (case B).
VaoCase vao_case(const VaoPipe& pipe, float surface_depth, float tolerance);

/// Δz of one pipe: A: surface_depth - front; B: back - front; C: 0. With `range_check`
/// (VAO++ §4.4) the occluded part back - front - Δz is weighted by s(d), d the depth of the
/// sample point (the pipe's middle) behind the surface (s = 1 while it is in front).
float vao_unoccluded_length(const VaoPipe& pipe, float surface_depth, float tolerance,
                            bool range_check, float radius);

/// The G-buffer as the per-pixel code reads it: depth with background as NaN (so every
/// comparison with it fails), prepared normals and, if asked for, colour clamped to [0, 1].
struct VaoFrame {
  Buffer<float> depth;
  Image normals;
  Image color;  ///< 3 channels, or empty
  int width = 0, height = 0;
  CameraIntrinsics camera;
};
VaoFrame vao_frame(const GBuffer& g, bool with_color, int threads);

/// What one pixel's samples are evaluated with.
struct VaoPixelOptions {
  float radius = 1.0f;
  bool view_ray_pipes = true;
  bool range_check = false;  ///< VAO++ §4.4
  int bleeding_step = 0;     ///< VAO++ §4.7: every k-th sample gathers colour; 0 = none
};

/// Sums over one pixel's samples.
struct VaoPixelSums {
  float open = 0.0f;                    ///< Σ Δz_i over the samples that were evaluated
  float full = 0.0f;                    ///< Σ full pipe lengths of the same samples (F)
  float bleed[3] = {0.0f, 0.0f, 0.0f};  ///< Σ lerp(white, colour, c(x)) (eq. 5)
  int bleed_count = 0;
  /// V = open / full clamped to [0, 1]; 1 when no sample was evaluated.
  float ao() const { return full > 0.0f ? std::clamp(open / full, 0.0f, 1.0f) : 1.0f; }
};

/// The per-sample work of eq. 1 for the geometry pixel (x, y), samples (sx, sy, sh) of the
/// unit disc (already rotated). A sample whose point projects outside the image or behind the
/// camera, or (view-ray pipes) whose texel's ray misses the sphere, is left out of both sums;
/// one that lands on the pixel itself is open (the surface there is P, where the sphere
/// touches it).
VaoPixelSums vao_pixel(const VaoFrame& f, const VaoPixelOptions& o, int x, int y, const float* sx,
                       const float* sy, const float* sh, int n);

}  // namespace aolab
