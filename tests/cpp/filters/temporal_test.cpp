#include "core/filters/temporal.h"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "core/methods/hbao/hbao.h"
#include "core/sampling/frame_seed.h"
#include "tests/cpp/test_support.h"

namespace aolab {
namespace {

using testing::random_image;

constexpr float kNan = std::numeric_limits<float>::quiet_NaN();

/// A plane facing the camera at depth 2 with normals (0, 0, 1): every history tap agrees.
struct Flat {
  Image depth, normal;
  GBuffer g;
  explicit Flat(int w = 13, int h = 9) : depth(w, h, 1, 2.0f), normal(w, h, 3, 0.0f) {
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) normal(x, y, 2) = 1.0f;
    g.depth = depth.view();
    g.normal = normal.view();
    g.camera = {10, 10, 0.5f * float(w), 0.5f * float(h)};
  }
};

Image motion_of(int w, int h, float dx, float dy) {
  Image m(w, h, 2);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) m(x, y, 0) = dx, m(x, y, 1) = dy;
  return m;
}

TemporalSettings unclamped(float alpha) {
  TemporalSettings s;
  s.alpha = alpha;
  s.clamp = int(TemporalClamp::Off);
  return s;
}

std::uint32_t bits(float v) { return std::bit_cast<std::uint32_t>(v); }

// Alpha = 0, a static scene: the running mean. After N frames every pixel is the mean of its
// N inputs to 1e-6 (each blend rounds to float once, so the error grows by at most an ulp of
// values in [0, 1], 6e-8, per frame: 16 frames stay below 1e-6).
TEST(Temporal, StaticSceneWithAlphaZeroIsTheMeanOfTheFrames) {
  Flat f;
  const int w = f.g.width(), h = f.g.height(), frames = 16;
  const Image still = motion_of(w, h, 0, 0);
  TemporalHistory history;
  std::vector<double> sum(std::size_t(w) * h, 0.0);
  for (int k = 0; k < frames; ++k) {
    const Image ao = random_image(w, h, 100 + k);
    for (std::size_t i = 0; i < sum.size(); ++i) sum[i] += ao.pixels()[i];
    const TemporalResult r = accumulate(ao.view(), f.g, still.view(), history, unclamped(0));
    for (std::size_t i = 0; i < sum.size(); ++i) {
      ASSERT_NEAR(r.accumulated.pixels()[i], sum[i] / (k + 1), 1e-6) << "frame " << k;
      ASSERT_EQ(r.disoccluded.pixels()[i], k == 0 ? 1.0f : 0.0f) << "frame " << k;
      ASSERT_EQ(history.length.pixels()[i], float(k + 1));
    }
  }
}

// Alpha > 0: with K = floor(1/alpha) − 1 the first K + 1 frames are averaged alike (the
// running mean, whose weight 1/(n+1) is still >= alpha), then each frame enters with weight
// alpha:
// A_N = (1−α)^(N−1−K) · mean(c_0..c_K) + Σ_{k=K+1}^{N−1} α (1−α)^(N−1−k) c_k.
TEST(Temporal, AlphaGivesTheClosedFormWeightedMean) {
  Flat f(7, 5);
  const int w = f.g.width(), h = f.g.height();
  const Image still = motion_of(w, h, 0, 0);
  for (float alpha : {0.25f, 0.1f, 0.3f}) {
    const int frames = 20, K = int(std::floor(1.0 / double(alpha))) - 1;
    TemporalHistory history;
    std::vector<Image> inputs;
    Image last;
    for (int k = 0; k < frames; ++k) {
      inputs.push_back(random_image(w, h, 7 * k + 3));
      last = accumulate(inputs.back().view(), f.g, still.view(), history, unclamped(alpha))
                 .accumulated;
    }
    const double a = alpha;
    for (std::size_t i = 0; i < last.pixels().size(); ++i) {
      double head = 0.0;
      for (int k = 0; k <= K; ++k) head += inputs[k].pixels()[i];
      double want = std::pow(1.0 - a, frames - 1 - K) * head / (K + 1);
      for (int k = K + 1; k < frames; ++k)
        want += a * std::pow(1.0 - a, frames - 1 - k) * inputs[k].pixels()[i];
      ASSERT_NEAR(last.pixels()[i], want, 2e-6) << "alpha " << alpha;
    }
  }
}

// max_history caps n: with alpha = 0 and max_history = 3 the fourth frame on enters with 1/4.
TEST(Temporal, MaxHistoryCapsTheRunningMean) {
  Flat f(5, 4);
  const Image still = motion_of(5, 4, 0, 0);
  TemporalSettings s = unclamped(0);
  s.max_history = 3;
  TemporalHistory history;
  double want = 0.0;
  for (int k = 0; k < 8; ++k) {
    const Image ao(5, 4, 1, float(k % 3) / 2.0f);
    const double c = ao(0, 0), weight = 1.0 / (std::min(k, 3) + 1);
    want = k == 0 ? c : want + weight * (c - want);
    const TemporalResult r = accumulate(ao.view(), f.g, still.view(), history, s);
    EXPECT_NEAR(r.accumulated(2, 2), want, 1e-6) << "frame " << k;
    EXPECT_EQ(history.length(2, 2), float(std::min(k + 1, 3)));
  }
}

// Disocclusion: a depth jump, a normal turned away, motion off the image and NaN motion each
// leave the pixel with the current frame exactly, flagged, its history length reset to 1.
TEST(Temporal, DisocclusionTakesTheCurrentFrameExactly) {
  Flat f;
  const int w = f.g.width(), h = f.g.height();
  TemporalHistory history;
  Image motion = motion_of(w, h, 0.25f, -0.5f);
  const Image a = random_image(w, h, 1);
  accumulate(a.view(), f.g, motion.view(), history, {});
  accumulate(a.view(), f.g, motion.view(), history, {});
  f.depth(3, 3) = 2.5f;      // 25 % deeper than every history tap: > 5 %
  f.normal(6, 4, 0) = 0.6f;  // cos = 0.8 < 0.9
  f.normal(6, 4, 2) = 0.8f;
  motion(9, 2, 0) = -20.0f;  // off the left edge
  motion(10, 6, 1) = kNan;   // NaN motion on geometry
  motion(0, 0, 0) = -0.75f;  // the taps at x = -1 drop, x = 0 is kept: not disoccluded
  const Image b = random_image(w, h, 2);
  const TemporalResult r = accumulate(b.view(), f.g, motion.view(), history, {});
  for (auto [x, y] : {std::pair{3, 3}, {6, 4}, {9, 2}, {10, 6}}) {
    EXPECT_EQ(bits(r.accumulated(x, y)), bits(b(x, y))) << x << "," << y;
    EXPECT_EQ(r.disoccluded(x, y), 1.0f) << x << "," << y;
    EXPECT_EQ(history.length(x, y), 1.0f) << x << "," << y;
  }
  EXPECT_EQ(r.disoccluded(0, 0), 0.0f);
  EXPECT_EQ(r.disoccluded(1, 1), 0.0f);
  EXPECT_EQ(history.length(1, 1), 3.0f);
}

// A depth tolerance of 10 keeps the 25 % jump; normal_tolerance = −1 keeps any normal.
TEST(Temporal, TolerancesDecideWhatIsKept) {
  Flat f;
  const int w = f.g.width(), h = f.g.height();
  const Image still = motion_of(w, h, 0, 0), a = random_image(w, h, 1);
  TemporalSettings s;
  s.depth_tolerance = 10.0f;
  s.normal_tolerance = -1.0f;
  TemporalHistory history;
  accumulate(a.view(), f.g, still.view(), history, s);
  f.depth(3, 3) = 2.5f;

  f.normal(5, 5, 0) = 1.0f;  // perpendicular to the history's normal
  f.normal(5, 5, 2) = 0.0f;
  const TemporalResult r = accumulate(a.view(), f.g, still.view(), history, s);
  for (float v : r.disoccluded.pixels()) EXPECT_EQ(v, 0.0f);
}

// Bilinear reprojection: an integer pan reads exactly the shifted history (one tap of weight
// 1); content moved k = 3 px right and 2 px up gives motion (−3, +2).
TEST(Temporal, IntegerPanReprojectsTheShiftedHistoryExactly) {
  Flat f(17, 11);
  const int w = f.g.width(), h = f.g.height(), k = 3, up = 2;
  const Image a = random_image(w, h, 5), b = random_image(w, h, 6);
  TemporalHistory history;
  accumulate(a.view(), f.g, motion_of(w, h, 0, 0).view(), history, unclamped(0));
  const Image pan = motion_of(w, h, float(-k), float(up));
  const TemporalResult r = accumulate(b.view(), f.g, pan.view(), history, unclamped(0));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int px = x - k, py = y + up;
      if (px < 0 || py >= h) {
        EXPECT_EQ(bits(r.accumulated(x, y)), bits(b(x, y)));
        EXPECT_EQ(r.disoccluded(x, y), 1.0f);
        continue;
      }
      const double past = a(px, py);
      EXPECT_EQ(bits(r.accumulated(x, y)), bits(float(past + 0.5 * (double(b(x, y)) - past))))
          << x << "," << y;
      EXPECT_EQ(r.disoccluded(x, y), 0.0f);
    }
}

// A half-pixel offset averages two taps; when one of them is rejected the other is read alone.
TEST(Temporal, BilinearTapsAreRenormalisedAfterRejection) {
  Flat f(8, 6);
  Image a(8, 6, 1, 0.0f);
  for (int y = 0; y < 6; ++y)
    for (int x = 0; x < 8; ++x) a(x, y) = 0.1f * float(x);
  TemporalHistory history;
  const TemporalSettings s = unclamped(0.0f);  // the second frame weighs 1/2
  accumulate(a.view(), f.g, motion_of(8, 6, 0, 0).view(), history, s);
  const Image zero(8, 6, 1, 0.0f);
  const Image half = motion_of(8, 6, 0.5f, 0.0f);
  TemporalHistory two = history;
  const TemporalResult r = accumulate(zero.view(), f.g, half.view(), two, s);
  EXPECT_NEAR(r.accumulated(2, 2), 0.5 * (0.5 * (a(2, 2) + a(3, 2))), 1e-7);
  history.depth(3, 2) = 9.0f;  // the right tap of (2, 2) now shows another surface
  const TemporalResult q = accumulate(zero.view(), f.g, half.view(), history, s);
  EXPECT_NEAR(q.accumulated(2, 2), 0.5 * a(2, 2), 1e-7);
  EXPECT_EQ(q.disoccluded(2, 2), 0.0f);
}

// The clamp keeps the result inside the current 3x3 neighbourhood's range; without it the
// result stays within the range of every input so far. Sub-pixel motion, both clamps.
TEST(Temporal, ResultStaysWithinTheRangeItIsHeldTo) {
  Flat f(23, 17);
  const int w = f.g.width(), h = f.g.height();
  for (int clamp : {0, 1, 2}) {
    TemporalSettings s;
    s.clamp = clamp;
    s.alpha = 0.05f;
    TemporalHistory history;
    float lo_all = 1.0f, hi_all = 0.0f;
    for (int k = 0; k < 6; ++k) {
      const Image ao = random_image(w, h, 40 + k, 0.2f + 0.05f * float(k), 0.5f + 0.08f * float(k));
      for (float v : ao.pixels()) lo_all = std::min(lo_all, v), hi_all = std::max(hi_all, v);
      const Image motion = random_image(w, 2 * h, 90 + k, -1.5f, 1.5f);
      const ConstImageView mv(motion.data(), w, h, 2);
      const TemporalResult r = accumulate(ao.view(), f.g, mv, history, s);
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
          const float v = r.accumulated(x, y);
          ASSERT_GE(v, lo_all);
          ASSERT_LE(v, hi_all);
          if (clamp == 0) continue;
          float lo = 1.0f, hi = 0.0f;
          for (int yy = std::max(0, y - 1); yy <= std::min(h - 1, y + 1); ++yy)
            for (int xx = std::max(0, x - 1); xx <= std::min(w - 1, x + 1); ++xx)
              lo = std::min(lo, ao(xx, yy)), hi = std::max(hi, ao(xx, yy));
          ASSERT_GE(v, lo) << "clamp " << clamp << " at " << x << "," << y;
          ASSERT_LE(v, hi) << "clamp " << clamp << " at " << x << "," << y;
        }
    }
  }
}

// Per pixel: the same bits, history included, on 1, 2 and 8 threads.
TEST(Temporal, SameBitsForAnyThreadCount) {
  Flat f(31, 29);
  const int w = f.g.width(), h = f.g.height();
  f.depth(4, 4) = kNan;
  for (int x = 10; x < 20; ++x) f.depth(x, 12) = 3.0f;
  std::vector<TemporalResult> results;
  std::vector<TemporalHistory> histories;
  for (int threads : {1, 2, 8}) {
    TemporalHistory history;
    TemporalResult r;
    TemporalSettings s;
    s.clamp = int(TemporalClamp::Variance);
    for (int k = 0; k < 4; ++k) {
      const Image ao = random_image(w, h, 7 + k);
      const Image motion = random_image(w, 2 * h, 11 + k, -2.0f, 2.0f);
      r = accumulate(ao.view(), f.g, ConstImageView(motion.data(), w, h, 2), history, s, threads);
    }
    results.push_back(std::move(r));
    histories.push_back(std::move(history));
  }
  for (std::size_t i = 1; i < results.size(); ++i) {
    EXPECT_EQ(results[i].accumulated.pixels(), results[0].accumulated.pixels());
    EXPECT_EQ(results[i].disoccluded.pixels(), results[0].disoccluded.pixels());
    EXPECT_EQ(histories[i].length.pixels(), histories[0].length.pixels());
  }
}

// Background: the current value, never flagged, history length 0.
TEST(Temporal, BackgroundKeepsTheCurrentValue) {
  Flat f(6, 5);
  f.depth(2, 2) = 1e10f;
  TemporalHistory history;
  const Image still = motion_of(6, 5, 0, 0), ao = random_image(6, 5, 3);
  accumulate(ao.view(), f.g, still.view(), history, {});
  const Image one(6, 5, 1, 1.0f);
  const TemporalResult r = accumulate(one.view(), f.g, still.view(), history, {});
  EXPECT_EQ(r.accumulated(2, 2), 1.0f);
  EXPECT_EQ(r.disoccluded(2, 2), 0.0f);
  EXPECT_EQ(history.length(2, 2), 0.0f);
}

std::string message_of(const std::function<void()>& call) {
  try {
    call();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "no exception";
}

TEST(Temporal, RejectsBadInputNamingIt) {
  Flat f(6, 5);
  const Image ao = random_image(6, 5, 1), still = motion_of(6, 5, 0, 0);
  TemporalHistory history;
  TemporalSettings s;
  s.alpha = 1.5f;
  EXPECT_EQ(message_of([&] { accumulate(ao.view(), f.g, still.view(), history, s); }),
            "alpha must be in [0, 1], got 1.5");
  s = {};
  s.clamp = 3;
  EXPECT_EQ(message_of([&] { accumulate(ao.view(), f.g, still.view(), history, s); }),
            "clamp must be one of off, minmax, variance, got 3");
  const Image three(6, 5, 3);
  EXPECT_EQ(message_of([&] { accumulate(ao.view(), f.g, three.view(), history, {}); }),
            "motion must have 2 channels (dx, dy in pixels), got 3");
  const Image small = motion_of(5, 5, 0, 0);
  EXPECT_EQ(message_of([&] { accumulate(ao.view(), f.g, small.view(), history, {}); }),
            "motion must have the size of depth (6x5), got 5x5");
  const Image wide = random_image(7, 5, 1);
  EXPECT_EQ(message_of([&] { accumulate(wide.view(), f.g, still.view(), history, {}); }),
            "ao must have the size of depth (6x5), got 7x5");
  Image nan_ao = ao;
  nan_ao(4, 1) = kNan;
  EXPECT_EQ(message_of([&] { accumulate(nan_ao.view(), f.g, still.view(), history, {}); }),
            "ao must be finite on geometry pixels (at 4, 1), got nan");
  EXPECT_TRUE(history.empty());  // nothing was accumulated by the failed calls
  accumulate(ao.view(), f.g, still.view(), history, {});
  Flat other(7, 5);
  const Image ao7 = random_image(7, 5, 1), still7 = motion_of(7, 5, 0, 0);
  EXPECT_EQ(message_of([&] { accumulate(ao7.view(), other.g, still7.view(), history, {}); }),
            "history must be empty (frame 0) or from frames of this size (7x5x1, normals x3; "
            "reset it when the size changes), got 6x5x1");
  EXPECT_EQ(history.width(), 6);  // left as it was
  EXPECT_THROW(accumulate(ao.view(), f.g, still.view(), history, {}, -1), std::invalid_argument);
}

TEST(FrameSeed, FrameZeroKeepsTheSeedAndLaterFramesDiffer) {
  for (std::uint32_t seed : {0u, 1u, 12345u, kMaxSeed}) {
    EXPECT_EQ(frame_seed(seed, 0), seed);
    std::vector<std::uint32_t> seen = {seed};
    for (std::uint32_t frame = 1; frame < 64; ++frame) {
      const std::uint32_t s = frame_seed(seed, frame);
      EXPECT_GE(s, 1u);
      EXPECT_LE(s, kMaxSeed);
      EXPECT_EQ(std::count(seen.begin(), seen.end(), s), 0) << seed << " frame " << frame;
      seen.push_back(s);
    }
  }
}

// A real method: HBAO (8 directions) at frame_seed(0, k), accumulated over 16 static frames
// with alpha = 0, is much closer to HBAO with 64 directions than one frame is. Its
// estimator is unbiased over the random rotation and jitter, so the accumulated error falls
// towards the 64-direction result's own noise; the bound 0.5 is far from the measured ratio
// (in the comment below) and far below 1, which frames that did not vary would give.
TEST(Temporal, AccumulatedHbaoConvergesTowardsManyDirections) {
  testing::SceneFixture scene("blocks", 96, 54);
  HbaoSettings s;
  s.radius = 0.5f;
  HbaoSettings many = s;
  many.directions = 64;
  many.seed = 977;
  const Image reference = hbao(scene.g, many);
  const Image still = motion_of(96, 54, 0, 0);
  TemporalHistory history;
  Image first, accumulated;
  TemporalSettings t = unclamped(0);
  for (int k = 0; k < 16; ++k) {
    s.seed = int(frame_seed(0, std::uint32_t(k)));
    const Image ao = hbao(scene.g, s);
    accumulated = accumulate(ao.view(), scene.g, still.view(), history, t).accumulated;
    if (k == 0) first = ao;
  }
  double e1 = 0.0, en = 0.0;
  int n = 0;
  for (int y = 0; y < 54; ++y)
    for (int x = 0; x < 96; ++x) {
      if (!scene.g.valid(x, y)) continue;
      e1 += std::abs(first(x, y) - reference(x, y));
      en += std::abs(accumulated(x, y) - reference(x, y));
      ++n;
    }
  e1 /= n, en /= n;
  std::printf("HBAO 8 directions vs 64: one frame %.4f, 16 frames accumulated %.4f\n", e1, en);
  EXPECT_LT(en, 0.5 * e1);
}

}  // namespace
}  // namespace aolab
