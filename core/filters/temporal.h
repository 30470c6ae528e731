// Temporal accumulation of AO over frames, shared by every method like the blur and `power`:
// the method's sample pattern varies per frame (frame_seed, core/sampling/frame_seed.h) and this
// step blends each frame into a history reprojected by motion vectors, as real-time engines
// do (Karis, "High Quality Temporal Supersampling", SIGGRAPH 2014 Advances in Real-Time
// Rendering course; the XeGTAO notes (Intel, its README), "Denoising" and "Sampling noise").
//
// Per geometry pixel p with the current AO c (docs/temporal.md gives the details):
//   reprojection   q = p + m(p), m the motion vector; H = the bilinear history at q over the
//                  taps whose stored depth and normal agree with p's (weights renormalised),
//                  n = the smallest history length among them; none: disocclusion, n = 0
//   clamp          H clamped to [lo, hi] of the current frame's 3x3 neighbourhood (Karis 2014,
//                  "neighborhood clamping"), optionally narrowed to mu ± gamma·sigma
//   blend          w = max(alpha, 1/(n + 1));  A = H + w·(c − H);  n' = min(n + 1, max_history)
// With alpha = 0 and no clamp a static scene gives the running mean of the frames so far.
#pragma once

#include "core/base/gbuffer.h"
#include "core/base/image.h"
#include "core/base/settings.h"

namespace aolab {

/// The steady-state weight of the current frame: an exponential average with weight α has
/// the variance of a mean of (2 − α)/α frames, 19 frames at 0.1, and a change in the scene
/// fades to 1/e of its size in about 1/α = 10 frames.
constexpr float kTemporalDefaultAlpha = 0.1f;
/// Frames the running mean may count before it becomes an exponential average with weight
/// 1/(max_history + 1): with α = 0, 256 frames average exactly.
constexpr int kTemporalDefaultMaxHistory = 255;
/// A camera 1 m from a surface moving 2.3 cm per frame (walking pace, 1.4 m/s at 60 fps)
/// changes its depth by 2.3 %: 5 % keeps such history, while the step from an object to what
/// lies behind it is usually larger.
constexpr float kTemporalDefaultDepthTolerance = 0.05f;
/// cos 25.8°: a camera turning a few degrees per frame keeps its history (view-space normals
/// turn with it), a crease or a new face does not.
constexpr float kTemporalDefaultNormalTolerance = 0.9f;
/// γ = 1 of variance clipping (Salvi, "An Excursion in Temporal Supersampling", GDC 2016).
constexpr float kTemporalDefaultVarianceGamma = 1.0f;

/// How the reprojected history is held to the current frame's 3x3 neighbourhood.
enum class TemporalClamp : int {
  Off = 0,       ///< no clamp: the history as reprojected (the running mean of a static scene)
  MinMax = 1,    ///< [min, max] of the neighbourhood (Karis 2014)
  Variance = 2,  ///< [min, max] narrowed to mean ± γ·standard deviation (Salvi 2016)
};

struct TemporalSettings {
  /// α: the weight of the current frame once the running mean has reached it. [0, 1].
  float alpha = kTemporalDefaultAlpha;
  /// The cap on a pixel's history length n. [1, 65535].
  int max_history = kTemporalDefaultMaxHistory;
  /// A history tap is kept if |d_history − d| ≤ depth_tolerance · d. [0, 10].
  float depth_tolerance = kTemporalDefaultDepthTolerance;
  /// A history tap is kept if n_history · n ≥ normal_tolerance; −1 keeps every normal.
  /// [−1, 1].
  float normal_tolerance = kTemporalDefaultNormalTolerance;
  /// TemporalClamp. [0, 2].
  int clamp = int(TemporalClamp::MinMax);
  /// γ of variance clipping: the box is mean ± γ·σ of the neighbourhood. [0.25, 8].
  float variance_gamma = kTemporalDefaultVarianceGamma;
};

inline const SettingField<TemporalSettings> kTemporalFields[] = {
    {"alpha", &TemporalSettings::alpha, 0, 1, "",
     "alpha, the steady-state weight of the current frame; a pixel with n frames of history "
     "blends with weight max(alpha, 1/(n+1)), so alpha = 0 is the running mean"},
    {"max_history", &TemporalSettings::max_history, 1, 65535, "frames",
     "cap on a pixel's history length n (the running mean then weighs each frame at least "
     "1/(max_history+1))"},
    {"depth_tolerance", &TemporalSettings::depth_tolerance, 0, 10, "",
     "relative depth difference beyond which a history tap is rejected"},
    {"normal_tolerance", &TemporalSettings::normal_tolerance, -1, 1, "",
     "cosine between history and current normal below which a history tap is rejected; -1 "
     "keeps all"},
    {"clamp", &TemporalSettings::clamp, 0, 2, "",
     "history held to the current 3x3 neighbourhood: off; minmax, its range (Karis 2014); "
     "variance, its range narrowed to mean +- variance_gamma * sigma (Salvi 2016)",
     "off|minmax|variance"},
    {"variance_gamma", &TemporalSettings::variance_gamma, 0.25, 8, "",
     "gamma of variance clipping (clamp = variance only)"},
};

/// What a caller keeps between frames: the last frame's accumulated AO, each pixel's history
/// length n (frames in its blend; 0 on background), its depth (background as NaN) and its
/// prepared normals (3 channels). Empty (default-constructed or reset) means frame 0.
struct TemporalHistory {
  Image ao;
  Image length;
  Image depth;
  Image normal;

  bool empty() const { return ao.width() == 0; }
  int width() const { return ao.width(); }
  int height() const { return ao.height(); }
  void reset() { *this = TemporalHistory{}; }
};

struct TemporalResult {
  Image accumulated;  ///< 1 channel: the blend; background keeps the current frame's value
  Image disoccluded;  ///< 1 where a geometry pixel had no usable history (all of frame 0), else 0
};

/// Which code runs the step: the SIMD kernel (temporal_simd.cpp) or the scalar per-pixel code
/// it is tested against (temporal.cpp); the same bits either way.
enum class TemporalKernel : int { Simd = 0, Scalar = 1 };

/// Blends `ao` (1 channel, this frame's result of a method on `g`) into `history`, which it
/// then replaces with this frame's. `motion` (2 channels, pixels): at pixel (i, j) the offset
/// (dx, dy) to where the surface seen there was in the previous frame, y down; NaN on
/// background. Any motion is ignored on frame 0. Per pixel, so the bits do not depend on
/// `threads` (0 = all cores). Throws std::invalid_argument naming the parameter for bad
/// settings, sizes or channel counts, a history of another size, or AO that is not finite on
/// a geometry pixel; the history is then left as it was.
TemporalResult accumulate(ConstImageView ao, const GBuffer& g, ConstImageView motion,
                          TemporalHistory& history, const TemporalSettings& settings,
                          int threads = 0, TemporalKernel kernel = TemporalKernel::Simd);

/// The settings as type-erased descriptions (describe_settings(kTemporalFields)).
std::vector<SettingDescription> temporal_setting_descriptions();

}  // namespace aolab
