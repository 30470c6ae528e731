// The straightforward HBAO: one thread, double precision, the paper's formulas with their
// trigonometry (α = atan(D.z/|D.xy|), sin h - sin t, or the cosine band from the angles
// themselves), positions reconstructed per sample.
// It shares only the per-pixel sampling pattern with core/methods/hbao/hbao.cpp (so both read the
// same texels). The textbook version the fast implementation is tested against, and the baseline
// of its speed.
#pragma once

#include "core/base/gbuffer.h"
#include "core/base/image.h"
#include "core/methods/hbao/hbao.h"

namespace aolab {

Image hbao_textbook(const GBuffer& g, const HbaoSettings& settings);

}  // namespace aolab
