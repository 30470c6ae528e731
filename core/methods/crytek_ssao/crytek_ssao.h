// Crytek's screen-space ambient occlusion: Mittring, "Finding Next Gen — CryEngine 2",
// SIGGRAPH 2007 course "Advanced Real-Time Rendering in 3D Graphics and Games", chapter 8,
// §8.5.4.3 (the first SSAO).
//
// A = 1 − (1/N) Σ_{i=1..N} w(Δ_i) · [z_buffer(π(S_i)) < d(S_i)],  S_i = P + R·o_i
// (§8.5.4.3): N points in the sphere of radius R around the pixel's view-space position P, a
// fixed kernel o_i reflected per pixel by a random vector (a small tiled texture of them),
// each projected to the screen (π) and compared with the depth buffer there: the point is
// occluded when the stored surface lies in front of it. w is the range check that keeps an
// occluder far in front of the point from counting. Normal-free: on an open plane half the
// sphere lies under the surface, so A = 1/2 ("the grey look"). docs/methods/crytek_ssao.md
// gives the details.
#pragma once

#include <cstdint>
#include <glm/vec3.hpp>
#include <vector>

#include "core/base/gbuffer.h"
#include "core/base/image.h"
#include "core/base/settings.h"
#include "core/methods/registry.h"

namespace aolab {

/// N = 16: CryEngine 2 used 8 to 16 samples per pixel (§8.5.4.3); the larger count is the
/// quality the course shows.
constexpr int kCrytekSsaoDefaultSamples = 16;

/// The innermost sample's distance, as a fraction of R, in the centre-weighted kernel: sample
/// pair k of K lies at R·lerp(kCrytekSsaoInnerScale, 1, (k/K)²), so occluders near P, which
/// matter most, are sampled more densely (the course's "scaled" kernel).
constexpr float kCrytekSsaoInnerScale = 0.1f;

/// How the kernel's distances from P are spread.
enum class CrytekSsaoDistribution : int {
  Centre = 0,   ///< pair k at R·lerp(0.1, 1, (k/K)²): denser near P (the course's)
  Uniform = 1,  ///< uniform in the ball's volume (distance R·u^(1/3))
};

/// The per-pixel random reflection of the kernel.
enum class CrytekSsaoRotation : int {
  Tiled4x4 = 0,  ///< 16 random vectors tiled over the screen with period 4 (the course's texture)
  PerPixel = 1,  ///< a random vector per pixel (no 4×4 period; noise a blur cannot hide)
  None = 2,      ///< the kernel as drawn (banding)
};

/// The range check w(Δ) of a point Δ behind the stored depth.
enum class CrytekSsaoRangeCheck : int {
  Smooth = 0,  ///< w = clamp(2 − Δ/R, 0, 1): full within R, fading out by 2R
  Hard = 1,    ///< w = 1 for Δ < R, else 0
  Off = 2,     ///< w = 1: any occluder in front counts (far objects darken edges)
};

/// What is returned.
enum class CrytekSsaoOutput : int {
  /// min(1, 2A): an open plane, where half the points lie under the surface, becomes 1 (ours;
  /// what later uses of the method do, so that only occlusion darkens). The default: the
  /// study compares against an AO in which open surfaces are 1.
  Rescaled = 0,
  /// A as published: 1/2 on open planes.
  Published = 1,
};

struct CrytekSsaoSettings {
  /// R: radius of the sphere of points in view-space units (the reference's AO distance).
  /// [1e-12, 1e30].
  float radius = 1.0f;
  /// N: points per pixel. The kernel is made of antipodal pairs o, −o (ours), so on an open
  /// plane exactly half of each pair lies under the surface for any reflection. [1, 256].
  int samples = kCrytekSsaoDefaultSamples;
  /// CrytekSsaoDistribution: 0 centre-weighted (the course's), 1 uniform in the ball.
  int distribution = int(CrytekSsaoDistribution::Centre);
  /// CrytekSsaoRotation: 0 tiled 4×4 (the course's), 1 per pixel, 2 none.
  int rotation = int(CrytekSsaoRotation::Tiled4x4);
  /// CrytekSsaoRangeCheck: 0 smooth, 1 hard, 2 off.
  int range_check = int(CrytekSsaoRangeCheck::Smooth);
  /// CrytekSsaoOutput: 0 rescaled min(1, 2A) (ours, open planes 1), 1 published A.
  int output = int(CrytekSsaoOutput::Rescaled);
  /// The later hemisphere variant: points on the normal's side of P only (o·n < 0 is
  /// flipped), so an open plane is 1 without the rescale; reads normals (the G-buffer's, or
  /// estimated from depth without them). Off: normal-free, as published.
  bool hemisphere = false;
  /// Seed of the kernel and of the reflection vectors. [0, 2^31 - 1].
  int seed = 0;
};

inline const SettingField<CrytekSsaoSettings> kCrytekSsaoFields[] = {
    {"radius", &CrytekSsaoSettings::radius, 1e-12, 1e30, "view-space units",
     "R, radius of the sphere of points (same as the reference's AO distance)"},
    {"samples", &CrytekSsaoSettings::samples, 1, 256, "", "N, points per pixel"},
    {"distribution", &CrytekSsaoSettings::distribution, 0, 1, "",
     "distances of the kernel's points: denser near the pixel (the course's) or uniform in "
     "the ball",
     "centre|uniform"},
    {"rotation", &CrytekSsaoSettings::rotation, 0, 2, "",
     "per-pixel reflection of the kernel: 4x4 tiled random vectors (the course's), one per "
     "pixel, or none",
     "tiled4x4|per_pixel|none"},
    {"range_check", &CrytekSsaoSettings::range_check, 0, 2, "",
     "weight of a point behind the stored depth by Delta: full within R fading out by 2R, "
     "full within R only, or always full",
     "smooth|hard|off"},
    {"output", &CrytekSsaoSettings::output, 0, 1, "",
     "min(1, 2A) so that open planes are 1 (ours), or A as published (1/2 on open planes)",
     "rescaled|published"},
    {"hemisphere", &CrytekSsaoSettings::hemisphere, 0, 1, "",
     "points on the normal's side only (the later variant; reads normals)"},
    {"seed", &CrytekSsaoSettings::seed, 0, 2147483647, "",
     "seed of the kernel and the reflection vectors"},
};

/// The kernel: `samples` offsets in the unit ball, antipodal pairs (o_{2k+1} = −o_{2k}; an odd
/// count ends with one unpaired point), distances by `distribution`, drawn from `seed`.
std::vector<glm::vec3> crytek_ssao_kernel(int samples, CrytekSsaoDistribution distribution,
                                          int seed);

/// The pixel_random stream of the per-pixel reflection vectors (`rotation = per_pixel`): the
/// vector of pixel (x, y) is a uniform unit vector from the streams 303 and 304 at (x, y).
constexpr std::uint32_t kCrytekSsaoPixelStream = 303;

/// Crytek SSAO of a G-buffer. Returns a 1-channel image in [0, 1]; background = 1.
/// Throws std::invalid_argument for invalid settings or an invalid G-buffer; Cancelled if
/// cancelled.
Image crytek_ssao(const GBuffer& g, const CrytekSsaoSettings& settings,
                  const RunOptions& options = {});

/// The registry entry (normal-free: needs_normal is false; the hemisphere variant reads
/// prepared_normals, which fall back to normals from depth).
Method crytek_ssao_method();

}  // namespace aolab
