// Visibility bitmask AO: Therrien, Levesque, Gilet, "Screen Space Indirect Lighting with
// Visibility Bitmask" (arXiv 2301.11376, 2023; The Visual Computer). GTAO's slices around the
// per-pixel view vector (Jimenez et al. 2016, §4; the set-up is shared, core/horizon/slice.h), but
// each slice keeps a bitmask of N sectors of equal angle over the hemisphere around the
// projected normal instead of two horizon angles (the paper's §3). Each sample S marks the
// sectors between its front angle (the direction of S) and its back angle (the direction of S
// moved away from the camera by a constant thickness), so a thin occluder shadows only the
// sectors it covers and light passes behind it. A slice's visibility is its free sectors: the
// paper's fraction 1 − bitCount/N (Algorithm 1), or each sector weighted by its exact share of
// the cosine-weighted slice integral (GTAO's eq. 7 between the sector's edges). The slices
// are weighted by |proj n| (GTAO's eq. 8) and divided by the unoccluded sum of the same
// slices. docs/methods/bitmask.md gives every step.
#pragma once

#include "core/base/gbuffer.h"
#include "core/base/image.h"
#include "core/base/settings.h"
#include "core/methods/registry.h"

namespace aolab {

/// Slices per pixel and steps per side of Blender 4.2 EEVEE's horizon scan, which implements
/// the paper: 2 slices per pixel (its `slice_len`) and its default step count of 8
/// (`fast_gi_step_count`). The paper does not fix sample counts.
constexpr int kBitmaskDefaultSlices = 2;
constexpr int kBitmaskDefaultSteps = 8;

/// Sectors per slice: the paper's 32, one bit of a 32-bit uint each (also EEVEE's and the
/// authors' published code). Up to 64 here (a 64-bit mask).
constexpr int kBitmaskDefaultSectors = 32;
constexpr int kBitmaskMaxSectors = 64;

/// The constant thickness of every surface, as a fraction of R (so the result depends only on
/// geometry relative to R, as for every method here). The paper gives no value; on the
/// `room` reference scene the error is flat between 0.25 R and 0.5 R and grows outside
/// (MAE 0.076 / 0.068 / 0.068 / 0.077 at 0.1 / 0.25 / 0.5 / 1 R, docs/methods/bitmask.md).
/// 1e30 stands for unbounded (a height field, as GTAO).
constexpr float kBitmaskDefaultThickness = 0.5f;
constexpr float kBitmaskUnboundedThickness = 1e30f;

/// Along which line a sample's back point lies behind it.
enum class BitmaskBackDirection : int {
  /// Along P's view vector, B = S − T·v (the paper's Algorithm 1 and the authors' code): the
  /// same direction for every sample of the pixel, exact for samples near P.
  View = 0,
  /// Along the sample's own view ray, B = S + T·S/|S| (EEVEE's horizon scan): where the solid
  /// hidden behind a depth-buffer texel actually lies, so that with an unbounded thickness
  /// and the sphere clip an overhang occludes only the directions that reach it within R.
  SampleRay = 1,
};

/// How a slice's free sectors are counted.
enum class BitmaskWeighting : int {
  /// The paper's (Algorithm 1): the fraction of free sectors, 1 − bitCount(b)/N. Sectors of
  /// equal angle count alike, so directions near the tangent weigh as much as those along
  /// the normal: not the cosine-weighted AO of the reference.
  Uniform = 0,
  /// Each free sector weighted by its exact share of the cosine-weighted slice integral,
  /// ∫ cos(θ − n)|sin θ| dθ between its edges (GTAO's eq. 7 at both edges); with an
  /// unbounded thickness this is GTAO up to the sector quantisation.
  Cosine = 1,
};

/// Which sectors a sample's interval [front, back] of slice angles marks (the authors'
/// published code offers ceil, round and floor of the interval's width in sectors).
enum class BitmaskRounding : int {
  /// Every sector the interval touches (ceil; the paper's Algorithm 1).
  Touch = 0,
  /// Every sector whose centre lies in the interval (round).
  Half = 1,
  /// Every sector the interval covers entirely (floor).
  Cover = 2,
};

/// What the radius R bounds besides the march.
enum class BitmaskRadiusClip : int {
  /// Nothing: every sample within the projected radius marks its sectors (the paper's).
  None = 0,
  /// A sample farther than R from P is ignored (GTAO's hard cut at R).
  Cut = 1,
  /// The segment from a sample's front to its back is clipped to the sphere of radius R
  /// around P (EEVEE's horizon scan), so only occluders within R occlude, as in Cycles.
  Sphere = 2,
};

/// How the slices' sum is turned into visibility.
enum class BitmaskNormalization : int {
  /// Σ_k |proj n|·V_k / Σ_k |proj n|·U_k, U_k the same slice with no sector marked (GTAO's
  /// `unoccluded`; with uniform weighting the |proj n|-weighted mean of EEVEE). Exactly 1 on
  /// open planes.
  Unoccluded = 0,
  /// The mean over the slices of each slice's own estimate: the paper's mean of the free
  /// fractions (uniform weighting), or the memo's (1/N) Σ |proj n|·V_k (cosine weighting, not
  /// 1 on tilted planes; clamped).
  Slices = 1,
};

struct BitmaskSettings {
  /// R: radius of influence in view-space units (the reference's AO distance). [1e-12, 1e30].
  float radius = 1.0f;
  /// Slices per pixel: screen-space directions spread over a half turn, φ_k = π(k + u)/N. [1, 64].
  int slices = kBitmaskDefaultSlices;
  /// Samples per side of each slice, equally spaced over the projected radius. [1, 512].
  int steps = kBitmaskDefaultSteps;
  /// N: sectors of equal angle over the hemisphere of each slice. [1, 64].
  int sectors = kBitmaskDefaultSectors;
  /// The paper's constant thickness, as a fraction of R: a sample's back point lies this far
  /// behind it along the view ray. 0 = the sample's own direction only, 1e30 = unbounded (a
  /// height field). [0, 1e30].
  float thickness = kBitmaskDefaultThickness;
  /// BitmaskBackDirection: 0 view (the paper's, along P's view vector), 1 sample_ray (EEVEE's,
  /// along the sample's own view ray).
  int back_direction = int(BitmaskBackDirection::View);
  /// BitmaskWeighting: 0 uniform (the paper's fraction of free sectors), 1 cosine (each sector
  /// weighted by its exact cosine-weighted measure).
  int weighting = int(BitmaskWeighting::Uniform);
  /// BitmaskRounding: 0 touch (the paper's), 1 half, 2 cover.
  int rounding = int(BitmaskRounding::Touch);
  /// BitmaskRadiusClip: 0 none (the paper's), 1 cut (GTAO's), 2 sphere (EEVEE's).
  int radius_clip = int(BitmaskRadiusClip::None);
  /// BitmaskNormalization: 0 unoccluded (exact on planes), 1 slices (the paper's mean).
  int normalization = int(BitmaskNormalization::Unoccluded);
  /// Rotate the slices by a random fraction u of their spacing per pixel; off: u = 0.
  bool random_rotation = true;
  /// Jitter the samples per pixel: sample i at (i − w)·step, w ∈ [0, 1); off: at i·step.
  bool jitter = true;
  /// Seed of the per-pixel random rotation and jitter. [0, 2^31 - 1].
  int seed = 0;
  /// q, in pixels: far samples read the depth MIP chain, as HBAO's (HbaoSettings::mip_distance):
  /// a sample r ≥ 2q pixels from P snaps to the pixel of its 2^l block, l = min(floor(log2(r/q)),
  /// 5), and reads that pixel's exact depth from level l. 0: full resolution, as in the paper.
  /// [0, 4096].
  float mip_distance = 0.0f;
};

inline const SettingField<BitmaskSettings> kBitmaskFields[] = {
    {"radius", &BitmaskSettings::radius, 1e-12, 1e30, "view-space units",
     "R, radius of influence (same as the reference's AO distance)"},
    {"slices", &BitmaskSettings::slices, 1, 64, "",
     "slices per pixel (screen directions over a half turn)"},
    {"steps", &BitmaskSettings::steps, 1, 512, "", "samples per side of each slice"},
    {"sectors", &BitmaskSettings::sectors, 1, kBitmaskMaxSectors, "",
     "N, sectors of equal angle over each slice's hemisphere (bits of the mask)"},
    {"thickness", &BitmaskSettings::thickness, 0, double(kBitmaskUnboundedThickness),
     "fraction of R",
     "constant thickness behind every sample along its view ray; 1e30 = unbounded (height "
     "field)"},
    {"back_direction", &BitmaskSettings::back_direction, 0, 1, "",
     "line of a sample's back point: P's view vector (the paper's) or the sample's own view "
     "ray",
     "view|sample_ray"},
    {"weighting", &BitmaskSettings::weighting, 0, 1, "",
     "free sectors counted alike (the paper's 1 - bitCount/N) or each by its exact "
     "cosine-weighted measure",
     "uniform|cosine"},
    {"rounding", &BitmaskSettings::rounding, 0, 2, "",
     "sectors a sample marks: every one its interval touches (the paper's), whose centre it "
     "holds, or that it covers",
     "touch|half|cover"},
    {"radius_clip", &BitmaskSettings::radius_clip, 0, 2, "",
     "R beyond the march: none (the paper's), ignore samples beyond R, or clip each "
     "front-to-back segment to the sphere of radius R",
     "none|cut|sphere"},
    {"normalization", &BitmaskSettings::normalization, 0, 1, "",
     "divide the sum weighted by the projected normal by the unoccluded one (exact on "
     "planes) or average the slices (the paper's)",
     "unoccluded|slices"},
    {"random_rotation", &BitmaskSettings::random_rotation, 0, 1, "",
     "rotate the slices randomly per pixel"},
    {"jitter", &BitmaskSettings::jitter, 0, 1, "", "jitter the sample offsets randomly per pixel"},
    {"seed", &BitmaskSettings::seed, 0, 2147483647, "", "seed of the per-pixel randomness"},
    {"mip_distance", &BitmaskSettings::mip_distance, 0, 4096, "px",
     "q: a sample r >= 2q px away reads the depth MIP level floor(log2(r/q)) (at most 5), "
     "snapped to a pixel of that level, which keeps large radii in the cache; 0 = full "
     "resolution everywhere, as in the paper"},
};

/// Visibility bitmask AO of a G-buffer with normals. Returns a 1-channel image in [0, 1];
/// background = 1. Throws std::invalid_argument for invalid settings, a G-buffer without
/// normals or an invalid G-buffer; Cancelled if cancelled.
Image bitmask(const GBuffer& g, const BitmaskSettings& settings, const RunOptions& options = {});

/// The registry entry.
Method bitmask_method();

}  // namespace aolab
