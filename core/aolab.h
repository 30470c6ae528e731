// AO Lab core: screen-space ambient occlusion methods, scored against ray-traced AO.
// Including this header gives the whole public C++ API.
//
// Layers (docs/architecture.md); each uses only the layers above it in this list:
// - core/base/      checks that throw (check.h), images and strided views (image.h), setting
//                   tables (settings.h), row-parallel loops with progress and cancellation
//                   (parallel.h), pinhole intrinsics (camera.h), the G-buffer and the
//                   background rule (gbuffer.h), the SIMD target in use (simd_target.h),
//                   the cache of large working arrays (working_memory.h), the depth MIP
//                   chain for far samples (depth_mip.h), how a computation runs (threads,
//                   progress, kernel: run_options.h), the SIMD kernels' tiles (simd_tiles.h).
// - core/sampling/  counter-based random numbers (random.h), per-frame seeds (frame_seed.h),
//                   blue noise (blue_noise.h), rotation-aware Poisson-disk sets
//                   (poisson_disk.h).
// - core/io/        Blender multilayer EXR G-buffers and AO images (image_io.h), the camera
//                   sidecar JSON (sidecar.h), durable writes and regular-file checks
//                   (files.h).
// - core/scoring/   MAE, RMSE, PSNR, bias and SSIM against a reference (metrics.h, ssim.h).
// - core/filters/   the separable Gaussian applied after a method (blur.h), temporal
//                   accumulation over frames (temporal.h; temporal_pixel.h: its per-pixel
//                   step, the oracle of its SIMD kernel).
// - core/scenes/    analytic scenes with closed-form Cycles AO (analytic_scenes.h).
// - core/horizon/   what the horizon-based methods share: the receiver and its tangent-plane
//                   test (receiver.h), the directions (directions.h), the frame and step
//                   (frame.h), GTAO's slice (slice.h), the obscurance estimator of Alchemy AO
//                   and SAO (obscurance_estimator.h, obscurance_simd.h).
// - core/volumetric/ what VAO and VAO++ share: sample sets, pipes and the per-pixel sums
//                   (pipes.h), their SIMD kernel (pipes_simd.h).
// - core/methods/   the registry (registry.h: every method by name, with its settings table)
//                   and one folder per method; a method's helpers in its folder are private,
//                   and a method includes no other method's folder.
// The Python bindings (core/python/) and the Blender add-on sit on top; nothing here knows
// of Python or Blender.
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
//   offending value. Internal invariants throw std::logic_error (core/base/check.h). Nothing
//   here calls exit or abort: the library runs inside Blender.
// - Threads. Heavy calls take a thread count (0 = all cores) and an optional Progress with
//   a cancel flag. Randomness is a pure function of (seed, pixel, stream), so results are
//   bit-identical for any thread count. No global mutable state but the working-memory
//   cache, which a mutex guards: two computations can run at once.
// - Memory. Inputs are non-owning views (ImageView), so callers' buffers (numpy arrays) are
//   used without copies; results are owning Images. Every large array, results included,
//   comes from a process-wide cache that keeps it for the next frame (working_memory.h):
//   fresh pages would cost a page fault per 4 KiB every frame.
#pragma once

// core/base
#include "core/base/camera.h"
#include "core/base/check.h"
#include "core/base/depth_mip.h"
#include "core/base/gbuffer.h"
#include "core/base/image.h"
#include "core/base/parallel.h"
#include "core/base/run_options.h"
#include "core/base/settings.h"
#include "core/base/simd_target.h"
#include "core/base/simd_tiles.h"
#include "core/base/triangle_mesh.h"
#include "core/base/working_memory.h"

// core/sampling
#include "core/sampling/blue_noise.h"
#include "core/sampling/cosine_hemisphere.h"
#include "core/sampling/frame_seed.h"
#include "core/sampling/poisson_disk.h"
#include "core/sampling/random.h"

// core/io
#include "core/io/files.h"
#include "core/io/image_io.h"
#include "core/io/sidecar.h"

// core/scoring
#include "core/scoring/metrics.h"
#include "core/scoring/ssim.h"

// core/filters
#include "core/filters/blur.h"
#include "core/filters/temporal.h"
#include "core/filters/temporal_pixel.h"

// core/scenes
#include "core/scenes/analytic_scenes.h"

// core/horizon: what the horizon-based methods share
#include "core/horizon/directions.h"
#include "core/horizon/frame.h"
#include "core/horizon/obscurance_estimator.h"
#include "core/horizon/obscurance_simd.h"
#include "core/horizon/receiver.h"
#include "core/horizon/slice.h"

// core/volumetric: what VAO and VAO++ share
#include "core/volumetric/pipes.h"
#include "core/volumetric/pipes_simd.h"

// core/methods: the registry and every method
#include "core/methods/alchemy/alchemy.h"
#include "core/methods/bitmask/bitmask.h"
#include "core/methods/chebyshev/chebyshev.h"
#include "core/methods/crytek_ssao/crytek_ssao.h"
#include "core/methods/gtao/gtao.h"
#include "core/methods/hbao/hbao.h"
#include "core/methods/lsao/lsao.h"
#include "core/methods/pyramid_hbao/pyramid_hbao.h"
#include "core/methods/registry.h"
#include "core/methods/sao/sao.h"
#include "core/methods/screen_space_limit/screen_space_limit.h"
#include "core/methods/vao/vao.h"
#include "core/methods/vao_pp/vao_pp.h"

// core/raytracing: rtao, the ray-traced peer (Embree), not a screen-space method
#include "core/raytracing/ray_scene.h"
#include "core/raytracing/rtao.h"
