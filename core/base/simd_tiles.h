// The tiles the SIMD kernels run their frame in, beside the SIMD preamble (simd-inl.h): written
// once here, not in every kernel. Included by a kernel's HWY_ONCE part (its dispatch), which is
// compiled once, so it is an ordinary header.
#pragma once

#include "core/base/image.h"
#include "core/base/parallel.h"

namespace aolab {

/// Tiles of 16 rows × 128 columns: the depth that a tile's samples read (±R around it, about
/// 270 × 160 texels at R ≈ 70 px) fits a core's 512 KiB L2, where ±R rows of the whole width
/// do not. Measured on `blocks` with HBAO at R = 0.25 it makes no difference (the kernel is
/// bound by arithmetic there); it keeps large radii from becoming bound by memory. 128 columns
/// are a multiple of every vector length, so a row is cut into vectors at the same places
/// whatever the tile (image_from_tiles).
constexpr int kSimdBandRows = 16;
constexpr int kSimdTileColumns = 128;

/// A kernel's frame in kSimdBandRows × kSimdTileColumns tiles on `threads` threads (0 = all
/// cores): span(y, x0, x1, out_row) fills out_row[x0, x1) of row y, typically by
/// HWY_DYNAMIC_DISPATCH of the kernel's per-target span. The image starts at 1 (background);
/// adds `height` rows to progress->total.
template <class Span>
Image image_from_simd_tiles(int width, int height, int threads, Progress* progress, Span span) {
  return image_from_tiles(
      width, height, threads, progress, kSimdBandRows, kSimdTileColumns, [] { return 0; },
      [&](int, int y, int x0, int x1, float* out) { span(y, x0, x1, out); });
}

}  // namespace aolab
