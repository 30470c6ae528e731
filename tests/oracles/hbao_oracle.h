// The straightforward HBAO: one thread, double precision, the paper's formulas with their
// trigonometry (α = atan(D.z/|D.xy|), sin h - sin t), positions reconstructed per sample.
// It shares only the per-pixel sampling pattern with core/hbao.cpp (so both read the same
// texels). It is the test oracle of the fast implementation and the baseline of its speed.
#pragma once

#include "core/gbuffer.h"
#include "core/hbao.h"
#include "core/image.h"

namespace aolab {

Image hbao_oracle(const GBuffer& g, const HbaoSettings& settings);

}  // namespace aolab
