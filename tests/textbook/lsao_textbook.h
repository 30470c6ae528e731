// The brute-force line sweep: per receiver, every earlier sample of its line, in double
// precision, with the 2-D geometry rebuilt from view-space positions (no obscure hull, no
// cancellation-free shortcuts). It shares with core/methods/lsao/lsao.cpp only the layout — which
// samples a line visits (lsao_plan, lsao_line_samples) — so both look at the same points. The
// obscure hull of §4.1 must return the same largest occluder except in the degenerate cases the
// paper describes; tests/cpp/methods/lsao/lsao_test.cpp measures how often it does not and what
// that costs in the final AO (docs/methods/lsao.md, "The hull against brute force").
#pragma once

#include "core/base/gbuffer.h"
#include "core/base/image.h"
#include "core/methods/lsao/lsao.h"

namespace aolab {

/// The intermediate buffer of lsao_sweep computed by brute force: for each sample, the
/// earlier sample of its line with the largest hull criterion max(0, sin h − sin t)·ρ (with
/// the tangent the hull uses; ties go to the later, nearer sample, as the hull keeps them),
/// evaluated with eq. 1 and the obscurance tangent.
LsaoSweep lsao_textbook_sweep(const GBuffer& g, const LsaoSettings& settings);

/// The gather by brute force: for each pixel and direction, the nearest of all the
/// direction's samples within lsao_gather_radius that passes the depth (and normal) test,
/// instead of the few lines and steps around the pixel that lsao_gather looks at.
Image lsao_textbook_gather(const GBuffer& g, const LsaoSettings& settings, const LsaoSweep& sweep);

/// lsao_textbook_sweep followed by the library's gather: differs from aolab::lsao only where
/// the hull misses the largest occluder (and by float rounding).
Image lsao_textbook(const GBuffer& g, const LsaoSettings& settings);

}  // namespace aolab
