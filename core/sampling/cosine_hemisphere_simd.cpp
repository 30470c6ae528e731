// cosine_directions: for_each_cosine_ray<float>'s directions, a vector of rays at a time.
// rtao draws 1 to 65536 rays per pixel; drawn one by one (two hashes, the concentric map's
// division and branch, a sine and a cosine, a normalisation) they cost half as much as Embree's
// traversal of them. Here the branch is a select, the sine and cosine Highway's, and every ray
// of a vector is drawn at once.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "core/sampling/cosine_hemisphere_simd.cpp"

#include <cmath>
#include <numbers>

#include "core/base/simd-inl.h"
#include "core/sampling/cosine_hemisphere.h"

HWY_BEFORE_NAMESPACE();
namespace aolab::HWY_NAMESPACE {

void CosineDirections(const CosineStrata& strata, std::uint32_t pixel, const glm::vec3& n,
                      float* HWY_RESTRICT dx, float* HWY_RESTRICT dy, float* HWY_RESTRICT dz) {
  const DF df;
  const DU du;
  glm::vec3 t, b;
  tangent_frame(n, t, b);
  const int lanes = int(hn::Lanes(df));
  const VF one = hn::Set(df, 1.0f), two = hn::Set(df, 2.0f), zero = hn::Zero(df);
  const VF quarter = hn::Set(df, std::numbers::pi_v<float> / 4.0f);
  const VF half_pi = hn::Set(df, std::numbers::pi_v<float> / 2.0f);
  const VF inv_columns = hn::Set(df, 1.0f / float(strata.columns));
  const VF scale = hn::Set(df, 1.0f / 16777216.0f);
  const auto stream_step = hn::Set(du, 0xC2B2AE35u);
  const auto base = hn::Set(du, pixel);
  for (int k = 0; k < strata.rays; k += lanes) {
    // Streams 2k and 2k + 1 of the pixel (pixel_stream_random), for the lanes' rays.
    const auto index = hn::Iota(du, std::uint32_t(k));
    const auto s1 = hn::Add(index, index);
    const auto h1 = PcgHash(du, hn::Add(base, hn::Mul(s1, stream_step)));
    const auto h2 = PcgHash(du, hn::Add(base, hn::Mul(hn::Add(s1, hn::Set(du, 1u)), stream_step)));
    const DI di;
    const VF r1 = hn::Mul(hn::ConvertTo(df, hn::BitCast(di, hn::ShiftRight<8>(h1))), scale);
    const VF r2 = hn::Mul(hn::ConvertTo(df, hn::BitCast(di, hn::ShiftRight<8>(h2))), scale);
    const VF u1 = hn::Mul(hn::Add(hn::LoadU(df, &strata.column[std::size_t(k)]), r1), inv_columns);
    const VF u2 = hn::Mul(hn::Add(hn::LoadU(df, &strata.row[std::size_t(k)]), r2),
                          hn::LoadU(df, &strata.inv_rows[std::size_t(k)]));
    // Shirley & Chiu's concentric map, the branch on |a| > |b| as a select: r is the larger
    // coordinate, t = π/4 · smaller/larger, and φ = t or π/2 − t.
    const VF a = hn::Sub(hn::Mul(two, u1), one), bb = hn::Sub(hn::Mul(two, u2), one);
    const auto a_wins = hn::Gt(hn::Abs(a), hn::Abs(bb));
    const VF larger = hn::IfThenElse(a_wins, a, bb), smaller = hn::IfThenElse(a_wins, bb, a);
    const auto centre = hn::Eq(larger, zero);
    const VF ratio =
        hn::IfThenZeroElse(centre, hn::Div(smaller, hn::IfThenElse(centre, one, larger)));
    const VF phi =
        hn::IfThenElse(a_wins, hn::Mul(quarter, ratio), hn::NegMulAdd(quarter, ratio, half_pi));
    const VF qx = hn::Mul(larger, hn::Cos(df, phi)), qy = hn::Mul(larger, hn::Sin(df, phi));
    const VF up = hn::Sqrt(hn::ZeroIfNegative(hn::NegMulAdd(qx, qx, hn::NegMulAdd(qy, qy, one))));
    VF x = hn::MulAdd(qx, hn::Set(df, t.x),
                      hn::MulAdd(qy, hn::Set(df, b.x), hn::Mul(up, hn::Set(df, n.x))));
    VF y = hn::MulAdd(qx, hn::Set(df, t.y),
                      hn::MulAdd(qy, hn::Set(df, b.y), hn::Mul(up, hn::Set(df, n.y))));
    VF z = hn::MulAdd(qx, hn::Set(df, t.z),
                      hn::MulAdd(qy, hn::Set(df, b.z), hn::Mul(up, hn::Set(df, n.z))));
    const VF inv_length = RecipSqrt(df, hn::MulAdd(x, x, hn::MulAdd(y, y, hn::Mul(z, z))));
    hn::StoreU(hn::Mul(x, inv_length), df, dx + k);
    hn::StoreU(hn::Mul(y, inv_length), df, dy + k);
    hn::StoreU(hn::Mul(z, inv_length), df, dz + k);
  }
}

}  // namespace aolab::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace aolab {

HWY_EXPORT(CosineDirections);

CosineStrata::CosineStrata(int n) : rays(n), columns(std::max(1, int(std::sqrt(double(n))))) {
  for (int c = 0; c < columns; ++c) {
    const int rows = int(std::int64_t(c + 1) * n / columns - std::int64_t(c) * n / columns);
    for (int r = 0; r < rows; ++r) {
      column.push_back(float(c));
      row.push_back(float(r));
      inv_rows.push_back(1.0f / float(rows));
      weight.push_back(1.0 / (double(columns) * rows));
    }
  }
  const std::size_t padded = (std::size_t(n) + 15) / 16 * 16;
  column.resize(padded, column[0]);
  row.resize(padded, row[0]);
  inv_rows.resize(padded, inv_rows[0]);
  weight.resize(padded, 0.0);
}

void cosine_directions(const CosineStrata& strata, std::uint32_t pixel, const glm::vec3& n,
                       float* dx, float* dy, float* dz) {
  HWY_DYNAMIC_DISPATCH(CosineDirections)(strata, pixel, n, dx, dy, dz);
}

}  // namespace aolab
#endif  // HWY_ONCE
