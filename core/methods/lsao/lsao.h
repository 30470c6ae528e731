// Line-sweep ambient obscurance: Ville Timonen, "Line-Sweep Ambient Obscuration", Computer
// Graphics Forum 32(4) (Proc. EGSR), 2013. docs/methods/lsao.md gives the details.
//
// K azimuthal directions (§3); per direction, lines D_L pixels apart cross the depth buffer
// (§5.1) and are walked in steps of D_S pixels. Along a line the visited points are kept on
// an "obscure hull" stack (§4.1, Algorithm 1) whose top is the point casting the largest
// falloff-weighted obscurance on the current receiver, found in amortised O(1):
//
//   O_k = sin t + max(0, sin h − sin t) · ρ(|h|)                      (eq. 1, one direction)
//   ρ(d) = r / (r + d²)  (eq. 2)   or   ρ0(d) = max(0, r(1+C)/(r + d²) − C)   (eq. 3)
//   or, as Cycles' reference AO counts hits: ρ(d) = 1 for d ≤ R, 0 beyond (falloff `cutoff`)
//
// h: the vector from the receiver to that point, t: the tangent (fixed sin t = −0.85 by
// default, §4.1 strategy 3), both as elevations from the zenith towards the eye. The values
// of a direction land in an intermediate buffer of about W·H/(D_S·D_L) values; each pixel
// then averages the nearest value of every direction, weighted by azimuthal coverage (§5.1,
// §5.2) and restricted to values of similar depth (and optionally normal):
//
//   A = 1 − Σ_k w_k O_k / Σ_k w_k,  clamped to [0, 1].
//
// Radius: r = C·R² (C = 0.3, §6), so eq. 3 reaches zero exactly at the reference's AO
// distance R and eq. 2 shares its decay rate. Cost per pixel is about 2K (§6) whatever R.
// Units: view space, planar depth (docs/conventions.md). Errors: std::invalid_argument naming
// the setting. Threads: lines, then pixels, in fixed bands; bit-identical for any count.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <mutex>
#include <vector>

#include "core/base/gbuffer.h"
#include "core/base/image.h"
#include "core/base/settings.h"
#include "core/methods/lsao/line_sweep_directions.h"
#include "core/methods/registry.h"

namespace aolab {

/// §4.1, last paragraph: "we have chosen to fix all tangents to sin(t) = −0.85, which
/// produces mainly underocclusion".
constexpr float kLsaoPaperTangentSin = -0.85f;

/// C of eq. 3; §6: "In this section we use C = 0.3". Also sets r = C·R² (see lsao_falloff).
constexpr float kLsaoFalloffOffset = 0.3f;

/// Normal-aware gather: a value counts for a pixel only if the normals at the two points
/// are within ~25° (cos 25° ≈ 0.906). The paper names the test but not its threshold (§5.1);
/// 25° keeps the values of one smooth surface (normals on a sphere of radius ≥ 2 D_S pixels
/// turn less) and drops the other face of any crease sharper than that.
constexpr float kLsaoGatherNormalCos = 0.906f;

/// Interpolated sampling (§5.2, "use linear interpolation ... until an edge is detected
/// (depth or normal changes too much from the previous point), in which case the sampling
/// coordinate is snapped to texel center"): an edge is a relative depth change above 10 %
/// from the line's previous sample, or a background texel among the four read. 10 % is far
/// above the change between D_S-apart samples of a surface facing the camera within ~80°
/// at D_S ≤ 4 (≈ D_S·tan θ/f) and below typical object-to-background jumps.
constexpr float kLsaoEdgeRelativeDepth = 0.1f;

/// §4.1's three treatments of the tangent plane in eq. 1.
enum class LsaoTangent : int {
  /// 1: the receiver's real tangent for popping the hull and for its obscurance.
  Real = 1,
  /// 2: the fixed tangent (tangent_sin) for popping, the real tangent for the obscurance.
  FixedHullRealObscurance = 2,
  /// 3 (paper's choice): the fixed tangent for both; needs no normals.
  Fixed = 3,
};

/// Weight of an occluder at distance d.
enum class LsaoFalloff : int {
  Eq2 = 2,  ///< ρ(d) = r/(r + d²): never zero, the paper's falloff for its own method
  Eq3 = 3,  ///< ρ0(d) = max(0, r(1+C)/(r + d²) − C): zero from d = √(r/C), used for HBAO (§6)
  /// ρ(d) = 1 for d ≤ R, 0 beyond: the Cycles reference's hard cut-off (every hit within the
  /// AO distance counts fully), not the paper's; d ≤ R is d²/r ≤ 1/C.
  Cutoff = 4,
};

/// Pixel sampling along lines of uniform (non-aligned) directions, §5.2.
enum class LsaoSampling : int {
  Snap = 0,         ///< the containing texel's centre and depth
  Interpolate = 1,  ///< bilinear depth, snapped to the texel at edges (kLsaoEdgeRelativeDepth)
};

struct LsaoSettings {
  /// R: view-space distance at which eq. 3 reaches zero (and the cutoff falloff cuts off);
  /// eq. 2 uses the same r = C·R² (half weight at √C·R ≈ 0.55 R, 0.23 at R).
  /// [1e-12, 1e30] view-space units.
  float radius = 1.0f;
  /// K: azimuthal directions (§3). Must be 8·template_size when template_size > 0. [1, 64].
  int directions = 16;
  /// n: §5.2 aligned directions from a (2n+1)×(2n+1) texel template (K = 8n); 0 = K
  /// directions evenly spaced in azimuth with step `step` (§5.1). [0, 8].
  int template_size = 2;
  /// m: aligned sets step m template vectors at a time, D_S = m · (mean template vector
  /// length): n = 2 gives 2.43 (m = 1), 4.87 (m = 2), the paper's K = 16 settings. [1, 16].
  int template_stride = 1;
  /// D_S for template_size = 0: step along a line, pixels (1 = dense, §5.1). [1, 64].
  float step = 1.0f;
  /// D_L: distance between parallel lines, pixels (1 = dense, §5.1). [1, 64].
  float line_spacing = 1.64f;
  /// §4.1 strategy, LsaoTangent: 1 real tangent (from normals), 2 fixed tangent for the
  /// hull and real for the obscurance, 3 fixed for both (the paper's). [1, 3].
  int tangent_strategy = 3;
  /// sin t of the fixed tangent (strategies 2 and 3), §4.1: −0.85 in the paper, Figure 7
  /// also shows −0.5 and −1.0. [−1, 0].
  float tangent_sin = kLsaoPaperTangentSin;
  /// Falloff, LsaoFalloff: 2 = eq. 2 (the paper's), 3 = eq. 3 (the one it uses for HBAO,
  /// C = 0.3), 4 = cutoff (ρ = 1 within R, 0 beyond: the reference's). [2, 4].
  int falloff = 2;
  /// Depth-aware gather (§5.1): a direction's value counts for a pixel only if its depth is
  /// within this fraction of the pixel's depth. [0, 1e30] (large = off).
  float gather_depth_tolerance = 0.1f;
  /// Normal-aware gather (§5.1): also require the normals within kLsaoGatherNormalCos.
  bool normal_aware_gather = false;
  /// LsaoSampling for lines whose samples are not on texel centres (uniform directions; the
  /// axis directions of aligned sets): 0 snap, 1 interpolate with snapping at edges. [0, 1].
  int sampling = 0;
  /// 0: the line lattice of every direction passes through the image centre (the paper's
  /// layout, no randomness). > 0: offset each direction pair's lattice by a random fraction
  /// of D_L across and D_S along (counter-based, from the seed). [0, 2^31 − 1].
  int seed = 0;
  /// Stack entries below the top whose obscurance is also tried for the written result
  /// (they are not popped). 0 = Algorithm 1 exactly (line 20 writes the top's). The paper's
  /// degenerate case with the largest occluder still on the stack, under a nearer point that
  /// is higher but farther in view space (thin geometry before a surface), is caught when it
  /// is within this many entries; cost grows linearly with it. [0, 256].
  int hull_search = 0;
};

inline const SettingField<LsaoSettings> kLsaoFields[] = {
    {"radius", &LsaoSettings::radius, 1e-12, 1e30, "view-space units",
     "R, where eq. 3 reaches zero and cutoff cuts off; eqs. 2 and 3 use r = 0.3 R^2"},
    {"directions", &LsaoSettings::directions, 1, 64, "",
     "K, azimuthal directions; 8 x template_size when template_size > 0"},
    {"template_size", &LsaoSettings::template_size, 0, 8, "",
     "n, aligned directions from a (2n+1)^2 texel template (K = 8n); 0 = K uniform directions"},
    {"template_stride", &LsaoSettings::template_stride, 1, 16, "",
     "m, template vectors per step of an aligned set (D_S = m x mean template vector length)"},
    {"step", &LsaoSettings::step, 1, 64, "px", "D_S of uniform directions (template_size = 0)"},
    {"line_spacing", &LsaoSettings::line_spacing, 1, 64, "px", "D_L, distance between lines"},
    {"tangent_strategy", &LsaoSettings::tangent_strategy, 1, 3, "",
     "real: the receiver's tangent; fixed_hull: the fixed tangent for the hull, the real one for "
     "the obscurance; fixed: the fixed tangent for both (the paper's)",
     "real|fixed_hull|fixed"},
    {"tangent_sin", &LsaoSettings::tangent_sin, -1, 0, "", "sin t of the fixed tangent"},
    {"falloff", &LsaoSettings::falloff, 2, 4, "",
     "rational: eq. 2, r/(r + d^2); clipped: eq. 3, max(0, r(1+C)/(r + d^2) - C), C = 0.3; "
     "cutoff: 1 within R, 0 beyond, as in the reference",
     "rational|clipped|cutoff"},
    {"gather_depth_tolerance", &LsaoSettings::gather_depth_tolerance, 0, 1e30, "relative",
     "a value counts for a pixel only within this fraction of its depth"},
    {"normal_aware_gather", &LsaoSettings::normal_aware_gather, 0, 1, "",
     "also require normals within 25 degrees when gathering"},
    {"sampling", &LsaoSettings::sampling, 0, 1, "",
     "off-texel samples: snap to the texel, or interpolate (snapping at depth edges)",
     "snap|interpolate"},
    {"seed", &LsaoSettings::seed, 0, 2147483647, "",
     "0 = line lattice through the image centre; > 0 = random lattice offset"},
    {"hull_search", &LsaoSettings::hull_search, 0, 256, "entries",
     "stack entries under the top also tried for the result; 0 = Algorithm 1 exactly"},
};

/// Line-sweep AO of a G-buffer; needs depth only (normals are read if present and a setting
/// asks for them, and estimated from depth with prepared_normals otherwise). Returns a
/// 1-channel image in [0, 1]; background = 1. Throws std::invalid_argument for invalid
/// settings or G-buffer; Cancelled if cancelled.
Image lsao(const GBuffer& g, const LsaoSettings& settings, const RunOptions& options = {});

/// The registry entry.
Method lsao_method();

/// ρ and 1 − ρ of a falloff; 1 − ρ is computed without cancellation.
struct LsaoWeight {
  float rho;
  float one_minus_rho;
};

/// The falloff for q2 = d²/r (r = C·R²). An infinite q2 gives ρ = 0.
inline LsaoWeight lsao_falloff(float q2, LsaoFalloff falloff) {
  if (!(q2 < std::numeric_limits<float>::infinity())) return {0.0f, 1.0f};
  if (falloff == LsaoFalloff::Cutoff) {  // d ≤ R ⇔ d²/r ≤ 1/C
    if (q2 * kLsaoFalloffOffset <= 1.0f) return {1.0f, 0.0f};
    return {0.0f, 1.0f};
  }
  const float rho = 1.0f / (1.0f + q2);  // eq. 2: r/(r + d²)
  const float rest = q2 * rho;           // 1 − r/(r + d²) = d²/(r + d²)
  if (falloff == LsaoFalloff::Eq2) return {rho, rest};
  // Eq. 3: (1 + C)·ρ − C, clipped at 0; 1 − ρ0 = (1 + C)(1 − ρ).
  return {std::max(0.0f, (1.0f + kLsaoFalloffOffset) * rho - kLsaoFalloffOffset),
          std::min(1.0f, (1.0f + kLsaoFalloffOffset) * rest)};
}

// ---- The layout of lines and samples (§5.1, §5.2), shared with the textbook version
// (tests/textbook) so both sweep the same samples and gather the same way; the textbook
// version re-derives the hull and the estimator in double precision. ----

/// One line of samples: sample j is at origin + j·step (pixel coordinates, the centre of
/// pixel (i, j) is (i + 0.5, j + 0.5)), for j in [first, first + count).
struct LsaoLine {
  double origin_x = 0, origin_y = 0;
  int first = 0, count = 0;
  std::size_t offset = 0;  ///< index of sample `first` in its direction's slice of the buffers
};

/// The lines of one direction and, backwards, of its opposite (same samples, §5.1).
struct LsaoLines {
  int direction = 0;            ///< the direction whose step the lines follow
  double across_x, across_y;    ///< unit vector across the lines (pixels)
  double phase_across;          ///< offset of line 0 across, from the image centre (pixels)
  double spacing;               ///< D_L
  int first_line;               ///< line index of lines[0]
  std::vector<LsaoLine> lines;  ///< consecutive line indices; lines outside the image have count 0
  std::size_t samples = 0;      ///< Σ count
};

struct LsaoPlan {
  int width = 0, height = 0;
  CameraIntrinsics camera;
  std::vector<SweepDirection> directions;
  std::vector<int> lines_of;   ///< per direction: index into `lines`
  std::vector<bool> reversed;  ///< per direction: walks its lines from the last sample
  std::vector<LsaoLines> lines;
  /// Buffer layout: per `lines` entry, per sample in line order, a record of `stride[li]`
  /// floats: the sample's depth, then O_k of each direction using the lines (slot[k]).
  std::vector<std::size_t> base;  ///< per `lines` entry: its first record in the buffer
  std::vector<int> stride;        ///< per `lines` entry: 1 + the directions that use it
  std::vector<int> slot;          ///< per direction: its value's place in a record (1 or 2)
  std::size_t buffer_size = 0;    ///< floats
  std::size_t value_count = 0;    ///< obscurance values, Σ over directions of their samples

  /// Index of sample i's depth (i counts from the first sample of lines[li]).
  std::size_t depth_index(int li, std::size_t i) const {
    return base[li] + i * std::size_t(stride[li]);
  }
  /// Index of direction k's value at sample i of its lines.
  std::size_t value_index(int k, std::size_t i) const {
    return depth_index(lines_of[k], i) + std::size_t(slot[k]);
  }
};

/// Directions, lines and buffer offsets for a frame (validates the settings).
LsaoPlan lsao_plan(const GBuffer& g, const LsaoSettings& s);

/// Position (pixels) of sample j of a line of `lines` whose step is (step_x, step_y):
/// computed one way everywhere, so the sweep, the gather and the textbook version agree to
/// the bit.
inline void lsao_sample_position(const LsaoLine& line, const SweepDirection& d, int j, double& x,
                                 double& y) {
  x = line.origin_x + double(j) * d.step_x;
  y = line.origin_y + double(j) * d.step_y;
}

/// One evaluated sample: where it was evaluated and its depth (NaN on background).
struct LsaoSample {
  float x, y;   ///< pixel coordinates: a texel centre, or a point between them if interpolated
  float depth;  ///< planar depth, NaN on background
};

/// The samples of line `line` of lines[`lines_index`] in line order (j = first, first+1, …),
/// sampled per `sampling`. `depth` holds W·H planar depths, background as NaN
/// (depth_with_background_as_nan).
void lsao_line_samples(const LsaoPlan& plan, const float* depth, LsaoSampling sampling,
                       int lines_index, int line, std::vector<LsaoSample>& out);

/// The intermediate buffer (§5.2, "an intermediate floating point buffer the size of
/// K·W·H/(D_S·D_L) elements"), with each sample's depth beside the values of the (one or
/// two) directions that visit it, so the gather reads one cache line per sample.
/// A geometry sample as the SIMD gather reads it: its texel, depth and Σ w_k O_k over the
/// directions sharing it (an opposite pair). 12 bytes: the sweep writes one per sample and
/// the gather reads them back from memory, so their size is time (images up to 65535 pixels
/// a side; larger ones run the scalar gather).
struct LsaoTexelRecord {
  std::uint16_t x, y;
  float depth, pair;
};

/// The texel records of a run of consecutive lines of one plan.lines entry, grouped by rows
/// of texels (kLsaoRecordRows rows a bucket; within a bucket in buffer order), so that the
/// gather reads the samples near a band of rows contiguously.
struct LsaoTexelRun {
  int lines_index = 0;
  /// bucket_start.back() records, in the sweep's LsaoRecordArena (not value-initialised: each
  /// is written once by the sweep).
  LsaoTexelRecord* records = nullptr;
  std::vector<std::uint32_t> bucket_start;  ///< per bucket of rows, and the end
};
constexpr int kLsaoRecordRows = 4;

/// The memory of a sweep's texel records: working arrays (working_memory.h) of
/// kLsaoRecordChunk records, a run's records taken from the last one with room, from any of
/// the sweep's threads. A frame's records (some 200 MiB at 3840×2160) were otherwise thousands
/// of allocations under 1 MiB that malloc returned to the system, and faulted in again, every
/// frame.
class LsaoRecordArena {
 public:
  /// Room for n records, left uninitialised; valid while the arena lives.
  LsaoTexelRecord* take(std::size_t n);

 private:
  std::mutex mutex_;
  std::vector<UninitializedBuffer<LsaoTexelRecord>> chunks_;
  std::size_t used_ = 0;  ///< records taken from chunks_.back()
};
constexpr std::size_t kLsaoRecordChunk = (std::size_t(8) << 20) / sizeof(LsaoTexelRecord);

struct LsaoSweep {
  LsaoPlan plan;
  /// plan.buffer_size floats laid out as LsaoPlan describes: depths (NaN on background) and
  /// O_k (NaN on background samples). A working array (working_memory.h).
  Buffer<float> buffer;
  /// lsao_sweep_simd, aligned sets with sampling = snap only (where lsao_gather_simd uses
  /// them): the geometry samples again, by rows (LsaoTexelRun); runs in buffer order.
  std::vector<LsaoTexelRun> texel_runs;
  std::unique_ptr<LsaoRecordArena> record_arena;  ///< where texel_runs' records are

  float value(int k, std::size_t i) const { return buffer[plan.value_index(k, i)]; }
  float depth(int li, std::size_t i) const { return buffer[plan.depth_index(li, i)]; }
};

/// The sweep phase: every line of every direction through the obscure hull.
LsaoSweep lsao_sweep(const GBuffer& g, const LsaoSettings& s, const RunOptions& options = {});

/// Samples farther than √((D_S/2)² + (D_L/2)²) (§5.1: "The K nearest obscuration values for
/// each screen pixel are found within the radius of √((D_S/2)² + (D_L/2)²)") plus this slack
/// never count for a pixel. The slack covers how far an evaluated sample can sit from its
/// place in the ideal lattice — snapping to a texel moves it by at most (0.5, 0.5) px, and an
/// aligned line sits at most half a lattice spacing (≤ 0.5 px) across from its ideal place
/// with its samples on texel centres — so √2/2 ≈ 0.707 px, rounded up: the nearest sample of
/// every direction is always within the radius (away from the image border).
constexpr double kLsaoGatherSlack = 0.75;

/// The gather radius of direction `d`, pixels.
inline double lsao_gather_radius(const SweepDirection& d, double line_spacing) {
  return std::hypot(0.5 * d.step_length(), 0.5 * line_spacing) + kLsaoGatherSlack;
}

/// The gather phase (§5.1): per pixel and direction, the nearest value within the gather
/// radius that passes the depth (and normal) test; A = 1 − their coverage-weighted average.
/// A direction without such a value is left out; if every direction is, the nearest values
/// within the radius are taken without the tests; a pixel with none gets 1.
Image lsao_gather(const GBuffer& g, const LsaoSettings& s, const LsaoSweep& sweep,
                  const RunOptions& options = {});

}  // namespace aolab
