// The SIMD kernel of VAO and VAO++: vao_pixel (pipes.cpp, the oracle it is tested against) on
// Lanes pixels of a row at once, compiled by Highway for every target and dispatched at run
// time. Both methods run this one sample loop; VAO++ adds its per-pixel sample counts (§4.1,
// §4.2), range check (§4.4), tiled sample sets (§4.5) and colour bleeding (§4.7).
//
// What it does differently (docs/methods/vao.md, "SIMD kernel"):
// - float instead of double: the tangent sphere is scaled by L = d (1 + |v0x| + |v0y|) + R/2
//   (P's depth and the sphere's radius), so that every quantity of the ray-sphere
//   intersection is O(1) at any radius (the scalar code needs double for R up to 1e30
//   because b² overflows float there); the roots are formed as the scalar code forms them,
//   without cancellation (q = b + sign(b)·sqrt(disc), roots q/a and c/q);
// - the sample's pixel by one multiply-add per coordinate (the division by C's depth is made
//   once per pixel);
// - the rounding tolerance of the case test from the hardware reciprocal estimates (it only
//   scales a tolerance);
// - a sample's depth, and where pixels use different sets its disc point, is a gather.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "core/volumetric/pipes_simd.cpp"

#include "core/volumetric/pipes_simd.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <numbers>

#include "core/base/simd-inl.h"
#include "core/sampling/random.h"

HWY_BEFORE_NAMESPACE();
namespace aolab::HWY_NAMESPACE {
namespace {

// pixel_random(seed, x, y, stream) for the columns x of the lanes (any columns): bit for bit
// the scalar value, as PixelRandom for consecutive ones.
HWY_INLINE VF PixelRandomAt(DF df, std::uint32_t seed, VI x, int y, std::uint32_t stream) {
  const DU du;
  const std::uint32_t h0 = pcg_hash(seed ^ 0x9E3779B9u);
  auto h = PcgHash(du, hn::Xor(hn::Set(du, h0), hn::BitCast(du, x)));
  h = PcgHash(du, hn::Xor(h, hn::Set(du, std::uint32_t(y) * 0x85EBCA6Bu)));
  h = PcgHash(du, hn::Add(h, hn::Set(du, stream * 0xC2B2AE35u)));
  return hn::Mul(hn::ConvertTo(df, hn::BitCast(DI(), hn::ShiftRight<8>(h))),
                 hn::Set(df, 1.0f / 16777216.0f));
}

// §4.1 on every lane: vao_pp_adaptive_samples of the projected disc (pixel_samples), in
// float (the scalar code squares the ratio in double: the two can differ where the disc's
// area is within an ulp of a power of two).
HWY_INLINE VI AdaptiveSamples(DF df, const VaoFrame& f, const VaoPixelOptions& o,
                              const VaoSimdCounts& c, VF d, VF nz) {
  const DI di;
  const VF dc = hn::Sub(d, hn::Mul(hn::Set(df, 0.5f * o.radius), nz));
  const VF diameter = hn::IfThenElse(hn::Gt(dc, hn::Zero(df)),
                                     hn::Mul(hn::Div(hn::Set(df, o.radius * f.camera.fy), dc),
                                             hn::Set(df, 1.0f / float(f.height))),
                                     hn::Set(df, HUGE_VALF));
  const VF ratio = hn::Div(diameter, hn::Set(df, c.adaptive_min_diameter));
  const VF area = hn::Mul(ratio, ratio);  // overflow: infinite, the most samples
  VI n = hn::Set(di, 2);
  for (float bound : {2.0f, 4.0f, 8.0f, 16.0f})
    n = hn::IfThenElse(hn::RebindMask(di, hn::Ge(area, hn::Set(df, bound))), hn::Add(n, n), n);
  return hn::Min(n, hn::Set(di, std::max(2, c.samples)));
}

// The tangent sphere of every lane's P (vao_pixel's Sphere), scaled by 1/L.
struct Sphere {
  VF scale;                               // L
  VF cx, cy, cz;                          // C / L
  VF c_term;                              // (|P|² + 2r P·n) / L²
  VF c_error_rel;                         // c_term_error / |c_term|
  VF b_error;                             // b_error / L
  VF c_error;                             // c_term_error / L²
  VF dc;                                  // C's depth (unscaled)
  VF r;                                   // R/2 (unscaled)
  VF r2;                                  // (r / L)²
  VF px_base, py_base, px_step, py_step;  // a sample's pixel: base + step·(sx, sy)
};

// What vao_pixel sums, on every lane.
struct Sums {
  VF open, full, br, bg, bb, bleed_count;
};

// Every lane's pixel as its samples see it: P's normal, P's view ray v0 = (vx, vy, −1) at
// depth 1, r = R/2 and the tangent sphere; `active` where the pixel is evaluated.
struct Pixels {
  VF d, nx, ny, nz;
  VF vx, vy, r;
  Sphere sp;
  MF active;
  bool outside;  // every active pixel sees its sphere from outside (c > 0)
};

// The sphere of every lane (scaled by 1/L) and where a sample on it projects. False when no
// active lane's disc is in front of the camera (NaN fails): then nothing is summed.
HWY_INLINE bool MakePixels(DF df, const VaoFrame& f, const VaoPixelOptions& o, int y, VI xs, VF d,
                           VF nx, VF ny, VF nz, MF active, Pixels& p) {
  const VF zero = hn::Zero(df), one = hn::Set(df, 1.0f);
  const CameraIntrinsics& cam = f.camera;
  const float inv_fx = 1.0f / cam.fx, inv_fy = 1.0f / cam.fy;
  p.d = d, p.nx = nx, p.ny = ny, p.nz = nz;
  // P = d·v0, v0 the view ray through the pixel centre at depth 1.
  const VF xc = hn::Add(hn::ConvertTo(df, xs), hn::Set(df, 0.5f));
  const VF vx = hn::Mul(hn::Sub(xc, hn::Set(df, cam.cx)), hn::Set(df, inv_fx));
  const VF vy = hn::Set(df, -(float(y) + 0.5f - cam.cy) * inv_fy);
  const VF r = hn::Set(df, 0.5f * o.radius);
  p.vx = vx, p.vy = vy, p.r = r;
  const VF scale = hn::MulAdd(d, hn::Add(one, hn::Add(hn::Abs(vx), hn::Abs(vy))), r);  // L
  const VF inv_scale = hn::Div(one, scale);
  const VF ps = hn::Mul(d, inv_scale);
  const VF px = hn::Mul(vx, ps), py = hn::Mul(vy, ps), pz = hn::Neg(ps);  // P / L
  const VF rs = hn::Mul(r, inv_scale);                                    // r / L
  Sphere& sp = p.sp;
  sp.scale = scale;
  sp.r = r;
  sp.cx = hn::MulAdd(rs, nx, px);
  sp.cy = hn::MulAdd(rs, ny, py);
  sp.cz = hn::MulAdd(rs, nz, pz);
  sp.r2 = hn::Mul(rs, rs);
  sp.dc = hn::Mul(hn::Neg(sp.cz), scale);
  // The disc is in front of the camera (NaN fails).
  p.active = hn::And(active, hn::And(hn::Gt(sp.dc, zero), hn::IsFinite(sp.dc)));
  if (hn::AllFalse(df, p.active)) return false;
  const VF p_dot_p = hn::MulAdd(px, px, hn::MulAdd(py, py, hn::Mul(pz, pz)));
  const VF p_dot_n = hn::MulAdd(px, nx, hn::MulAdd(py, ny, hn::Mul(pz, nz)));
  const VF p_len = hn::Sqrt(p_dot_p);
  sp.c_term = hn::MulAdd(hn::Add(rs, rs), p_dot_n, p_dot_p);
  sp.c_error = hn::MulAdd(hn::Mul(hn::Set(df, 4.0f), rs), p_len, p_dot_p);
  sp.c_error_rel = hn::Div(sp.c_error, hn::Abs(sp.c_term));
  sp.b_error = hn::MulAdd(hn::Set(df, 2.0f), rs, p_len);
  // Every pixel sees its sphere from outside (c > 0, the usual radii): one discriminant form
  // and one tolerance form serve every sample.
  p.outside = hn::AllFalse(df, hn::AndNot(hn::Gt(sp.c_term, zero), p.active));
  // The sample at disc point (sx, sy) projects to pixel (cx + fx (C.x + r sx)/dc,
  // cy − fy (C.y + r sy)/dc): one division per pixel, one multiply-add per sample.
  const VF kx = hn::Div(hn::Set(df, cam.fx), hn::Neg(sp.cz));
  const VF ky = hn::Div(hn::Set(df, cam.fy), hn::Neg(sp.cz));
  sp.px_base = hn::MulAdd(sp.cx, kx, hn::Set(df, cam.cx));
  sp.py_base = hn::NegMulAdd(sp.cy, ky, hn::Set(df, cam.cy));
  sp.px_step = hn::Mul(rs, kx);
  sp.py_step = hn::Neg(hn::Mul(rs, ky));
  return true;
}

// The lanes' sample sets: the base set of each lane's count, turned by the lane's angle.
struct LaneSets {
  VI n_active, base;  // each lane's count (0 where inactive) and its set's first sample
  int max_n;
  bool uniform;  // every active lane takes the set of max_n samples
  int base0;     // that set's first sample
  bool rotate;
  VF ca, sa;  // cos and sin of each lane's angle
};

HWY_INLINE LaneSets MakeLaneSets(DF df, const VaoSimdSets& sets, int y, VI xs, VI n, MF active) {
  const DI di;
  LaneSets ls;
  ls.n_active = hn::IfThenElseZero(hn::RebindMask(di, active), n);
  ls.base = hn::GatherIndex(di, sets.offset.data(), ls.n_active);
  ls.max_n = hn::GetLane(hn::MaxOfLanes(di, ls.n_active));
  // Where every pixel takes the same set (almost everywhere: counts change only at the
  // edges of §4.1's and §4.2's regions) its points are broadcast instead of gathered.
  ls.uniform = hn::AllTrue(
      di, hn::Or(hn::Eq(ls.n_active, hn::Set(di, ls.max_n)), hn::Not(hn::RebindMask(di, active))));
  ls.base0 = sets.offset[std::size_t(ls.max_n)];
  ls.ca = hn::Set(df, 1.0f), ls.sa = hn::Zero(df);
  ls.rotate = sets.random_rotation || sets.tiled;
  if (sets.tiled) {
    // Rotation (x mod 3) + 3 (y mod 3); x/3 in float is exact enough to floor at any width.
    const VF xf = hn::ConvertTo(df, xs);
    const VF q = hn::Floor(hn::Mul(xf, hn::Set(df, 1.0f / 3.0f)));
    const VI xm = hn::ConvertTo(di, hn::NegMulAdd(q, hn::Set(df, 3.0f), xf));
    const VI rot = hn::Add(xm, hn::Set(di, 3 * (y % 3)));
    ls.ca = hn::GatherIndex(df, sets.rotation_cos, rot);
    ls.sa = hn::GatherIndex(df, sets.rotation_sin, rot);
  } else if (sets.random_rotation) {
    const VF angle =
        hn::Mul(hn::Set(df, float(2.0 * std::numbers::pi)), PixelRandomAt(df, sets.seed, xs, y, 0));
    ls.ca = hn::Cos(df, angle);
    ls.sa = hn::Sin(df, angle);
  }
  return ls;
}

// What every sample of the lanes reads besides the sphere: the image, P's own texel and ray
// (for samples on it), the rounding scale and the settings' constants.
struct SampleConstants {
  int w;
  VF width, height;
  VF ray_x0, ray_y0, fx_inv,
      fy_inv;  // a texel's view ray: (ray_x0, ray_y0) + (ix, iy)·(fx_inv, fy_inv)
  VF tol_scale, axis_tol;
  VI xi, yi;  // P's texel
  VF self_full;
  VF range_u, inv_radius;
  bool bleeding;
};

HWY_INLINE SampleConstants MakeSampleConstants(DF df, const VaoFrame& f, const VaoPixelOptions& o,
                                               int y, VI xs, const Pixels& p) {
  const DI di;
  const VF one = hn::Set(df, 1.0f);
  const CameraIntrinsics& cam = f.camera;
  const float inv_fx = 1.0f / cam.fx, inv_fy = 1.0f / cam.fy;
  SampleConstants k;
  k.w = f.width;
  k.width = hn::Set(df, float(f.width)), k.height = hn::Set(df, float(f.height));
  k.ray_x0 = hn::Set(df, (0.5f - cam.cx) * inv_fx);
  k.ray_y0 = hn::Set(df, -(0.5f - cam.cy) * inv_fy);
  k.fx_inv = hn::Set(df, inv_fx), k.fy_inv = hn::Set(df, -inv_fy);
  k.tol_scale = hn::Set(df, kUnitRoundoff * kVaoDepthUlps);
  k.axis_tol = hn::Mul(k.tol_scale, hn::Add(p.d, p.r));  // eq. 2 pipes: ε·16·(d + r) + |ds|
  k.xi = xs, k.yi = hn::Set(di, y);
  const VF v0_n = hn::Sub(hn::MulAdd(p.vx, p.nx, hn::Mul(p.vy, p.ny)), p.nz);
  k.self_full = hn::Div(hn::Mul(hn::Add(p.r, p.r), hn::Abs(v0_n)),
                        hn::MulAdd(p.vx, p.vx, hn::MulAdd(p.vy, p.vy, one)));
  k.range_u = hn::Set(df, kVaoRangeCheckU * o.radius);
  k.bleeding = o.bleeding_step > 0 && !f.color.pixels().empty();
  k.inv_radius = hn::Set(df, 1.0f / o.radius);
  return k;
}

// The samples go in chunks: first every sample's texel and gathered depth (independent of
// each other, so that the gathers' memory latencies overlap), then their cases, whose
// branches would otherwise stall each gather behind a mispredicted one.
constexpr int kChunk = 16;

// A chunk's samples as phase 1 leaves them for phase 2: sample j of lane l at j·Lanes + l.
struct Chunk {
  HWY_ALIGN float sx[kChunk * hn::MaxLanes(DF())], sy[kChunk * hn::MaxLanes(DF())];
  HWY_ALIGN float h[kChunk * hn::MaxLanes(DF())], ds[kChunk * hn::MaxLanes(DF())];
  HWY_ALIGN float live[kChunk * hn::MaxLanes(DF())];
  HWY_ALIGN std::int32_t ix[kChunk * hn::MaxLanes(DI())], iy[kChunk * hn::MaxLanes(DI())];
};

// Phase 1: samples i0 … i0 + chunk − 1 of every lane: the disc point, turned; its texel, and
// the depth there; whether it counts (within the lane's count, on screen).
HWY_INLINE void PlaceChunk(DF df, const VaoFrame& f, const VaoPixelOptions& o,
                           const VaoSimdSets& sets, const Pixels& p, const LaneSets& ls,
                           const SampleConstants& k, int i0, int chunk, Chunk& c) {
  const DI di;
  const VF zero = hn::Zero(df);
  const std::size_t lanes = hn::Lanes(df);
  const Sphere& sp = p.sp;
  for (int j = 0; j < chunk; ++j) {
    const int i = i0 + j;
    MF live = hn::And(p.active, hn::RebindMask(df, hn::Lt(hn::Set(di, i), ls.n_active)));
    VF bx, by, bh;
    if (ls.uniform) {
      bx = hn::Set(df, sets.x[std::size_t(ls.base0 + i)]);
      by = hn::Set(df, sets.y[std::size_t(ls.base0 + i)]);
      bh = hn::Set(df, sets.h[std::size_t(ls.base0 + i)]);
    } else {
      const VI index =
          hn::IfThenElseZero(hn::RebindMask(di, live), hn::Add(ls.base, hn::Set(di, i)));
      bx = hn::GatherIndex(df, sets.x.data(), index);
      by = hn::GatherIndex(df, sets.y.data(), index);
      bh = o.view_ray_pipes ? zero : hn::GatherIndex(df, sets.h.data(), index);
    }
    VF sx = bx, sy = by;
    if (ls.rotate) {  // vao_random_rotation, or the tile's rotated set
      sx = hn::Sub(hn::Mul(ls.ca, bx), hn::Mul(ls.sa, by));
      sy = hn::MulAdd(ls.sa, bx, hn::Mul(ls.ca, by));
    }
    const VF fpx = hn::MulAdd(sp.px_step, sx, sp.px_base);
    const VF fpy = hn::MulAdd(sp.py_step, sy, sp.py_base);
    // Off-screen samples carry no information: left out (NaN fails too).
    live = hn::And(live, hn::And(hn::And(hn::Ge(fpx, zero), hn::Lt(fpx, k.width)),
                                 hn::And(hn::Ge(fpy, zero), hn::Lt(fpy, k.height))));
    const VI ix = hn::ConvertTo(di, hn::IfThenElseZero(live, fpx));  // truncation: the texel
    const VI iy = hn::ConvertTo(di, hn::IfThenElseZero(live, fpy));
    const VI texel = hn::Add(hn::Mul(iy, hn::Set(di, k.w)), ix);
    hn::Store(sx, df, c.sx + j * lanes);
    hn::Store(sy, df, c.sy + j * lanes);
    hn::Store(bh, df, c.h + j * lanes);
    hn::Store(ix, di, c.ix + j * lanes);
    hn::Store(iy, di, c.iy + j * lanes);
    hn::Store(hn::GatherIndex(df, f.depth.data(), texel), df, c.ds + j * lanes);
    hn::Store(hn::VecFromMask(df, live), df, c.live + j * lanes);
  }
}

// A sample's pipe through the sphere: its extent [front, back] in depth, its full length and
// the case test's rounding tolerance.
struct Pipe {
  VF front, back, full, tol;
};

// view_ray_pipe, scaled by 1/L: the ray X = δ v through the texel centre (ix, iy). Updates
// `live` (the ray misses the sphere, or meets it behind the camera: out) and returns whether
// any lane is left; `self` marks the samples on P's own texel.
HWY_INLINE bool ViewRayPipe(DF df, const Pixels& p, const SampleConstants& k, VI ix, VI iy, VF ds,
                            MF self, MF& live, Pipe& pipe) {
  const VF zero = hn::Zero(df), one = hn::Set(df, 1.0f);
  const Sphere& sp = p.sp;
  const VF rx = hn::MulAdd(hn::ConvertTo(df, ix), k.fx_inv, k.ray_x0);
  const VF ry = hn::MulAdd(hn::ConvertTo(df, iy), k.fy_inv, k.ray_y0);
  const VF a = hn::MulAdd(rx, rx, hn::MulAdd(ry, ry, one));
  const VF b = hn::Sub(hn::MulAdd(rx, sp.cx, hn::Mul(ry, sp.cy)), sp.cz);
  // b² − a·c cancels where the sphere looks small from the camera (c = |C|² − r² > 0,
  // the far depths): there disc = a r² − |v × C|², whose terms are of the size of the
  // result. Inside the sphere (c < 0, huge radii) b² − a·c adds two positive terms.
  const VF cross_x = hn::MulAdd(ry, sp.cz, sp.cy);
  const VF cross_y = hn::MulAdd(rx, sp.cz, sp.cx);
  const VF cross_z = hn::MulSub(rx, sp.cy, hn::Mul(ry, sp.cx));
  const VF cross2 =
      hn::MulAdd(cross_x, cross_x, hn::MulAdd(cross_y, cross_y, hn::Mul(cross_z, cross_z)));
  const VF disc_outside = hn::MulSub(a, sp.r2, cross2);
  const VF disc = p.outside
                      ? disc_outside
                      : hn::IfThenElse(hn::Lt(sp.c_term, zero),
                                       hn::NegMulAdd(a, sp.c_term, hn::Mul(b, b)), disc_outside);
  // A sample on P's own texel has P's ray, which meets the sphere at P (depth d) and at
  // d + 2r (v0·n)/|v0|²: its pipe's length without the discriminant, which cancels
  // there when the sphere is a fraction of a pixel (far, grazing surfaces).
  const MF own = hn::And(live, self);
  live = hn::And(live, hn::Or(own, hn::Gt(disc, zero)));
  if (hn::AllFalse(df, live)) return false;
  const VF sq = hn::Sqrt(hn::IfThenElse(live, disc, one));
  const MF b_pos = hn::Ge(b, zero);
  const VF q = hn::Add(b, hn::CopySign(sq, b));  // b + sign(b) sq: no cancellation
  const VF root_a = hn::Div(q, a), root_c = hn::Div(sp.c_term, q);
  const VF back_s = hn::IfThenElse(b_pos, root_a, root_c);
  const VF front_s = hn::IfThenElse(b_pos, root_c, root_a);
  pipe.back = hn::Mul(back_s, sp.scale);
  pipe.front = hn::Max(zero, hn::Mul(front_s, sp.scale));  // the camera may be inside
  live = hn::And(live, hn::And(hn::Gt(pipe.back, zero), hn::IsFinite(pipe.back)));
  // The scalar code's rounding bound (view_ray_pipe), over L; the reciprocals' estimates
  // only scale a tolerance.
  const VF inv_sq = hn::ApproximateReciprocal(sq);
  const VF inv_a = hn::ApproximateReciprocal(a);
  const VF t = hn::Abs(q);
  const VF bound_pos =
      hn::Mul(hn::Mul(hn::Add(hn::Add(b, sq),
                              hn::Mul(hn::MulAdd(b, b, hn::Abs(hn::Mul(a, sp.c_term))), inv_sq)),
                      inv_a),
              sp.scale);
  VF bound = bound_pos;
  if (!p.outside) {  // b < 0 needs the camera inside the sphere (c > 0: back > 0 needs b > 0)
    const VF sqrt_a = hn::Mul(a, hn::ApproximateReciprocalSqrt(a));
    const VF bound_neg =
        hn::Mul(hn::Abs(pipe.back), hn::MulAdd(hn::MulAdd(hn::Add(sp.b_error, sp.b_error), sqrt_a,
                                                          hn::Mul(hn::Mul(a, sp.c_error), inv_sq)),
                                               hn::ApproximateReciprocal(t), sp.c_error_rel));
    bound = hn::IfThenElse(b_pos, bound_pos, bound_neg);
  }
  pipe.tol = hn::Add(hn::Abs(ds), bound);
  pipe.tol = hn::Min(hn::Mul(k.tol_scale, pipe.tol), hn::Set(df, 1e38f));
  pipe.full = hn::IfThenElse(own, k.self_full, hn::Sub(pipe.back, pipe.front));
  live = hn::Or(live, hn::And(own, hn::Gt(k.self_full, zero)));
  return true;
}

// Parallel to the view axis through the disc point (h: the half pipe length over r);
// Σ full = R Σ h_i: F of eq. 2.
HWY_INLINE Pipe AxisPipe(const Pixels& p, const SampleConstants& k, VF bh, VF ds) {
  Pipe pipe;
  const VF half = hn::Mul(p.r, bh);
  pipe.front = hn::Sub(p.sp.dc, half);
  pipe.back = hn::Add(p.sp.dc, half);
  pipe.full = hn::Add(half, half);
  pipe.tol = hn::MulAdd(k.tol_scale, hn::Abs(ds), k.axis_tol);
  return pipe;
}

// Δz of Figure 3's cases for a surface at depth ds; on P's own texel (`self`) the surface is
// P, where the sphere touches: open. With the range check, §4.4's s(d) = u / max(u, d/R).
HWY_INLINE VF OpenLength(DF df, const VaoPixelOptions& o, const SampleConstants& k,
                         const Pipe& pipe, VF ds, MF self) {
  const VF zero = hn::Zero(df), one = hn::Set(df, 1.0f);
  const MF case_b = hn::Or(self, hn::Not(hn::Lt(ds, hn::Sub(pipe.back, pipe.tol))));
  const MF case_c = hn::Le(ds, pipe.front);
  VF open = hn::IfThenZeroElse(case_c, hn::Sub(ds, pipe.front));
  if (o.range_check) {  // s(d) = u / max(u, d/R) = uR / max(uR, d)
    const VF behind = hn::Sub(hn::Mul(hn::Set(df, 0.5f), hn::Add(pipe.front, pipe.back)), ds);
    const VF s =
        hn::IfThenElse(hn::Gt(behind, zero), hn::Div(k.range_u, hn::Max(k.range_u, behind)), one);
    open = hn::NegMulAdd(hn::Sub(pipe.full, open), s, pipe.full);
  }
  return hn::IfThenElse(case_b, pipe.full, hn::Min(pipe.full, open));
}

// Eq. 5 (add_bleeding) of one sample at disc point (sx, sy) on the lanes `bleeds`: the
// colour at its texel, weighted by the cosine and falloff of the offset from P.
HWY_INLINE void AddBleeding(DF df, const VaoFrame& f, const Pixels& p, const SampleConstants& k,
                            VF sx, VF sy, VI texel, MF bleeds, Sums& out) {
  const DI di;
  const VF zero = hn::Zero(df), one = hn::Set(df, 1.0f);
  const VF r = p.r, nx = p.nx, ny = p.ny, nz = p.nz;
  const VF ox = hn::Mul(r, sx), oy = hn::Mul(r, sy);
  const VF tx = hn::MulAdd(r, nx, ox), ty = hn::MulAdd(r, ny, oy), tz = hn::Mul(r, nz);
  const VF len2 = hn::MulAdd(tx, tx, hn::MulAdd(ty, ty, hn::Mul(tz, tz)));
  const VF len = hn::Sqrt(len2);  // overflows to ∞ beyond R ~ 1e19, as the scalar float
  const VF dot = hn::MulAdd(tx, nx, hn::MulAdd(ty, ny, hn::Mul(tz, nz)));
  const MF has_len = hn::Gt(len, zero);
  const VF cosine =
      hn::IfThenElseZero(has_len, hn::Max(zero, hn::Div(dot, hn::IfThenElse(has_len, len, one))));
  const VF fall = hn::Max(zero, hn::NegMulAdd(len, k.inv_radius, one));
  const VF weight = hn::Mul(cosine, hn::Mul(fall, fall));
  const VI ci = hn::Mul(hn::IfThenElseZero(hn::RebindMask(di, bleeds), texel), hn::Set(di, 3));
  const float* col = f.color.data();
  const VF cr = hn::GatherIndex(df, col, ci);
  const VF cg = hn::GatherIndex(df, col, hn::Add(ci, hn::Set(di, 1)));
  const VF cb = hn::GatherIndex(df, col, hn::Add(ci, hn::Set(di, 2)));
  out.br = hn::Add(out.br, hn::IfThenElseZero(bleeds, hn::MulAdd(weight, hn::Sub(cr, one), one)));
  out.bg = hn::Add(out.bg, hn::IfThenElseZero(bleeds, hn::MulAdd(weight, hn::Sub(cg, one), one)));
  out.bb = hn::Add(out.bb, hn::IfThenElseZero(bleeds, hn::MulAdd(weight, hn::Sub(cb, one), one)));
  out.bleed_count = hn::Add(out.bleed_count, hn::IfThenElseZero(bleeds, one));
}

// Phase 2: the chunk's samples' pipes and cases, summed into `out`.
HWY_INLINE void SumChunk(DF df, const VaoFrame& f, const VaoPixelOptions& o, const Pixels& p,
                         const SampleConstants& k, int i0, int chunk, const Chunk& c, Sums& out) {
  const DI di;
  const VF zero = hn::Zero(df);
  const std::size_t lanes = hn::Lanes(df);
  for (int j = 0; j < chunk; ++j) {
    const int i = i0 + j;
    MF live = hn::MaskFromVec(hn::Load(df, c.live + j * lanes));
    if (hn::AllFalse(df, live)) continue;
    const VF sx = hn::Load(df, c.sx + j * lanes), sy = hn::Load(df, c.sy + j * lanes);
    const VF bh = hn::Load(df, c.h + j * lanes);
    const VI ix = hn::Load(di, c.ix + j * lanes), iy = hn::Load(di, c.iy + j * lanes);
    const VI texel = hn::Add(hn::Mul(iy, hn::Set(di, k.w)), ix);
    const VF ds = hn::Load(df, c.ds + j * lanes);
    const MF self = hn::RebindMask(df, hn::And(hn::Eq(ix, k.xi), hn::Eq(iy, k.yi)));
    Pipe pipe;
    if (o.view_ray_pipes) {
      if (!ViewRayPipe(df, p, k, ix, iy, ds, self, live, pipe)) continue;
    } else {
      pipe = AxisPipe(p, k, bh, ds);
    }
    live = hn::And(live, hn::Gt(pipe.full, zero));
    if (hn::AllFalse(df, live)) continue;
    const VF open = OpenLength(df, o, k, pipe, ds, self);
    out.open = hn::Add(out.open, hn::IfThenElseZero(live, open));
    out.full = hn::Add(out.full, hn::IfThenElseZero(live, pipe.full));
    if (k.bleeding && i % o.bleeding_step == 0) {  // on non-background samples
      const MF bleeds = hn::And(live, hn::Eq(ds, ds));
      if (hn::AllFalse(df, bleeds)) continue;
      AddBleeding(df, f, p, k, sx, sy, texel, bleeds, out);
    }
  }
}

// vao_pixel on every lane of `active`: the sphere, the lanes' sample sets, then the samples
// chunk by chunk.
HWY_INLINE Sums PixelSums(DF df, const VaoFrame& f, const VaoPixelOptions& o,
                          const VaoSimdSets& sets, int y, VI xs, VF d, VF nx, VF ny, VF nz, VI n,
                          MF active) {
  const VF zero = hn::Zero(df);
  Sums out{zero, zero, zero, zero, zero, zero};
  Pixels p;
  if (!MakePixels(df, f, o, y, xs, d, nx, ny, nz, active, p)) return out;
  const LaneSets ls = MakeLaneSets(df, sets, y, xs, n, p.active);
  const SampleConstants k = MakeSampleConstants(df, f, o, y, xs, p);
  Chunk c;
  for (int i0 = 0; i0 < ls.max_n; i0 += kChunk) {
    const int chunk = std::min(kChunk, ls.max_n - i0);
    PlaceChunk(df, f, o, sets, p, ls, k, i0, chunk, c);
    SumChunk(df, f, o, p, k, i0, chunk, c, out);
  }
  return out;
}

}  // namespace

void VaoSimdSpan(const VaoFrame& f, const VaoPixelOptions& o, const VaoSimdSets& sets,
                 const VaoSimdCounts& counts, int y, int k_begin, int k_end, int stride, int offset,
                 float* HWY_RESTRICT out, int channels, VaoSimdStats* stats) {
  const DF df;
  const DI di;
  const int lanes = int(hn::Lanes(df));
  const int w = f.width;
  const float* normals = f.normals.data();
  VaoSimdStats local;
  for (int k0 = k_begin; k0 < k_end; k0 += lanes) {
    const int count = std::min(lanes, k_end - k0);
    // Lanes past the span repeat its last pixel; their results are dropped.
    const VI k = hn::Min(hn::Add(hn::Set(di, k0), hn::Iota(di, 0)), hn::Set(di, k_end - 1));
    const VI xs =
        hn::Min(hn::Add(hn::Mul(k, hn::Set(di, stride)), hn::Set(di, offset)), hn::Set(di, w - 1));
    const VI index = hn::Add(xs, hn::Set(di, y * w));
    VF d, nx, ny, nz;
    if (stride == 1 && offset == 0 && count == lanes) {  // consecutive pixels: plain loads
      const std::size_t first = std::size_t(y) * w + std::size_t(k0);
      d = hn::LoadU(df, f.depth.data() + first);
      hn::LoadInterleaved3(df, normals + 3 * first, nx, ny, nz);
    } else {
      d = hn::GatherIndex(df, f.depth.data(), index);
      const VI index3 = hn::Mul(index, hn::Set(di, 3));
      nx = hn::GatherIndex(df, normals, index3);
      ny = hn::GatherIndex(df, normals, hn::Add(index3, hn::Set(di, 1)));
      nz = hn::GatherIndex(df, normals, hn::Add(index3, hn::Set(di, 2)));
    }
    const MF in_span = hn::RebindMask(df, hn::Lt(hn::Iota(di, 0), hn::Set(di, count)));
    const MF geometry = hn::And(in_span, hn::Eq(d, d));  // background is NaN
    if (hn::AllFalse(df, geometry)) continue;

    VI n = counts.adaptive ? AdaptiveSamples(df, f, o, counts, d, nz) : hn::Set(di, counts.samples);
    if (counts.culled) {
      const MF culled =
          hn::And(geometry, hn::Ne(hn::GatherIndex(df, counts.culled, xs), hn::Zero(df)));
      const VI cut = counts.greedy ? hn::Zero(di) : hn::Min(n, hn::Set(di, counts.careful));
      n = hn::IfThenElse(hn::RebindMask(di, culled), cut, n);
      local.culled += std::int64_t(hn::CountTrue(df, culled));
    }
    local.pixels += std::int64_t(hn::CountTrue(df, geometry));
    const VI n_geometry = hn::IfThenElseZero(hn::RebindMask(di, geometry), n);
    HWY_ALIGN std::int32_t n_lanes[hn::MaxLanes(di)];
    hn::Store(n_geometry, di, n_lanes);
    for (int j = 0; j < count; ++j) local.samples += n_lanes[j];

    const MF active = hn::And(geometry, hn::RebindMask(df, hn::Gt(n, hn::Zero(di))));
    if (hn::AllFalse(df, active)) continue;
    const Sums sums = PixelSums(df, f, o, sets, y, xs, d, nx, ny, nz, n, active);
    // VaoPixelSums::ao: V = open / full clamped to [0, 1]; 1 without samples.
    const VF zero = hn::Zero(df), one = hn::Set(df, 1.0f);
    const MF has_full = hn::Gt(sums.full, zero);
    const VF ao = hn::IfThenElse(
        has_full,
        hn::Min(hn::Max(hn::Div(sums.open, hn::IfThenElse(has_full, sums.full, one)), zero), one),
        one);
    HWY_ALIGN float lane_ao[hn::MaxLanes(df)];
    HWY_ALIGN float lane_active[hn::MaxLanes(df)];
    hn::Store(ao, df, lane_ao);
    hn::Store(hn::VecFromMask(df, active), df, lane_active);
    if (channels == 1) {
      for (int j = 0; j < count; ++j)
        if (lane_active[j] != 0.0f) out[k0 + j] = lane_ao[j];
      continue;
    }
    HWY_ALIGN float lane_b[3][hn::MaxLanes(df)];
    HWY_ALIGN float lane_count[hn::MaxLanes(df)];
    const VF inv_count = hn::Div(one, hn::Max(sums.bleed_count, one));
    hn::Store(hn::Mul(sums.br, inv_count), df, lane_b[0]);
    hn::Store(hn::Mul(sums.bg, inv_count), df, lane_b[1]);
    hn::Store(hn::Mul(sums.bb, inv_count), df, lane_b[2]);
    hn::Store(sums.bleed_count, df, lane_count);
    for (int j = 0; j < count; ++j) {
      if (lane_active[j] == 0.0f) continue;
      float* px = out + std::size_t(k0 + j) * channels;
      px[0] = lane_ao[j];
      if (lane_count[j] > 0.0f)
        for (int c = 0; c < 3; ++c) px[1 + c] = lane_b[c][j];
    }
  }
  if (stats) {
    stats->pixels += local.pixels;
    stats->culled += local.culled;
    stats->samples += local.samples;
  }
}

}  // namespace aolab::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace aolab {

HWY_EXPORT(VaoSimdSpan);

void VaoSimdSets::add(const VaoKernel& k) {
  offset[std::size_t(k.size())] = int(x.size());
  x.insert(x.end(), k.x.begin(), k.x.end());
  y.insert(y.end(), k.y.begin(), k.y.end());
  h.insert(h.end(), k.h.begin(), k.h.end());
}

void vao_simd_span(const VaoFrame& f, const VaoPixelOptions& o, const VaoSimdSets& sets,
                   const VaoSimdCounts& counts, int y, int k_begin, int k_end, int stride,
                   int offset, float* out, int channels, VaoSimdStats* stats) {
  HWY_DYNAMIC_DISPATCH(VaoSimdSpan)
  (f, o, sets, counts, y, k_begin, k_end, stride, offset, out, channels, stats);
}

}  // namespace aolab
#endif  // HWY_ONCE
