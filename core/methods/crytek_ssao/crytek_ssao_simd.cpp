// Crytek SSAO's SIMD kernel: the scalar per-pixel code of crytek_ssao.cpp (the oracle it is
// tested against) on Lanes consecutive pixels of a row at once, compiled by Highway for every
// target and dispatched at run time. Every setting is supported; each lane takes the scalar
// pixel's points in the same order, so the two differ only by float rounding.
//
// What it does differently (docs/methods/crytek_ssao.md, "SIMD kernel"):
// - the projection is rewritten so that a point costs one reciprocal and no division: with
//   D = d − R·o_z the point's depth, its pixel is ((x+½)·d + u, (y+½)·d + v) / D, where
//   u = R·(f_x·o_x − c_x·o_z) and v = −R·(f_y·o_y + c_y·o_z) depend on the reflected offset o
//   alone; D itself is the scalar code's bits;
// - with the 4×4 tiled reflection (and without any), o depends on the pixel only through
//   (x mod 4, y mod 4): the reflected kernel's u, v, R·o_z and o are made once per frame, in
//   the scalar code's own float operations, for the 4 × 4 phases, and a row's vectors load
//   them (4 columns repeated across the vector: its lanes are pixels x0 .. x0 + Lanes − 1 with
//   x0 a multiple of 4); the per-pixel reflection computes them per lane from the kernel's
//   u, v, R·k_z by linearity (o = k − 2(k·r)r, so u(o) = u(k) − 2(k·r)·u(r));
// - the texel's index comes from Floor and the float's bits (x + 2^23 holds the integer x in
//   its low mantissa bits), which costs less than a float-to-int conversion and its
//   overflow fix-ups; only on-image lanes use it;
// - the depth is read where the G-buffer holds it, each read tested for background
//   (is_geometry), instead of a copy of it with background as NaN, which cost more (an
//   allocation of the image's size, its page faults and a pass) than the tests;
// - the range check multiplies by 1/R where the scalar code divides by R;
// - every test is a mask and the depth read a gather: no branch per point.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "core/methods/crytek_ssao/crytek_ssao_simd.cpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <glm/geometric.hpp>
#include <limits>
#include <numbers>
#include <vector>

#include "core/base/parallel.h"
#include "core/base/simd-inl.h"
#include "core/base/simd_tiles.h"
#include "core/methods/crytek_ssao/crytek_ssao.h"
#include "core/methods/crytek_ssao/crytek_ssao_shared.h"

#ifndef AOLAB_CRYTEK_SSAO_SIMD_ONCE_
#define AOLAB_CRYTEK_SSAO_SIMD_ONCE_
namespace aolab {
namespace {

// What a point of the kernel costs per pixel, made once per frame (see the file comment).
struct CrytekTables {
  int samples = 0;
  // Tiled4x4 and None: [row phase y & 3][sample][component][column phase x & 3], the
  // components being u, v, R·o_z, o_x, o_y, o_z of the reflected offset o.
  std::vector<float> reflected;
  // Every rotation: [sample][component], the components being k_x, k_y, k_z, u(k), v(k),
  // R·k_z (the per-lane path: the per-pixel reflection, and vectors too short for a period of
  // the tile).
  std::vector<float> kernel;
  // Tiled4x4: the 16 reflection vectors, [y & 3][x & 3][component]; None: zeros.
  float tile[16][3] = {};
};
constexpr int kReflectedComponents = 6;
constexpr int kKernelComponents = 6;

// What the kernel reads: the G-buffer's depth as it is (row_stride floats a row), the
// prepared normals (3 per pixel, rows of width) or null.
struct CrytekSimdFrame {
  const float* depth;
  std::ptrdiff_t stride;
  const float* normals;
  int width, height;
  CameraIntrinsics cam;
  float background;  // GBuffer::background_depth
};

}  // namespace
}  // namespace aolab
#endif  // AOLAB_CRYTEK_SSAO_SIMD_ONCE_

HWY_BEFORE_NAMESPACE();
namespace aolab::HWY_NAMESPACE {
namespace {

// What every point of a row shares.
struct RowConstants {
  VF width, height, radius, inv_radius, background;
  VI stride, index_bias;
  const float* depth;
};

// 2^23: for an integer 0 ≤ i < 2^23, the float i + 2^23 holds i in its low mantissa bits.
constexpr float kMagic = 8388608.0f;
constexpr std::uint32_t kMagicBits = 0x4B000000u;

// The pixels' part of a point's test.
struct Pixels {
  VF d, px, py;
};

// One point on every lane: u, v, w = R·o_z of its offset (already on the normal's side).
// Adds its weight w(Δ) to `occluded` where it is occluded (crytek_pixel's loop body).
template <CrytekSsaoRangeCheck kRange>
HWY_INLINE void AddPoint(DF df, const RowConstants& k, const Pixels& p, VF u, VF v, VF w,
                         VF& occluded) {
  const DI di;
  const VF zero = hn::Zero(df);
  const VF depth = hn::Sub(p.d, w);  // −sp.z of the scalar code, the same bits
  // Where depth ≤ 0 (at or behind the camera plane) the reciprocal is not used.
  const VF inv = hn::Div(hn::Set(df, 1.0f), depth);
  const VF qx = hn::Mul(hn::MulAdd(p.px, p.d, u), inv);
  const VF qy = hn::Mul(hn::MulAdd(p.py, p.d, v), inv);
  // In front of the camera and on the image (NaN, from background P, fails every test).
  const MF inside =
      hn::And(hn::And(hn::Gt(depth, zero), hn::And(hn::Ge(qx, zero), hn::Lt(qx, k.width))),
              hn::And(hn::Ge(qy, zero), hn::Lt(qy, k.height)));
  // The texel (the scalar code's truncation, qx and qy ≥ 0): the bits of floor(q) + 2^23 are
  // those of 2^23 plus floor(q), whose bias index_bias removes.
  const VI bx = hn::BitCast(di, hn::Add(hn::Floor(qx), hn::Set(df, kMagic)));
  const VI by = hn::BitCast(di, hn::Add(hn::Floor(qy), hn::Set(df, kMagic)));
  const VI index = hn::Sub(hn::Add(hn::Mul(by, k.stride), bx), k.index_bias);
  const VF stored =
      hn::GatherIndex(df, k.depth, hn::IfThenElseZero(hn::RebindMask(di, inside), index));
  const VF delta = hn::Sub(depth, stored);  // > 0: the stored surface is in front of the point
  // Occluded: the stored surface is in front of the point (delta > 0, i.e. stored < depth)
  // and is geometry (is_geometry: 0 < stored < background; NaN fails).
  const MF counts =
      hn::And(hn::And(inside, hn::Gt(stored, zero)), hn::Lt(stored, hn::Min(depth, k.background)));
  VF weight;
  if constexpr (kRange == CrytekSsaoRangeCheck::Smooth) {
    weight = hn::Min(hn::Max(hn::NegMulAdd(delta, k.inv_radius, hn::Set(df, 2.0f)), zero),
                     hn::Set(df, 1.0f));
  } else if constexpr (kRange == CrytekSsaoRangeCheck::Hard) {
    weight = hn::IfThenElseZero(hn::Lt(delta, k.radius), hn::Set(df, 1.0f));
  } else {
    weight = hn::Set(df, 1.0f);
  }
  occluded = hn::Add(occluded, hn::IfThenElseZero(counts, weight));
}

// −v where o·n < 0 (the hemisphere variant's flip), else v.
HWY_INLINE VF FlipWhere(VF sign, VF v) { return hn::Xor(v, sign); }

// The sign bit where o·n < 0, else 0.
HWY_INLINE VF FlipSign(DF df, VF dot) {
  return hn::And(hn::VecFromMask(df, hn::Lt(dot, hn::Zero(df))), hn::Set(df, -0.0f));
}

// Occluded weight of every lane's points, the reflected kernel read from the tables (tiled
// and no reflection). row_table: the row phase's [sample][component][4 column phases].
template <CrytekSsaoRangeCheck kRange, bool kHemisphere>
HWY_INLINE VF OccludedTabled(DF df, const RowConstants& k, const Pixels& p, int samples,
                             const float* HWY_RESTRICT row_table, VF nx, VF ny, VF nz) {
  VF occluded = hn::Zero(df);
  for (int i = 0; i < samples; ++i) {
    const float* t = row_table + std::size_t(i) * kReflectedComponents * 4;
    VF u = hn::LoadDup128(df, t), v = hn::LoadDup128(df, t + 4), w = hn::LoadDup128(df, t + 8);
    if constexpr (kHemisphere) {
      const VF dot = hn::MulAdd(
          hn::LoadDup128(df, t + 20), nz,
          hn::MulAdd(hn::LoadDup128(df, t + 16), ny, hn::Mul(hn::LoadDup128(df, t + 12), nx)));
      const VF sign = FlipSign(df, dot);
      u = FlipWhere(sign, u), v = FlipWhere(sign, v), w = FlipWhere(sign, w);
    }
    AddPoint<kRange>(df, k, p, u, v, w, occluded);
  }
  return occluded;
}

// The same with a reflection vector r per lane (per-pixel reflection): o = k − 2(k·r)r, and
// u, v, R·o_z by linearity from the kernel's and r's.
template <CrytekSsaoRangeCheck kRange, bool kHemisphere>
HWY_INLINE VF OccludedPerLane(DF df, const RowConstants& k, const Pixels& p, int samples,
                              const float* HWY_RESTRICT kernel, VF rx, VF ry, VF rz, VF ur, VF vr,
                              VF wr, VF nx, VF ny, VF nz) {
  VF occluded = hn::Zero(df);
  const VF rx2 = hn::Add(rx, rx), ry2 = hn::Add(ry, ry), rz2 = hn::Add(rz, rz);
  const VF r_n = hn::MulAdd(rz, nz, hn::MulAdd(ry, ny, hn::Mul(rx, nx)));
  for (int i = 0; i < samples; ++i) {
    const float* c = kernel + std::size_t(i) * kKernelComponents;
    const VF kx = hn::Set(df, c[0]), ky = hn::Set(df, c[1]), kz = hn::Set(df, c[2]);
    const VF t = hn::MulAdd(kz, rz2, hn::MulAdd(ky, ry2, hn::Mul(kx, rx2)));  // 2 k·r
    VF u = hn::NegMulAdd(t, ur, hn::Set(df, c[3]));
    VF v = hn::NegMulAdd(t, vr, hn::Set(df, c[4]));
    VF w = hn::NegMulAdd(t, wr, hn::Set(df, c[5]));
    if constexpr (kHemisphere) {
      const VF k_n = hn::MulAdd(kz, nz, hn::MulAdd(ky, ny, hn::Mul(kx, nx)));
      const VF sign = FlipSign(df, hn::NegMulAdd(t, r_n, k_n));  // o·n
      u = FlipWhere(sign, u), v = FlipWhere(sign, v), w = FlipWhere(sign, w);
    }
    AddPoint<kRange>(df, k, p, u, v, w, occluded);
  }
  return occluded;
}

template <CrytekSsaoRangeCheck kRange, bool kHemisphere>
void SpanT(const CrytekSimdFrame& f, const CrytekSsaoSettings& s, const CrytekTables& tables, int y,
           int x_begin, int x_end, float* HWY_RESTRICT out) {
  const DF df;
  const DI di;
  const int w = f.width;
  RowConstants k;
  k.width = hn::Set(df, float(w)), k.height = hn::Set(df, float(f.height));
  k.radius = hn::Set(df, s.radius), k.inv_radius = hn::Set(df, 1.0f / s.radius);
  k.background = hn::Set(df, f.background);
  k.stride = hn::Set(di, std::int32_t(f.stride));
  // kMagicBits·(stride + 1), wrapped to 32 bits as the vector arithmetic wraps.
  k.index_bias = hn::Set(di, std::int32_t(kMagicBits * (std::uint32_t(f.stride) + 1u)));
  k.depth = f.depth;
  const float* depth_row = f.depth + std::size_t(y) * std::size_t(f.stride);
  const float* normal_row = kHemisphere ? f.normals + 3 * std::size_t(y) * w : nullptr;
  const bool per_pixel = s.rotation == int(CrytekSsaoRotation::PerPixel);
  // The tables hold a row phase's 4 columns; a vector of a multiple of 4 lanes starting at a
  // multiple of its length repeats them. Shorter vectors (Highway's 1-lane scalar target)
  // take the per-lane path with the tile's vectors.
  const bool tabled = !per_pixel && hn::Lanes(df) % 4 == 0;
  const float* row_table = tabled ? tables.reflected.data() + std::size_t(y & 3) * tables.samples *
                                                                  kReflectedComponents * 4
                                  : nullptr;
  const float radius = s.radius;
  const float fx_r = f.cam.fx * radius, fy_r = f.cam.fy * radius;
  const float cx_r = f.cam.cx * radius, cy_r = f.cam.cy * radius;
  const VF count_n = hn::Set(df, float(tables.samples));
  const bool rescaled = s.output == int(CrytekSsaoOutput::Rescaled);
  const auto seed = std::uint32_t(s.seed);

  ForEachSpanVector(df, x_begin, x_end, [&](int x0, int count) {
    Pixels p;
    p.d = LoadRowPart(df, depth_row + x0, count);
    // is_geometry; background lanes get NaN, which fails every test of their points.
    const MF geometry = hn::And(hn::Gt(p.d, hn::Zero(df)), hn::Lt(p.d, k.background));
    p.d = hn::IfThenElse(geometry, p.d, hn::Set(df, std::numeric_limits<float>::quiet_NaN()));
    VF result = hn::Set(df, 1.0f);
    if (!hn::AllFalse(df, geometry)) {
      p.px = PixelCentres(df, x0), p.py = hn::Set(df, float(y) + 0.5f);
      VF nx = hn::Zero(df), ny = nx, nz = nx;
      if constexpr (kHemisphere) {
        if (count == int(hn::Lanes(df))) {
          hn::LoadInterleaved3(df, normal_row + 3 * std::size_t(x0), nx, ny, nz);
        } else {
          HWY_ALIGN float n[3][hn::MaxLanes(df)];
          for (int i = 0; i < int(hn::Lanes(df)); ++i)
            for (int c = 0; c < 3; ++c)
              n[c][i] = normal_row[3 * std::size_t(x0 + std::min(i, count - 1)) + c];
          nx = hn::Load(df, n[0]), ny = hn::Load(df, n[1]), nz = hn::Load(df, n[2]);
        }
      }
      VF occluded;
      if (!tabled) {
        VF rx, ry, rz;
        if (per_pixel) {
          // random_unit(seed, x, y, kCrytekSsaoPixelStream) on every lane.
          const VF u1 = PixelRandom(df, seed, x0, y, kCrytekSsaoPixelStream);
          const VF u2 = PixelRandom(df, seed, x0, y, kCrytekSsaoPixelStream + 1);
          rz = hn::Sub(hn::Mul(hn::Set(df, 2.0f), u1), hn::Set(df, 1.0f));
          const VF rr = hn::Sqrt(hn::Max(hn::Zero(df), hn::NegMulAdd(rz, rz, hn::Set(df, 1.0f))));
          const VF phi = hn::Mul(hn::Set(df, 2.0f * std::numbers::pi_v<float>), u2);
          rx = hn::Mul(rr, hn::Cos(df, phi)), ry = hn::Mul(rr, hn::Sin(df, phi));
        } else {
          HWY_ALIGN float r[3][hn::MaxLanes(df)];
          for (int i = 0; i < int(hn::Lanes(df)); ++i)
            for (int c = 0; c < 3; ++c) r[c][i] = tables.tile[4 * (y & 3) + ((x0 + i) & 3)][c];
          rx = hn::Load(df, r[0]), ry = hn::Load(df, r[1]), rz = hn::Load(df, r[2]);
        }
        const VF ur = hn::MulSub(hn::Set(df, fx_r), rx, hn::Mul(hn::Set(df, cx_r), rz));
        const VF vr = hn::Neg(hn::MulAdd(hn::Set(df, fy_r), ry, hn::Mul(hn::Set(df, cy_r), rz)));
        const VF wr = hn::Mul(hn::Set(df, radius), rz);
        occluded = OccludedPerLane<kRange, kHemisphere>(
            df, k, p, tables.samples, tables.kernel.data(), rx, ry, rz, ur, vr, wr, nx, ny, nz);
      } else {
        occluded =
            OccludedTabled<kRange, kHemisphere>(df, k, p, tables.samples, row_table, nx, ny, nz);
      }
      // A = 1 − occluded/N, rescaled 2A, clamped: crytek_pixel's last lines.
      VF a = hn::Sub(hn::Set(df, 1.0f), hn::Div(occluded, count_n));
      if (rescaled) a = hn::Mul(hn::Set(df, 2.0f), a);
      a = hn::Min(hn::Max(a, hn::Zero(df)), hn::Set(df, 1.0f));
      result = hn::IfThenElse(geometry, a, result);
    }
    StoreRowPart(df, result, count, out + x0);
  });
}

}  // namespace

// Pixels [x_begin, x_end) of row y into out (the row); x_begin a multiple of Lanes.
void CrytekSsaoSpan(const CrytekSimdFrame& f, const CrytekSsaoSettings& s,
                    const CrytekTables& tables, int y, int x_begin, int x_end,
                    float* HWY_RESTRICT out) {
  const bool hemisphere = f.normals != nullptr;
  switch (CrytekSsaoRangeCheck(s.range_check)) {
    case CrytekSsaoRangeCheck::Smooth:
      return hemisphere
                 ? SpanT<CrytekSsaoRangeCheck::Smooth, true>(f, s, tables, y, x_begin, x_end, out)
                 : SpanT<CrytekSsaoRangeCheck::Smooth, false>(f, s, tables, y, x_begin, x_end, out);
    case CrytekSsaoRangeCheck::Hard:
      return hemisphere
                 ? SpanT<CrytekSsaoRangeCheck::Hard, true>(f, s, tables, y, x_begin, x_end, out)
                 : SpanT<CrytekSsaoRangeCheck::Hard, false>(f, s, tables, y, x_begin, x_end, out);
    case CrytekSsaoRangeCheck::Off:
      return hemisphere
                 ? SpanT<CrytekSsaoRangeCheck::Off, true>(f, s, tables, y, x_begin, x_end, out)
                 : SpanT<CrytekSsaoRangeCheck::Off, false>(f, s, tables, y, x_begin, x_end, out);
  }
}

}  // namespace aolab::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace aolab {

HWY_EXPORT(CrytekSsaoSpan);

namespace {

// u, v of an offset o (file comment), in double and rounded once.
float offset_u(const CameraIntrinsics& cam, double radius, const glm::vec3& o) {
  return float(radius * (double(cam.fx) * o.x - double(cam.cx) * o.z));
}
float offset_v(const CameraIntrinsics& cam, double radius, const glm::vec3& o) {
  return float(-radius * (double(cam.fy) * o.y + double(cam.cy) * o.z));
}

CrytekTables make_tables(const CrytekSimdFrame& f, const CrytekSsaoSettings& s,
                         const std::vector<glm::vec3>& kernel, const glm::vec3 (&tile)[16]) {
  CrytekTables t;
  t.samples = int(kernel.size());
  const auto rotation = CrytekSsaoRotation(s.rotation);
  for (const glm::vec3& k : kernel) {
    t.kernel.insert(t.kernel.end(), {k.x, k.y, k.z, offset_u(f.cam, s.radius, k),
                                     offset_v(f.cam, s.radius, k), s.radius * k.z});
  }
  if (rotation == CrytekSsaoRotation::Tiled4x4)
    for (int i = 0; i < 16; ++i)
      for (int c = 0; c < 3; ++c) t.tile[i][c] = tile[i][c];
  if (rotation == CrytekSsaoRotation::PerPixel) return t;
  t.reflected.resize(std::size_t(4) * t.samples * kReflectedComponents * 4);
  for (int py = 0; py < 4; ++py)
    for (int i = 0; i < t.samples; ++i)
      for (int px = 0; px < 4; ++px) {
        const glm::vec3 r =
            rotation == CrytekSsaoRotation::Tiled4x4 ? tile[px + 4 * py] : glm::vec3(0.0f);
        const glm::vec3& k = kernel[std::size_t(i)];
        // The scalar code's reflection, in the same float operations (compiled here for the
        // baseline target, no FMA): the same o, so the same R·o_z and point depth.
        const glm::vec3 o = k - 2.0f * glm::dot(k, r) * r;
        const float c[kReflectedComponents] = {offset_u(f.cam, s.radius, o),
                                               offset_v(f.cam, s.radius, o),
                                               s.radius * o.z,
                                               o.x,
                                               o.y,
                                               o.z};
        for (int j = 0; j < kReflectedComponents; ++j)
          t.reflected[((std::size_t(py) * t.samples + i) * kReflectedComponents + j) * 4 + px] =
              c[j];
      }
  return t;
}

}  // namespace

Image crytek_ssao_simd(const GBuffer& g, const float* normals, const CrytekSsaoSettings& s,
                       const std::vector<glm::vec3>& kernel, const glm::vec3 (&tile)[16],
                       int threads, Progress* progress) {
  const CrytekSimdFrame f{g.depth.data, g.depth.row_stride, normals,           g.width(),
                          g.height(),   g.camera,           g.background_depth};
  const CrytekTables tables = make_tables(f, s, kernel, tile);
  return image_from_simd_tiles(f.width, f.height, threads, progress,
                               [&](int y, int x0, int x1, float* out) {
                                 HWY_DYNAMIC_DISPATCH(CrytekSsaoSpan)(f, s, tables, y, x0, x1, out);
                               });
}

}  // namespace aolab
#endif  // HWY_ONCE
