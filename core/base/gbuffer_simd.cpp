// prepared_normals_row in SIMD: every method that reads normals prepares them once per frame,
// and at 1280×720 the per-pixel scalar rule cost a visible part of a fast method's time.
// Bit for bit prepared_normal: the same IEEE operations in the same order (glm's length and
// dot are ((x·x + y·y) + z·z), the division by the length is a division), no fused
// multiply-adds; the lanes that are background or whose normal is unusable are redone by
// prepared_normal itself.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "core/base/gbuffer_simd.cpp"

#include <cstddef>

#include "core/base/gbuffer.h"
#include "core/base/simd-inl.h"

HWY_BEFORE_NAMESPACE();
namespace aolab::HWY_NAMESPACE {

void PreparedNormalsRow(const GBuffer& g, int y, float* HWY_RESTRICT out) {
  const DF df;
  const int w = g.width(), n = int(hn::Lanes(df));
  const float* depth = &g.depth(0, y);
  const bool interleaved = g.has_normal() && g.normal.channels == 3;
  const float* normal = interleaved ? &g.normal(0, y) : nullptr;
  const VF zero = hn::Zero(df), min_length = hn::Set(df, kMinNormalLength);
  const VF background = hn::Set(df, g.background_depth);
  const VF cx = hn::Set(df, g.camera.cx), cy = hn::Set(df, g.camera.cy);
  const VF fx = hn::Set(df, g.camera.fx), fy = hn::Set(df, g.camera.fy);
  const VF py = hn::Set(df, float(y) + 0.5f);
  int x = 0;
  if (interleaved && g.depth.channels == 1) {
    for (; x + n <= w; x += n) {
      const VF d = hn::LoadU(df, depth + x);
      VF nx, ny, nz;
      hn::LoadInterleaved3(df, normal + 3 * std::size_t(x), nx, ny, nz);
      // is_geometry: finite, > 0, < background (a NaN fails every comparison).
      const auto geometry =
          hn::And(hn::And(hn::IsFinite(d), hn::Gt(d, zero)), hn::Lt(d, background));
      const VF len = hn::Sqrt(hn::Add(hn::Add(hn::Mul(nx, nx), hn::Mul(ny, ny)), hn::Mul(nz, nz)));
      const auto usable = hn::And(geometry, hn::And(hn::IsFinite(len), hn::Ge(len, min_length)));
      nx = hn::Div(nx, len), ny = hn::Div(ny, len), nz = hn::Div(nz, len);
      // −P = −view_position(px, py, d) = (−((px − cx)/fx)·d, ((py − cy)/fy)·d, d).
      const VF px = hn::Add(hn::Iota(df, float(x)), hn::Set(df, 0.5f));
      const VF to_x = hn::Neg(hn::Mul(hn::Div(hn::Sub(px, cx), fx), d));
      const VF to_y = hn::Neg(hn::Mul(hn::Neg(hn::Div(hn::Sub(py, cy), fy)), d));
      const VF to_z = hn::Neg(hn::Neg(d));
      const VF facing = hn::Add(hn::Add(hn::Mul(nx, to_x), hn::Mul(ny, to_y)), hn::Mul(nz, to_z));
      const auto flip = hn::Lt(facing, zero);
      nx = hn::IfThenElse(flip, hn::Neg(nx), nx);
      ny = hn::IfThenElse(flip, hn::Neg(ny), ny);
      nz = hn::IfThenElse(flip, hn::Neg(nz), nz);
      float* o = out + 3 * std::size_t(x);
      hn::StoreInterleaved3(nx, ny, nz, df, o);
      if (!hn::AllTrue(df, usable)) {
        for (int i = 0; i < n; ++i) {
          const glm::vec3 p = prepared_normal(g, x + i, y);  // the exceptions, as the rule says
          o[3 * i] = p.x, o[3 * i + 1] = p.y, o[3 * i + 2] = p.z;
        }
      }
    }
  }
  for (; x < w; ++x) {
    const glm::vec3 p = prepared_normal(g, x, y);
    out[3 * x] = p.x, out[3 * x + 1] = p.y, out[3 * x + 2] = p.z;
  }
}

}  // namespace aolab::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace aolab {

HWY_EXPORT(PreparedNormalsRow);

void prepared_normals_row(const GBuffer& g, int y, float* out) {
  HWY_DYNAMIC_DISPATCH(PreparedNormalsRow)(g, y, out);
}

}  // namespace aolab
#endif  // HWY_ONCE
