// AO Lab core: screen-space ambient occlusion methods, scored against ray-traced AO.
//
// Principles (docs/conventions.md has the details):
// - Units. AO is ambient accessibility in [0, 1] (1 = unoccluded). View space is Blender's
//   camera space: x right, y up, the camera looks down -z. Depth is planar, d = -z > 0.
//   Pixel (i, j) has its centre at (i + 0.5, j + 0.5), row 0 at the top. Intrinsics fx, fy,
//   cx, cy are in pixels. The radius R is a view-space distance.
// - Background. Depth that is not finite, <= 0 or >= background_depth is no geometry: AO 1,
//   never an occluder, excluded from metrics.
// - Errors. Input is validated at the API boundary; invalid input throws
//   std::invalid_argument whose message starts with the parameter's name and ends with the
//   offending value. Internal invariants throw std::logic_error (core/base/check.h). Nothing here
//   calls exit or abort: the library runs inside Blender.
// - Threads. Heavy calls take a thread count (0 = all cores) and an optional Progress with
//   a cancel flag. Randomness is a pure function of (seed, pixel, stream), so results are
//   bit-identical for any thread count. No global mutable state: two computations can run
//   at once.
// - Memory. Inputs are non-owning views (ImageView), so callers' buffers (numpy arrays) are
//   used without copies; results are owning Images.
#pragma once

#include "core/base/camera.h"
#include "core/base/gbuffer.h"
#include "core/base/image.h"
#include "core/base/parallel.h"
#include "core/filters/blur.h"
#include "core/io/image_io.h"
#include "core/io/sidecar.h"
#include "core/methods/hbao/hbao.h"
#include "core/methods/registry.h"
#include "core/scenes/analytic_scenes.h"
#include "core/scoring/metrics.h"
#include "core/scoring/ssim.h"
