// Tests of algo/image: YUYV downsampling, feature selection, Eq 3.1 match error, epipolar tracking.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <utility>
#include <vector>

#include "algo/core/fixed_vector.h"
#include "algo/image/epipolar_tracker.h"
#include "algo/image/features.h"
#include "algo/image/low_res_frame.h"
#include "CppUTest/TestHarness.h"
#include "alloc_guard.h"

using namespace boticelli;
using namespace boticelli::image;

namespace {

LowResFrame& frame_a() {
  static LowResFrame f;
  return f;
}
LowResFrame& frame_b() {
  static LowResFrame f;
  return f;
}

// A smooth, non-repeating luma pattern shifted down by `shift_v` rows.
void fill_pattern(LowResFrame& f, float shift_v) {
  f.width = 160;
  f.height = 120;
  for (std::uint32_t v = 0; v < f.height; ++v) {
    for (std::uint32_t u = 0; u < f.width; ++u) {
      const float x = static_cast<float>(u);
      const float y = static_cast<float>(v) - shift_v;
      f.luma[f.index(u, v)] = 128.0F + 50.0F * std::sin(0.55F * y + 0.21F * x) +
                              30.0F * std::sin(0.37F * y - 0.53F * x + 0.002F * x * y) +
                              20.0F * std::cos(0.13F * y * y / 40.0F + 0.3F * x);
    }
  }
}

}  // namespace

TEST_GROUP(Image){};

TEST(Image, DownsamplingAveragesLumaAndChromaOverFourByFourBlocks) {
  const std::uint32_t w = 16;
  const std::uint32_t h = 8;
  std::vector<std::uint8_t> yuyv(w * h * 2);
  for (std::uint32_t v = 0; v < h; ++v) {
    for (std::uint32_t u = 0; u < w; u += 2) {
      std::uint8_t* p = &yuyv[(v * w + u) * 2];
      p[0] = static_cast<std::uint8_t>(u + v);
      p[1] = static_cast<std::uint8_t>(100 + v);
      p[2] = static_cast<std::uint8_t>(u + 1 + v);
      p[3] = static_cast<std::uint8_t>(200 - u);
    }
  }
  LowResFrame& out = frame_a();
  CHECK(downsample_yuyv(yuyv.data(), w, h, w * 2, 4, out));
  LONGS_EQUAL(4, out.width);
  LONGS_EQUAL(2, out.height);
  // Block (1, 1): u 4..7, v 4..7 → mean of u + v = 5.5 + 5.5 = 11.
  DOUBLES_EQUAL(11.0, out.y(1, 1), 1e-6);
  // U: 100 + v averaged over v 4..7 = 105.5 → rounds to 106; V: 200 − u over u 4, 6 = 195.
  LONGS_EQUAL(106, out.chroma_u[out.index(1, 1)]);
  LONGS_EQUAL(195, out.chroma_v[out.index(1, 1)]);
  CHECK_FALSE(downsample_yuyv(yuyv.data(), 15, h, w * 2, 4, out));  // odd width
  CHECK_FALSE(downsample_yuyv(yuyv.data(), w, h, w * 2, 3, out));   // odd factor
}

TEST(Image, FeaturesAreStrongestVerticalDerivativesInsideTheBandAndSpreadOut) {
  LowResFrame& f = frame_a();
  fill_pattern(f, 0.0F);
  FeatureParams params;
  params.max_features = 100;
  FeatureSelector selector(params);
  static core::FixedVector<Feature, 1024> features;
  const BandGeometry band{79.5F, 59.5F, 150.0F};
  std::size_t n = 0;
  CHECK_NO_ALLOCATION(n = selector.select(f, band, features));
  LONGS_EQUAL(100, n);
  for (std::size_t i = 0; i < n; ++i) {
    const Feature& a = features[i];
    CHECK(std::fabs(static_cast<float>(a.u_px) - 79.5F) <= 53.0F);
    CHECK(std::fabs(static_cast<float>(a.v_px) - 59.5F) <= 40.0F);
    if (i > 0) {
      CHECK(features[i - 1].strength >= a.strength);  // strongest first
    }
    const float g = 0.5F * std::fabs(f.y(a.u_px, a.v_px + 1U) - f.y(a.u_px, a.v_px - 1U));
    DOUBLES_EQUAL(g, a.strength, 1e-4);
    for (std::size_t j = 0; j < i; ++j) {  // non-maximum suppression: no two adjacent
      const int du = std::abs(int{a.u_px} - int{features[j].u_px});
      const int dv = std::abs(int{a.v_px} - int{features[j].v_px});
      CHECK(du > 1 || dv > 1);
    }
  }
  // The band scales with F: at F = 75 it is half as wide.
  selector.select(f, {79.5F, 59.5F, 75.0F}, features);
  for (const Feature& a : features) {
    CHECK(std::fabs(static_cast<float>(a.u_px) - 79.5F) <= 26.5F);
  }
}

TEST(Image, AnEdgeWeakerThanTheMinimumStrengthGivesNoFeatures) {
  // Two horizontal edges across the band whose height varies along them: a step of
  // 3 ± 0.6 grey levels at row 40 (derivative at most 1.8 per px, below min_strength = 2)
  // and one of 6 ± 2 at row 80 (2–4 per px).
  LowResFrame& f = frame_a();
  f.width = 160;
  f.height = 120;
  for (std::uint32_t v = 0; v < f.height; ++v) {
    for (std::uint32_t u = 0; u < f.width; ++u) {
      const float wave = std::sin(0.5F * static_cast<float>(u));
      f.luma[f.index(u, v)] =
          100.0F + (v >= 40 ? 3.0F + 0.6F * wave : 0.0F) + (v >= 80 ? 6.0F + 2.0F * wave : 0.0F);
    }
  }
  FeatureParams params;
  FeatureSelector selector(params);
  static core::FixedVector<Feature, 1024> features;
  const std::size_t n = selector.select(f, {79.5F, 59.5F, 150.0F}, features);
  CHECK(n >= 5);
  for (std::size_t i = 0; i < n; ++i) {
    CHECK(features[i].v_px >= 78 && features[i].v_px <= 81);
    CHECK(features[i].strength >= params.min_strength);
  }
}

TEST(Image, MatchErrorIsTheSumOfSquaredDifferencesOfCentreRemovedWindows) {
  LowResFrame& a = frame_a();
  LowResFrame& b = frame_b();
  a.width = b.width = 8;
  a.height = b.height = 8;
  for (std::size_t i = 0; i < 64; ++i) {
    a.luma[i] = static_cast<float>(i % 7);
    b.luma[i] = static_cast<float>(i % 7) + 10.0F;  // a brightness offset alone costs nothing
  }
  DOUBLES_EQUAL(0.0, match_error(a, 3, 3, b, 3, 3), 1e-4);
  // One window pixel off by 3 grey levels: E = 3² = 9.
  b.luma[b.index(2, 4)] += 3.0F;
  DOUBLES_EQUAL(9.0, match_error(a, 3, 3, b, 3, 3), 1e-4);
  // The centre off by 2: each of the 24 others differs by 2 once the centre is removed,
  // and the one already off by 3 now by 1: 23·4 + 1 = 93.
  b.luma[b.index(3, 3)] += 2.0F;
  DOUBLES_EQUAL(93.0, match_error(a, 3, 3, b, 3, 3), 1e-4);
}

TEST(Image, TrackingFindsASubPixelVerticalShiftAlongTheEpipolarSegment) {
  LowResFrame& a = frame_a();
  LowResFrame& b = frame_b();
  TrackParams params;
  // The pattern is far sharper than a 4x4-averaged camera image (up to 45 grey levels per
  // pixel), so half a pixel off costs E of thousands: the threshold is not under test here.
  params.match_error_thresh = 1e6F;
  for (const float shift : {2.0F, 3.3F, 5.5F, 7.8F}) {
    fill_pattern(a, 0.0F);
    fill_pattern(b, shift);
    int found = 0;
    float worst = 0.0F;
    std::vector<float> errors;
    for (std::uint32_t u = 40; u < 120; u += 9) {
      for (std::uint32_t v = 30; v < 80; v += 7) {
        const EpipolarSegment segment{static_cast<float>(u), static_cast<float>(v),
                                      static_cast<float>(u) + 0.2F, static_cast<float>(v) + 12.0F};
        Track t;
        CHECK_NO_ALLOCATION(t = track_feature(a, u, v, b, segment, params));
        if (!t.found) continue;
        ++found;
        errors.push_back(std::fabs(t.v_px - (static_cast<float>(v) + shift)));
        worst = std::fmax(worst, errors.back());
        CHECK(std::fabs(t.u_px - (static_cast<float>(u) +
                                  0.2F * (t.v_px - static_cast<float>(v)) / 12.0F)) < 1e-3F);
      }
    }
    CHECK(found > 50);
    std::sort(errors.begin(), errors.end());
    // Integer search alone would be off by 0, 0.3, 0.5 and 0.2 px for these shifts.
    CHECK(errors[errors.size() / 2] < 0.1F);
    CHECK(worst < 0.45F);
  }
}

TEST(Image, RepeatedTextureAlongTheLineIsRejectedAsAmbiguous) {
  LowResFrame& a = frame_a();
  a.width = 40;
  a.height = 40;
  for (std::uint32_t v = 0; v < 40; ++v) {
    for (std::uint32_t u = 0; u < 40; ++u) {
      a.luma[a.index(u, v)] = (v / 2) % 2 == 0 ? 200.0F : 50.0F;  // stripes of period 4 rows
    }
  }
  const EpipolarSegment segment{20.0F, 10.0F, 20.0F, 25.0F};
  TrackParams params;
  CHECK_FALSE(track_feature(a, 20, 10, a, segment, params).found);
  params.distinctiveness = 1.0F;
  CHECK(track_feature(a, 20, 10, a, segment, params).found);
  params.match_error_thresh = 0.0F;  // nothing is below a zero threshold
  params.normalized_error_thresh = 0.0F;
  CHECK_FALSE(track_feature(a, 20, 10, a, segment, params).found);
}

TEST(Image, AMatchThatLeftTheImageIsNotReportedAtTheBorder) {
  LowResFrame& a = frame_a();
  LowResFrame& b = frame_b();
  fill_pattern(a, 0.0F);
  fill_pattern(b, -8.0F);  // the scene moved up by 8 rows
  TrackParams params;
  params.match_error_thresh = 1e7F;
  params.distinctiveness = 1.0F;
  // The feature at row 9 moved to row 1, where its window no longer fits: the search is
  // cut at row 2, whose error is then the lowest, and must not report it as the match.
  const EpipolarSegment off_image{60.0F, 9.0F, 60.0F, -10.0F};
  CHECK_FALSE(track_feature(a, 60, 9, b, off_image, params).found);
  // The same motion lower down is found.
  const EpipolarSegment inside{60.0F, 40.0F, 60.0F, 23.0F};
  const Track t = track_feature(a, 60, 40, b, inside, params);
  CHECK(t.found);
  DOUBLES_EQUAL(32.0, t.v_px, 0.05);
}

TEST(Image, TheBandReachesTheImageBottomWhenItsLowerHalfIsSetApart) {
  LowResFrame& f = frame_a();
  fill_pattern(f, 0.0F);
  static core::FixedVector<Feature, 1024> features;
  const BandGeometry band{79.5F, 59.5F, 150.0F};
  const auto lowest = [&](const FeatureParams& params) {
    FeatureSelector selector(params);
    selector.select(f, band, features);
    std::uint32_t v_max = 0;
    std::uint32_t v_min = f.height;
    for (const Feature& a : features) {
      v_max = std::max<std::uint32_t>(v_max, a.v_px);
      v_min = std::min<std::uint32_t>(v_min, a.v_px);
    }
    return std::pair{v_min, v_max};
  };
  FeatureParams thesis;
  thesis.max_features = 1000;
  const auto [top, bottom] = lowest(thesis);
  CHECK(bottom <= 99U);  // 59.5 + 40
  FeatureParams low = thesis;
  low.band_half_height_below_at_f150_px = 60.0F;
  const auto [top_low, bottom_low] = lowest(low);
  LONGS_EQUAL(top, top_low);  // the upper half is the thesis's
  CHECK(bottom_low > 110U);   // down to the 5x5 window's and the 3x3 test's border
  CHECK(bottom_low <= f.height - 4U);
}

// An occlusion edge: a near surface (dark, rows above the edge) over a far one (bright, with
// a dark line two rows below the edge). Between the frames the near surface moves up 10 rows
// and the far one 8, so the centred 5x5 window, which holds both, matches neither.
TEST(Image, AShiftedWindowMatchesTheNearSideOfAnOcclusionEdge) {
  LowResFrame& a = frame_a();
  LowResFrame& b = frame_b();
  const auto scene = [](LowResFrame& f, int edge_row, int line_row) {
    f.width = 160;
    f.height = 120;
    for (std::uint32_t v = 0; v < f.height; ++v) {
      for (std::uint32_t u = 0; u < f.width; ++u) {
        const int row = static_cast<int>(v);
        f.luma[f.index(u, v)] = row < edge_row ? 60.0F : (row == line_row ? 110.0F : 170.0F);
      }
    }
  };
  scene(a, 60, 62);
  scene(b, 50, 54);
  const EpipolarSegment segment{80.0F, 56.0F, 80.0F, 40.0F};  // infinity at 56, near at 40
  TrackParams params;
  params.normalized_error_thresh = 0.0F;  // E_thresh alone, as the thesis
  const Track centred = track_feature(a, 80, 60, b, segment, params);
  CHECK_FALSE(centred.found);
  CHECK(centred.match_error > params.match_error_thresh);
  params.window_shift_px = 2;
  Track t;
  CHECK_NO_ALLOCATION(t = track_feature(a, 80, 60, b, segment, params));
  CHECK(t.found);
  DOUBLES_EQUAL(50.0, t.v_px, 0.1);  // the edge's own motion, not the far surface's
  DOUBLES_EQUAL(80.0, t.u_px, 1e-3);
}
