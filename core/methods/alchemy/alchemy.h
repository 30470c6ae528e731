// Alchemy screen-space ambient obscurance: McGuire, Osman, Bukowski, Hennessy, "The Alchemy
// Screen-Space Ambient Obscurance Algorithm", HPG 2011.
//
// A = max(0, 1 − (2σ/s) Σ_{i=1..s} max(0, v_i·n̂ + z_C·β) / (v_i·v_i + ε))^k   (§3, the
// estimator): s taps P_i read from the depth buffer on the screen-space disc whose radius is
// the projection of the world-space radius r at C's depth, v_i = P_i − C, taps with
// |v_i| ≥ r dropped; z_C < 0 in the paper's camera space, so z_C·β subtracts β times C's
// depth. σ and ε are given here in units of r and r² (obscurance_estimator.h).
// docs/methods/alchemy.md gives the details.
#pragma once

#include "core/base/gbuffer.h"
#include "core/base/image.h"
#include "core/base/settings.h"
#include "core/horizon/obscurance_estimator.h"
#include "core/methods/registry.h"

namespace aolab {

/// s of the paper's Figure 1 (12 taps per pixel at 1280×720).
constexpr int kAlchemyDefaultSamples = 12;
/// β, the bias per unit of depth: 10⁻⁴, the paper's value as recalled (docs/methods/alchemy.md:
/// not checked against its text).
constexpr float kAlchemyDefaultBias = 1e-4f;
/// ε, in units of r²: 10⁻⁴ (at r = 1), the paper's value as recalled, likewise.
constexpr float kAlchemyDefaultEpsilon = 1e-4f;

struct AlchemySettings {
  /// r: radius of influence in view-space units (the reference's AO distance). [1e-12, 1e30].
  float radius = 1.0f;
  /// s: taps per pixel on the projected disc. [1, 98].
  int samples = kAlchemyDefaultSamples;
  /// τ: turns of the tap spiral; 0 = the SAO paper's low-discrepancy table for s. [0, 98].
  int turns = 0;
  /// σ: intensity, in units of r (the paper's σ at r = 1). [0, 100].
  float intensity = 1.0f;
  /// k: contrast, the exponent of the result. [0.1, 10].
  float contrast = 1.0f;
  /// β: bias per unit of depth; a tap counts only where v·n exceeds β·depth(C). [0, 1].
  float bias = kAlchemyDefaultBias;
  /// ε: added to v·v, in units of r² (the paper's ε at r = 1). [0, 1].
  float epsilon = kAlchemyDefaultEpsilon;
  /// ObscuranceFalloff: 0 alchemy (the paper's: taps beyond r dropped), 1 smooth (SAO's
  /// reference code's (1 − v·v/r²)³). [0, 1].
  int falloff = int(ObscuranceFalloff::Alchemy);
  /// Rotate the spiral by a random angle per pixel (the paper's per-pixel hash).
  bool random_rotation = true;
  /// Seed of the per-pixel rotation. [0, 2^31 - 1].
  int seed = 0;
};

inline const SettingField<AlchemySettings> kAlchemyFields[] = {
    {"radius", &AlchemySettings::radius, 1e-12, 1e30, "view-space units",
     "r, radius of influence (same as the reference's AO distance)"},
    {"samples", &AlchemySettings::samples, 1, kSpiralMaxSamples, "", "s, taps per pixel"},
    {"turns", &AlchemySettings::turns, 0, kSpiralMaxSamples, "",
     "turns of the tap spiral; 0 = the SAO paper's low-discrepancy table"},
    {"intensity", &AlchemySettings::intensity, 0, 100, "units of r", "sigma, intensity"},
    {"contrast", &AlchemySettings::contrast, 0.1, 10, "", "k, contrast (exponent of the result)"},
    {"bias", &AlchemySettings::bias, 0, 1, "per unit of depth",
     "beta: a tap counts where v.n exceeds beta times the pixel's depth"},
    {"epsilon", &AlchemySettings::epsilon, 0, 1, "units of r^2",
     "epsilon added to v.v (keeps close taps finite)"},
    {"falloff", &AlchemySettings::falloff, 0, 1, "",
     "alchemy: taps beyond r dropped (the paper's); smooth: (1 - v.v/r^2)^3 (SAO's reference "
     "code)",
     "alchemy|smooth"},
    {"random_rotation", &AlchemySettings::random_rotation, 0, 1, "",
     "rotate the tap spiral randomly per pixel"},
    {"seed", &AlchemySettings::seed, 0, 2147483647, "", "seed of the per-pixel randomness"},
};

/// Alchemy AO of a G-buffer with normals. Returns a 1-channel image in [0, 1]; background = 1.
/// Throws std::invalid_argument for invalid settings, a G-buffer without normals or an
/// invalid G-buffer; Cancelled if cancelled.
Image alchemy(const GBuffer& g, const AlchemySettings& settings, const RunOptions& options = {});

/// The registry entry.
Method alchemy_method();

}  // namespace aolab
