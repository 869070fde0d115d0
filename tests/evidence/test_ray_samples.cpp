// Tests of the ray samples of the visual sensor model (Fig 4.2b), seam copies and pads (§4.9.1).
#include <cmath>
#include <cstddef>

#include "algo/core/angles.h"
#include "algo/core/fixed_vector.h"
#include "algo/evidence/ray_samples.h"
#include "alloc_guard.h"
#include "CppUTest/TestHarness.h"

using namespace boticelli;
using namespace boticelli::evidence;

TEST_GROUP(RaySamples) {
  core::FixedVector<RaySample, 512> samples;
  RaySampleParams params;
  const Reading reading{1.0F, 0.6F, 3.0F, 0.9F};  // α = 1 rad, h = 0.6 m, r = 3 m, m = 0.9
};

TEST(RaySamples, DefaultReadingExpandsIntoFiveSamplesPlacedAsTheThesisSays) {
  LONGS_EQUAL(5, append_plausibility_samples(reading, params, samples));
  LONGS_EQUAL(5, samples.size());
  // Plateau at evidence m around r ± δr, δr = 0.3 m.
  DOUBLES_EQUAL(3.3, samples[0].r_m, 1e-5);
  DOUBLES_EQUAL(0.9, samples[0].occupancy, 1e-6);
  DOUBLES_EQUAL(2.7, samples[1].r_m, 1e-5);
  DOUBLES_EQUAL(0.9, samples[1].occupancy, 1e-6);
  // Two lower samples towards the camera: 2/3 m at r − 2δr, 1/3 m at r − 3δr.
  DOUBLES_EQUAL(2.4, samples[2].r_m, 1e-5);
  DOUBLES_EQUAL(0.6, samples[2].occupancy, 1e-6);
  DOUBLES_EQUAL(2.1, samples[3].r_m, 1e-5);
  DOUBLES_EQUAL(0.3, samples[3].occupancy, 1e-6);
  // The robot centre, empty.
  DOUBLES_EQUAL(0.0, samples[4].r_m, 1e-9);
  DOUBLES_EQUAL(0.0, samples[4].h_m, 1e-9);
  DOUBLES_EQUAL(0.0, samples[4].occupancy, 1e-9);
}

TEST(RaySamples, LineOfSightSamplesAreFreeAndEvenlySpacedBetweenTheRobotAndTheRampsFoot) {
  params.line_of_sight_samples = 3;
  LONGS_EQUAL(8, plausibility_samples_per_reading(params));
  LONGS_EQUAL(8, append_plausibility_samples(reading, params, samples));
  LONGS_EQUAL(8, samples.size());
  // The thesis's five come first, unchanged; the ramp's foot is at r − 4δr = 1.8 m, so the
  // three lie at 0.45, 0.9 and 1.35 m on the ray of view, each with occupancy 0.
  DOUBLES_EQUAL(3.3, samples[0].r_m, 1e-5);
  DOUBLES_EQUAL(0.0, samples[4].r_m, 1e-9);
  for (std::size_t j = 1; j <= 3; ++j) {
    const RaySample& s = samples[4 + j];
    DOUBLES_EQUAL(0.45 * static_cast<double>(j), s.r_m, 1e-5);
    DOUBLES_EQUAL(0.2 * static_cast<double>(s.r_m), s.h_m, 1e-5);
    DOUBLES_EQUAL(1.0, s.alpha_rad, 1e-9);
    DOUBLES_EQUAL(0.0, s.occupancy, 1e-9);
  }
  // Belief samples carry them too, before the ramp mirrored behind the point.
  samples.clear();
  LONGS_EQUAL(belief_samples_per_reading(params), append_belief_samples(reading, params, samples));
  LONGS_EQUAL(11, samples.size());
  DOUBLES_EQUAL(1.35, samples[7].r_m, 1e-5);
}

TEST(RaySamples, LineOfSightSamplesStartAtTheReadingsViewNotAtThePtuCentre) {
  // The point 2 m ahead at pan 0, level; seen from an optical centre 0.21 m to its side and
  // 0.1 m down: the free samples lie on that line of sight, at j/3 of the way from the view
  // to the ramp's foot, 4δr = 0.8 m short of the point along it.
  Reading side{0.0F, 0.0F, 2.0F, 0.9F};
  side.view_y_m = 0.21F;
  side.view_z_m = -0.1F;
  params.line_of_sight_samples = 2;
  LONGS_EQUAL(7, append_plausibility_samples(side, params, samples));
  const double vx = 0.0;
  const double vy = 0.21;
  const double vz = -0.1;
  const double d = std::sqrt(2.0 * 2.0 + vy * vy + vz * vz);
  for (std::size_t j = 1; j <= 2; ++j) {
    const RaySample& s = samples[4 + j];
    const double t = (d - 0.8) / d * static_cast<double>(j) / 3.0;
    const double x = vx + t * (2.0 - vx);
    const double y = vy + t * (0.0 - vy);
    const double z = vz + t * (0.0 - vz);
    DOUBLES_EQUAL(std::sqrt(x * x + y * y + z * z), s.r_m, 1e-5);
    DOUBLES_EQUAL(z, s.h_m, 1e-5);
    DOUBLES_EQUAL(std::atan2(y, x), s.alpha_rad, 1e-5);
    DOUBLES_EQUAL(0.0, s.occupancy, 1e-9);
  }
  // The thesis's five are where they were: on the ray from the PTU centre.
  DOUBLES_EQUAL(2.2, samples[0].r_m, 1e-5);
  DOUBLES_EQUAL(0.0, samples[0].alpha_rad, 1e-9);
}

TEST(RaySamples, WithoutLowerSamplesTheLineOfSightEndsAtTheNearPlateauSample) {
  params.samples_per_reading = 3;
  params.line_of_sight_samples = 1;
  LONGS_EQUAL(4, append_plausibility_samples(reading, params, samples));
  DOUBLES_EQUAL(1.35, samples[3].r_m, 1e-5);  // half of r − δr = 2.7 m
  DOUBLES_EQUAL(0.0, samples[3].occupancy, 1e-9);
}

TEST(RaySamples, TheStereoSizedModelIsSharperThanTheThesisAndSeesThroughItsLineOfSight) {
  const RaySampleParams stereo = stereo_ray_sample_params();
  CHECK(stereo.delta_r_fraction < params.delta_r_fraction);
  LONGS_EQUAL(stereo.samples_per_reading + 2, plausibility_samples_per_reading(stereo));
  LONGS_EQUAL(7, append_plausibility_samples(reading, stereo, samples));
  DOUBLES_EQUAL(3.0 * (1.0 + double{kStereoDeltaRFraction}), samples[0].r_m, 1e-5);
}

TEST(RaySamples, SamplesLieOnTheRayOfViewSoHeightScalesWithDistance) {
  (void)append_plausibility_samples(reading, params, samples);
  for (const RaySample& s : samples) {
    DOUBLES_EQUAL(1.0, s.alpha_rad, 1e-9);
    DOUBLES_EQUAL(0.2 * static_cast<double>(s.r_m), s.h_m, 1e-5);
  }
}

TEST(RaySamples, PlausibilitySamplesNeverDecreaseAwayFromTheCamera) {
  params.samples_per_reading = 9;
  LONGS_EQUAL(9, append_plausibility_samples(reading, params, samples));
  // Sort-free check: for every pair, the farther sample has at least the occupancy.
  for (const RaySample& a : samples) {
    for (const RaySample& b : samples) {
      if (b.r_m > a.r_m) {
        CHECK(b.occupancy >= a.occupancy - 1e-6F);
      }
    }
  }
}

TEST(RaySamples, BeliefSamplesFallBackToZeroBehindThePoint) {
  const std::size_t n = append_belief_samples(reading, params, samples);
  LONGS_EQUAL(8, n);
  LONGS_EQUAL(belief_samples_per_reading(params), n);
  float far_r = 0.0F;
  float far_occ = 1.0F;
  float max_occ = 0.0F;
  for (const RaySample& s : samples) {
    if (s.r_m > far_r) {
      far_r = s.r_m;
      far_occ = s.occupancy;
    }
    max_occ = std::fmax(max_occ, s.occupancy);
  }
  DOUBLES_EQUAL(0.0, far_occ, 1e-9);
  CHECK(far_r > 3.3F);
  DOUBLES_EQUAL(0.9, max_occ, 1e-6);
  // The first five are the plausibility samples, so Bel ≤ Pl holds sample by sample.
  core::FixedVector<RaySample, 16> pl;
  (void)append_plausibility_samples(reading, params, pl);
  for (std::size_t i = 0; i < pl.size(); ++i) {
    DOUBLES_EQUAL(pl[i].r_m, samples[i].r_m, 1e-9);
  }
}

TEST(RaySamples, AFullBufferTakesNoPartOfAReading) {
  core::FixedVector<RaySample, 7> small;
  LONGS_EQUAL(5, append_plausibility_samples(reading, params, small));
  LONGS_EQUAL(0, append_plausibility_samples(reading, params, small));
  LONGS_EQUAL(5, small.size());
  core::FixedVector<RaySample, 6> six;
  params.line_of_sight_samples = 2;  // 7 samples: none fit in 6
  LONGS_EQUAL(0, append_plausibility_samples(reading, params, six));
  CHECK(six.empty());
}

TEST(RaySamples, InvalidParametersOrRangesGiveNoSamples) {
  params.samples_per_reading = 2;
  LONGS_EQUAL(0, append_plausibility_samples(reading, params, samples));
  params.samples_per_reading = 5;
  params.line_of_sight_samples = kMaxSamplesPerReading + 1;
  LONGS_EQUAL(0, append_plausibility_samples(reading, params, samples));
  params.line_of_sight_samples = 0;
  LONGS_EQUAL(0, append_plausibility_samples({0.0F, 0.0F, 0.0F, 0.9F}, params, samples));
  CHECK(samples.empty());
}

TEST(RaySamples, ManyReadingsExpandWithoutAllocating) {
  core::FixedVector<Reading, 32> readings;
  for (int i = 0; i < 32; ++i) {
    (void)readings.push_back({0.2F * static_cast<float>(i), 0.1F, 2.0F, 0.8F});
  }
  std::size_t fitted = 0;
  CHECK_NO_ALLOCATION(fitted = append_ray_samples(readings.span(), params, samples));
  LONGS_EQUAL(32, fitted);
  LONGS_EQUAL(160, samples.size());
  LONGS_EQUAL(32, append_ray_samples(readings.span(), params, samples, OccupancyBound::kBelief));
  LONGS_EQUAL(160 + 32 * 8, samples.size());
}

TEST(RaySamples, SeamCopiesMirrorSamplesNearZeroAndTwoPi) {
  const float two_pi = core::kTwoPi<float>;
  (void)samples.push_back({0.1F, 0.0F, 1.0F, 0.9F});
  (void)samples.push_back({3.0F, 0.0F, 1.0F, 0.9F});
  (void)samples.push_back({two_pi - 0.2F, 0.0F, 1.0F, 0.5F});
  LONGS_EQUAL(2, append_seam_copies(samples, 0.5F));
  LONGS_EQUAL(5, samples.size());
  DOUBLES_EQUAL(0.1 + 2.0 * 3.14159265, samples[3].alpha_rad, 1e-5);
  DOUBLES_EQUAL(-0.2, samples[4].alpha_rad, 1e-5);
  DOUBLES_EQUAL(0.5, samples[4].occupancy, 1e-9);
}

TEST(RaySamples, ZeroPadsStayInTheirRegionAndRepeatForTheSameSeed) {
  PadRegion region{0.0F, 1.0F, -0.5F, 0.5F, 1.0F, 2.0F};
  PadRandom a{42U};
  LONGS_EQUAL(100, append_zero_pads(region, 100, a, samples));
  for (const RaySample& s : samples) {
    CHECK(s.alpha_rad >= 0.0F && s.alpha_rad <= 1.0F);
    CHECK(s.h_m >= -0.5F && s.h_m <= 0.5F);
    CHECK(s.r_m >= 1.0F && s.r_m <= 2.0F);
    DOUBLES_EQUAL(0.0, s.occupancy, 1e-12);
  }
  core::FixedVector<RaySample, 256> again;
  PadRandom b{42U};
  (void)append_zero_pads(region, 100, b, again);
  DOUBLES_EQUAL(samples[57].r_m, again[57].r_m, 0.0);
}

TEST(RaySamples, FeaturelessPadsGoOnlyInDirectionsWithoutReadings) {
  // Readings cover α ∈ [0, π) at elevations within ±0.3 rad; the rest is featureless.
  core::FixedVector<Reading, 64> readings;
  for (int i = 0; i < 64; ++i) {
    const float a = 3.1F * static_cast<float>(i) / 64.0F;
    const float el = -0.25F + 0.5F * static_cast<float>(i % 8) / 8.0F;
    (void)readings.push_back({a, 2.0F * std::sin(el), 2.0F, 0.9F});
  }
  PadRegion region{};  // α ∈ [0, 2π), h ∈ [−1, 1] m, r ∈ [0, 4.5] m
  FeaturelessPadParams pads;
  pads.alpha_bins = 8;
  pads.elevation_bins = 4;
  pads.elevation_min_rad = -0.6F;
  pads.elevation_max_rad = 0.6F;
  pads.pads_per_empty_cell = 5;
  PadRandom random{7U};
  const std::size_t added = append_featureless_pads(readings.span(), region, pads, random, samples);
  // Seen: α bins 0..3 x elevation bins 1, 2 (|el| < 0.3). Empty: 32 − 8 cells.
  LONGS_EQUAL(24 * 5, added);
  for (const RaySample& s : samples) {
    const float el = std::asin(s.h_m / s.r_m);
    const bool seen_dir = s.alpha_rad < core::kPi<float> && std::fabs(el) < 0.3F;
    CHECK_FALSE(seen_dir);
    CHECK(s.h_m >= -1.0F - 1e-5F && s.h_m <= 1.0F + 1e-5F);  // never below the floor
    DOUBLES_EQUAL(0.0, s.occupancy, 1e-12);
  }
}
