// Tests of the TargetTracker: a goal only when two distinct views agree; outliers, NaN, refinement.
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>

#include <Eigen/Core>

#include "firmware/mission/target/target_tracker.h"

#include "CppUTest/TestHarness.h"

using boticelli::firmware::mission::TargetTracker;
using boticelli::firmware::mission::TargetTrackerParams;

namespace {

const Eigen::Vector3f kTarget(2.0F, 1.0F, 0.3F);  // world frame [m]

void check_near(const Eigen::Vector3f& expected, const Eigen::Vector3f& actual, float tol_m) {
  DOUBLES_EQUAL(expected.x(), actual.x(), tol_m);
  DOUBLES_EQUAL(expected.y(), actual.y(), tol_m);
  DOUBLES_EQUAL(expected.z(), actual.z(), tol_m);
}

}  // namespace

TEST_GROUP(TargetTracker) {
  TargetTracker tracker;
  void setup() override {
    tracker.configure(TargetTrackerParams{});
  }
};

TEST(TargetTracker, OneSightingNeverConfirms) {
  tracker.add(kTarget, 0.9F, 1);
  CHECK_FALSE(tracker.confirmed());
  UNSIGNED_LONGS_EQUAL(1, tracker.sightings());
  UNSIGNED_LONGS_EQUAL(1, tracker.supporting_views());
}

TEST(TargetTracker, AnUnconfirmedSightingIsTheCandidateToLookAtAgain) {
  const Eigen::Vector3f lone = kTarget + Eigen::Vector3f(2.0F, 0.0F, 0.0F);
  tracker.add(lone, 0.9F, 1);
  CHECK_FALSE(tracker.confirmed());
  check_near(lone, tracker.candidate_m(), 1e-6F);
  // Two views of the target outvote the lone sighting: confirmed, and the candidate with it.
  tracker.add(kTarget, 0.9F, 2);
  tracker.add(kTarget, 0.9F, 3);
  CHECK_TRUE(tracker.confirmed());
  check_near(kTarget, tracker.candidate_m(), 1e-5F);
  check_near(tracker.estimate_m(), tracker.candidate_m(), 1e-6F);
}

TEST(TargetTracker, TheCandidateIsTheMeanOfItsGroupNotOneOfItsSightings) {
  // Two sightings of one view 0.2 m apart, equally weighted: too few views to confirm, and
  // the candidate is their mean, whichever came first.
  const Eigen::Vector3f a = kTarget;
  const Eigen::Vector3f b = kTarget + Eigen::Vector3f(0.2F, 0.0F, 0.0F);
  tracker.add(a, 0.9F, 4);
  tracker.add(b, 0.9F, 4);
  CHECK_FALSE(tracker.confirmed());
  check_near(0.5F * (a + b), tracker.candidate_m(), 1e-5F);
}

TEST(TargetTracker, SightingsFromTheSameViewNeverConfirm) {
  for (int i = 0; i < 10; ++i) {
    tracker.add(kTarget + Eigen::Vector3f(0.01F * static_cast<float>(i), 0.0F, 0.0F), 0.9F, 7);
  }
  CHECK_FALSE(tracker.confirmed());
  UNSIGNED_LONGS_EQUAL(10, tracker.sightings());
  UNSIGNED_LONGS_EQUAL(1, tracker.supporting_views());
}

TEST(TargetTracker, TwoViewsWithinTheRadiusConfirmWithTheirMean) {
  const Eigen::Vector3f a = kTarget + Eigen::Vector3f(0.1F, 0.0F, 0.0F);
  const Eigen::Vector3f b = kTarget - Eigen::Vector3f(0.1F, 0.0F, 0.0F);  // 0.2 m < 0.25 m
  tracker.add(a, 0.8F, 1);
  CHECK_FALSE(tracker.confirmed());
  tracker.add(b, 0.8F, 2);
  CHECK(tracker.confirmed());
  UNSIGNED_LONGS_EQUAL(2, tracker.supporting_views());
  check_near(kTarget, tracker.estimate_m(), 1e-5F);
}

TEST(TargetTracker, TwoViewsFartherApartThanTheRadiusDoNotConfirm) {
  tracker.add(kTarget, 0.8F, 1);
  tracker.add(kTarget + Eigen::Vector3f(0.0F, 0.3F, 0.0F), 0.8F, 2);  // 0.3 m > 0.25 m
  CHECK_FALSE(tracker.confirmed());
  UNSIGNED_LONGS_EQUAL(1, tracker.supporting_views());
}

TEST(TargetTracker, AConfidentSightingWeighsMoreThanAnUnsureOne) {
  const Eigen::Vector3f sure = kTarget + Eigen::Vector3f(0.1F, 0.0F, 0.0F);
  const Eigen::Vector3f unsure = kTarget - Eigen::Vector3f(0.1F, 0.0F, 0.0F);
  tracker.add(sure, 1.0F, 1);
  tracker.add(unsure, 0.0F, 2);
  CHECK(tracker.confirmed());
  // Still between the two, but nearer the confident one.
  CHECK(tracker.estimate_m().x() > kTarget.x() + 0.05F);
  CHECK(tracker.estimate_m().x() < sure.x());
}

TEST(TargetTracker, APreciseSightingWeighsMoreThanACoarseOne) {
  const Eigen::Vector3f close = kTarget + Eigen::Vector3f(0.1F, 0.0F, 0.0F);
  const Eigen::Vector3f far = kTarget - Eigen::Vector3f(0.1F, 0.0F, 0.0F);
  tracker.add(close, 0.5F, 1, 0.05F);
  tracker.add(far, 0.5F, 2, 0.2F);  // 16 times less weight
  CHECK(tracker.confirmed());
  DOUBLES_EQUAL(kTarget.x() + 0.1F * 15.0F / 17.0F, tracker.estimate_m().x(), 1e-4);
}

TEST(TargetTracker, OnceConfirmedTheEstimateTakesInSightingsScatteredAlongTheLineOfSight) {
  TargetTrackerParams p;
  p.agree_radius_m = 0.25F;
  p.refine_radius_m = 1.0F;
  tracker.configure(p);
  // Two views agree 0.4 m beyond the target; a third fix 0.4 m short of it is too far from
  // them to agree, but close enough to refine: the estimate lands on the target.
  const Eigen::Vector3f beyond = kTarget + Eigen::Vector3f(0.4F, 0.0F, 0.0F);
  const Eigen::Vector3f beyond2 = kTarget + Eigen::Vector3f(0.4F, 0.1F, 0.0F);
  const Eigen::Vector3f short_of = kTarget - Eigen::Vector3f(0.4F, -0.05F, 0.0F);
  tracker.add(beyond, 0.5F, 1, 0.3F);
  tracker.add(beyond2, 0.5F, 2, 0.3F);
  CHECK(tracker.confirmed());
  tracker.add(short_of, 0.5F, 3, 0.212F);  // twice the weight of each of the others
  DOUBLES_EQUAL(kTarget.x(), tracker.estimate_m().x(), 0.02);
  DOUBLES_EQUAL(kTarget.y() + 0.05F, tracker.estimate_m().y(), 0.02);
}

TEST(TargetTracker, ViewsFromOnePlaceNeverConfirmWhenTwoPlacesAreAskedFor) {
  TargetTrackerParams p;
  p.min_baseline_m = 0.2F;
  tracker.configure(p);
  // Five pans of one look, from one place (and a turn on the spot: 0.1 m of drift).
  for (std::uint32_t v = 0; v < 5; ++v) tracker.add(kTarget, 0.9F, v, 0.1F, {0.0F, 0.0F});
  tracker.add(kTarget, 0.9F, 9, 0.1F, {0.1F, 0.0F});
  CHECK_FALSE(tracker.confirmed());
  UNSIGNED_LONGS_EQUAL(6, tracker.supporting_views());
  // A sighting from 0.3 m away elsewhere in the room (another group) confirms nothing.
  tracker.add(kTarget + Eigen::Vector3f(2.0F, 0.0F, 0.0F), 0.9F, 20, 0.1F, {0.0F, 0.3F});
  CHECK_FALSE(tracker.confirmed());
  // The same target from 0.3 m away: confirmed.
  tracker.add(kTarget, 0.9F, 21, 0.1F, {0.0F, 0.3F});
  CHECK(tracker.confirmed());
  check_near(kTarget, tracker.estimate_m(), 1e-5F);
}

TEST(TargetTracker, AConfirmedTargetMissedTwiceInARowIsRevokedAndItsSightingsForgotten) {
  TargetTrackerParams p;
  p.revoke_after_misses = 2;
  tracker.configure(p);
  const Eigen::Vector3f other = kTarget + Eigen::Vector3f(3.0F, 0.0F, 0.0F);
  tracker.add(other, 0.9F, 1);  // a lone sighting elsewhere: kept
  tracker.add(kTarget, 0.9F, 2);
  tracker.add(kTarget, 0.9F, 3);
  CHECK(tracker.confirmed());
  CHECK_FALSE(tracker.missed());
  tracker.add(kTarget + Eigen::Vector3f(0.1F, 0.0F, 0.0F), 0.9F, 4);  // seen again: count reset
  UNSIGNED_LONGS_EQUAL(0, tracker.misses());
  CHECK_FALSE(tracker.missed());
  CHECK(tracker.missed());
  CHECK_FALSE(tracker.confirmed());
  UNSIGNED_LONGS_EQUAL(0, tracker.misses());  // a target confirmed again starts from none
  UNSIGNED_LONGS_EQUAL(1, tracker.revocations());
  UNSIGNED_LONGS_EQUAL(1, tracker.sightings());
  check_near(other, tracker.candidate_m(), 1e-5F);
  CHECK_FALSE(tracker.missed());  // nothing confirmed: nothing to miss
  // Seen again from two views afterwards, it is confirmed again.
  tracker.add(kTarget, 0.9F, 5);
  tracker.add(kTarget, 0.9F, 6);
  CHECK(tracker.confirmed());
}

TEST(TargetTracker, MissesNeverRevokeWhenRevocationIsOff) {
  tracker.add(kTarget, 0.9F, 1);
  tracker.add(kTarget, 0.9F, 2);
  for (int i = 0; i < 10; ++i) CHECK_FALSE(tracker.missed());
  CHECK(tracker.confirmed());
}

TEST(TargetTracker, ARestoredGoalIsConfirmedAtOnceAndIsTheTarget) {
  TargetTrackerParams p;
  p.min_baseline_m = 0.2F;
  tracker.configure(p);
  tracker.restore(kTarget);
  CHECK(tracker.confirmed());
  check_near(kTarget, tracker.estimate_m(), 1e-6F);
  CHECK(tracker.is_target(kTarget + Eigen::Vector3f(0.2F, 0.0F, 0.0F)));
  CHECK_FALSE(tracker.is_target(kTarget + Eigen::Vector3f(0.3F, 0.0F, 0.0F)));
}

// "Within agree_radius_m of their mean" includes the radius itself, for the mean and for the
// count of views alike: sightings exactly the radius from the group's centre are views of it.
TEST(TargetTracker, SightingsExactlyTheAgreeRadiusFromTheGroupsCentreAreViewsOfIt) {
  TargetTrackerParams p;
  p.agree_radius_m = 0.5F;  // exact in binary, as are the points and their mean
  p.min_views = 3;
  tracker.configure(p);
  tracker.add(Eigen::Vector3f(-0.5F, 0.0F, 0.0F), 0.9F, 1, 1.0F);
  tracker.add(Eigen::Vector3f(0.0F, 0.0F, 0.0F), 0.9F, 2, 1.0F);
  tracker.add(Eigen::Vector3f(0.5F, 0.0F, 0.0F), 0.9F, 3, 1.0F);
  UNSIGNED_LONGS_EQUAL(3, tracker.supporting_views());
  CHECK(tracker.confirmed());
  check_near(Eigen::Vector3f::Zero(), tracker.estimate_m(), 1e-6F);
}

// A resume restores the goal into the tracker the mission already used: what it counted
// before (misses, revocations, sightings) is gone, as in a fresh one.
TEST(TargetTracker, ARestoreOnAUsedTrackerStartsAfreshWithTheGoalAlone) {
  TargetTrackerParams p;
  p.revoke_after_misses = 3;
  tracker.configure(p);
  tracker.add(kTarget + Eigen::Vector3f(1.0F, 0.0F, 0.0F), 0.9F, 1);
  tracker.add(kTarget + Eigen::Vector3f(1.0F, 0.0F, 0.0F), 0.9F, 2);
  tracker.restore(kTarget);
  for (int i = 0; i < 3; ++i) (void)tracker.missed();  // revoked once
  UNSIGNED_LONGS_EQUAL(1, tracker.revocations());
  // The revocation forgot the one sighting it had: nothing supports a target any more.
  CHECK_FALSE(tracker.confirmed());
  UNSIGNED_LONGS_EQUAL(0, tracker.sightings());
  UNSIGNED_LONGS_EQUAL(0, tracker.supporting_views());
  tracker.restore(kTarget);
  CHECK_FALSE(tracker.missed());
  CHECK_FALSE(tracker.missed());
  UNSIGNED_LONGS_EQUAL(2, tracker.misses());
  tracker.restore(kTarget);
  UNSIGNED_LONGS_EQUAL(0, tracker.misses());
  UNSIGNED_LONGS_EQUAL(0, tracker.revocations());
  UNSIGNED_LONGS_EQUAL(1, tracker.sightings());
  check_near(kTarget, tracker.estimate_m(), 1e-6F);
  CHECK_FALSE(tracker.missed());
  CHECK_FALSE(tracker.missed());
  CHECK(tracker.confirmed());
  CHECK(tracker.missed());  // the third miss since the restore revokes it
}

TEST(TargetTracker, ARestoredGoalIsOneSightingOfWeightOneThatLaterSightingsRefine) {
  tracker.restore(kTarget);
  UNSIGNED_LONGS_EQUAL(1, tracker.sightings());
  // A sighting 0.1 m off of weight (0.1 + 0.9) / 1² = 1, from another view: the estimate is
  // the mean of the two, halfway.
  tracker.add(kTarget + Eigen::Vector3f(0.1F, 0.0F, 0.0F), 0.9F, 7, 1.0F);
  UNSIGNED_LONGS_EQUAL(2, tracker.sightings());
  CHECK(tracker.confirmed());
  check_near(kTarget + Eigen::Vector3f(0.05F, 0.0F, 0.0F), tracker.estimate_m(), 1e-5F);
}

TEST(TargetTracker, ARevocationForgetsOnlyTheSightingsWithinTheRefineRadius) {
  TargetTrackerParams p;
  p.revoke_after_misses = 1;
  tracker.configure(p);
  // Another object 0.6 m from the target: beyond the refine radius (0.25 m), so kept.
  const Eigen::Vector3f other = kTarget + Eigen::Vector3f(0.0F, 0.6F, 0.0F);
  tracker.add(other, 0.9F, 1);
  tracker.add(kTarget, 0.9F, 2);
  tracker.add(kTarget, 0.9F, 3);
  CHECK(tracker.confirmed());
  CHECK(tracker.missed());
  CHECK_FALSE(tracker.confirmed());
  UNSIGNED_LONGS_EQUAL(1, tracker.sightings());
  check_near(other, tracker.candidate_m(), 1e-5F);
}

TEST(TargetTracker, ViewsExactlyTheBaselineApartConfirm) {
  TargetTrackerParams p;
  p.min_baseline_m = 0.5F;
  tracker.configure(p);
  tracker.add(kTarget, 0.9F, 1, 0.1F, {0.0F, 0.0F});
  tracker.add(kTarget, 0.9F, 2, 0.1F, {0.5F, 0.0F});  // "at least 0.5 m apart"
  CHECK(tracker.confirmed());
}

TEST(TargetTracker, ANonFiniteRangeErrorIsIgnored) {
  tracker.add(kTarget, 0.5F, 1, std::numeric_limits<float>::quiet_NaN());
  UNSIGNED_LONGS_EQUAL(0, tracker.sightings());
}

TEST(TargetTracker, AFarOutlierDoesNotMoveTheEstimate) {
  tracker.add(kTarget + Eigen::Vector3f(0.05F, 0.0F, 0.0F), 0.8F, 1);
  tracker.add(kTarget - Eigen::Vector3f(0.05F, 0.0F, 0.0F), 0.8F, 2);
  CHECK(tracker.confirmed());
  const Eigen::Vector3f before = tracker.estimate_m();
  tracker.add(kTarget + Eigen::Vector3f(1.5F, -2.0F, 0.4F), 1.0F, 3);  // a reflection
  CHECK(tracker.confirmed());
  UNSIGNED_LONGS_EQUAL(2, tracker.supporting_views());
  check_near(before, tracker.estimate_m(), 1e-6F);
  // An outlier just outside the radius of the group's mean does not pull it either.
  tracker.add(kTarget + Eigen::Vector3f(0.0F, 0.0F, 0.27F), 1.0F, 4);
  check_near(before, tracker.estimate_m(), 1e-6F);
}

TEST(TargetTracker, AGroupWithMoreViewsWinsOverAnEarlierPair) {
  // A false pair first (two views of a reflection), then the real target from three views.
  const Eigen::Vector3f ghost(-1.0F, 3.0F, 0.5F);
  tracker.add(ghost, 0.9F, 1);
  tracker.add(ghost, 0.9F, 2);
  CHECK(tracker.confirmed());
  check_near(ghost, tracker.estimate_m(), 1e-6F);
  tracker.add(kTarget, 0.5F, 3);
  tracker.add(kTarget, 0.5F, 4);
  tracker.add(kTarget, 0.5F, 5);
  UNSIGNED_LONGS_EQUAL(3, tracker.supporting_views());
  check_near(kTarget, tracker.estimate_m(), 1e-6F);
}

TEST(TargetTracker, MoreSightingsRefineTheEstimate) {
  // Noisy sightings (σ = 5 cm per axis) from distinct views: the error of the estimate after
  // 40 sightings is well below that after the first two that confirmed it.
  std::mt19937 rng(12345);
  std::normal_distribution<float> noise(0.0F, 0.05F);
  auto sighting = [&] {
    return Eigen::Vector3f(kTarget + Eigen::Vector3f(noise(rng), noise(rng), noise(rng)));
  };
  float first_error = 0.0F;
  float sum_first = 0.0F;
  float sum_last = 0.0F;
  constexpr int kTrials = 20;
  for (int trial = 0; trial < kTrials; ++trial) {
    tracker.clear();
    std::uint32_t view = 0;
    while (!tracker.confirmed()) tracker.add(sighting(), 0.7F, view++);
    first_error = (tracker.estimate_m() - kTarget).norm();
    for (int i = 0; i < 40; ++i) tracker.add(sighting(), 0.7F, view++);
    sum_first += first_error;
    sum_last += (tracker.estimate_m() - kTarget).norm();
  }
  const float mean_first = sum_first / kTrials;
  const float mean_last = sum_last / kTrials;
  CHECK(mean_last < 0.5F * mean_first);
  CHECK(mean_last < 0.03F);
}

TEST(TargetTracker, ANonFiniteSightingIsIgnored) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  tracker.add(kTarget, 0.8F, 1);
  tracker.add(Eigen::Vector3f(nan, 1.0F, 0.3F), 0.8F, 2);
  tracker.add(Eigen::Vector3f(2.0F, inf, 0.3F), 0.8F, 3);
  UNSIGNED_LONGS_EQUAL(1, tracker.sightings());
  CHECK_FALSE(tracker.confirmed());
  tracker.add(kTarget, 0.8F, 4);
  CHECK(tracker.confirmed());
  CHECK(tracker.estimate_m().allFinite());
  check_near(kTarget, tracker.estimate_m(), 1e-6F);
}

TEST(TargetTracker, ANonFiniteConfidenceDoesNotPoisonTheEstimate) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  tracker.add(kTarget, 0.8F, 1);
  tracker.add(Eigen::Vector3f(-2.0F, 0.0F, 0.2F), nan, 2);  // far away, confidence NaN
  tracker.add(Eigen::Vector3f(4.0F, 3.0F, 0.2F), 0.8F, 3);
  CHECK_FALSE(tracker.confirmed());  // three lone sightings, none agreeing
  tracker.add(kTarget, 0.8F, 4);
  CHECK(tracker.confirmed());
  CHECK(tracker.estimate_m().allFinite());
  check_near(kTarget, tracker.estimate_m(), 1e-6F);
}

TEST(TargetTracker, TheRingBufferOverwritesTheOldestAfter64) {
  // Five views of A, then 64 sightings of B from only two views: while A keeps more views
  // than B it stays the estimate; once B's sightings have overwritten every one of A's,
  // B is the estimate.
  const Eigen::Vector3f a(1.0F, 0.0F, 0.3F);
  const Eigen::Vector3f b(-1.0F, 2.0F, 0.3F);
  for (std::uint32_t v = 0; v < 5; ++v) tracker.add(a, 0.8F, v);
  for (std::uint32_t i = 0; i < 59; ++i) tracker.add(b, 0.8F, 100 + i % 2);
  UNSIGNED_LONGS_EQUAL(TargetTracker::kMaxSightings, tracker.sightings());
  UNSIGNED_LONGS_EQUAL(5, tracker.supporting_views());
  check_near(a, tracker.estimate_m(), 1e-6F);
  for (std::uint32_t i = 59; i < 64; ++i) tracker.add(b, 0.8F, 100 + i % 2);
  UNSIGNED_LONGS_EQUAL(TargetTracker::kMaxSightings, tracker.sightings());
  UNSIGNED_LONGS_EQUAL(2, tracker.supporting_views());
  check_near(b, tracker.estimate_m(), 1e-6F);
}

TEST(TargetTracker, ClearForgetsEverything) {
  tracker.add(kTarget, 0.8F, 1);
  tracker.add(kTarget, 0.8F, 2);
  CHECK(tracker.confirmed());
  tracker.clear();
  CHECK_FALSE(tracker.confirmed());
  UNSIGNED_LONGS_EQUAL(0, tracker.sightings());
  UNSIGNED_LONGS_EQUAL(0, tracker.supporting_views());
  check_near(Eigen::Vector3f::Zero(), tracker.estimate_m(), 0.0F);
  tracker.add(kTarget, 0.8F, 3);
  CHECK_FALSE(tracker.confirmed());
}

// A revocation that forgets every sighting leaves nothing of the target: no estimate and no
// candidate to look at again.
TEST(TargetTracker, ARevocationThatForgetsEverySightingLeavesNoEstimateNorCandidate) {
  TargetTrackerParams p;
  p.revoke_after_misses = 1;
  tracker.configure(p);
  tracker.add(kTarget, 0.9F, 1);
  tracker.add(kTarget, 0.9F, 2);
  CHECK(tracker.confirmed());
  CHECK(tracker.missed());
  UNSIGNED_LONGS_EQUAL(0, tracker.sightings());
  check_near(Eigen::Vector3f::Zero(), tracker.estimate_m(), 0.0F);
  check_near(Eigen::Vector3f::Zero(), tracker.candidate_m(), 0.0F);
}

// Two views of one look agree: not confirmed (one place), but a provisional goal to go and see
// from its stand-off; one view alone, or a confirmed target, is not provisional.
TEST(TargetTracker, TwoViewsFromOnePlaceMakeAProvisionalCandidateNotAConfirmedOne) {
  TargetTrackerParams p;
  p.min_baseline_m = 0.2F;
  tracker.configure(p);
  CHECK_FALSE(tracker.provisional());
  tracker.add(kTarget, 0.9F, 1, 0.1F, {0.0F, 0.0F});
  CHECK_FALSE(tracker.provisional());
  tracker.add(kTarget + Eigen::Vector3f(0.05F, 0.0F, 0.0F), 0.9F, 2, 0.1F, {0.0F, 0.0F});
  CHECK(tracker.provisional());
  CHECK_FALSE(tracker.confirmed());
  check_near(kTarget + Eigen::Vector3f(0.025F, 0.0F, 0.0F), tracker.candidate_m(), 1e-5F);
  // Seen from its stand-off (a second place): confirmed, no longer provisional.
  tracker.add(kTarget, 0.9F, 3, 0.1F, {1.0F, 0.0F});
  CHECK(tracker.confirmed());
  CHECK_FALSE(tracker.provisional());
  CHECK_FALSE(tracker.dismiss_candidate());
  CHECK(tracker.confirmed());
}

// Not seen from its stand-off: the candidate's sightings are forgotten (others kept), and its
// place never makes a provisional candidate again, though two places can still confirm it.
TEST(TargetTracker, ADismissedCandidatesPlaceIsNeverProvisionalAgainButCanBeConfirmed) {
  TargetTrackerParams p;
  p.min_baseline_m = 0.2F;
  tracker.configure(p);
  const Eigen::Vector3f other = kTarget + Eigen::Vector3f(3.0F, 0.0F, 0.0F);
  tracker.add(other, 0.9F, 1, 0.1F, {0.0F, 0.0F});
  tracker.add(kTarget, 0.9F, 2, 0.1F, {0.0F, 0.0F});
  tracker.add(kTarget, 0.9F, 3, 0.1F, {0.0F, 0.0F});
  CHECK(tracker.provisional());
  CHECK(tracker.dismiss_candidate());
  UNSIGNED_LONGS_EQUAL(1, tracker.dismissed());
  UNSIGNED_LONGS_EQUAL(1, tracker.sightings());
  check_near(other, tracker.candidate_m(), 1e-5F);
  CHECK_FALSE(tracker.provisional());  // the lone sighting elsewhere: one view
  CHECK_FALSE(tracker.dismiss_candidate());
  // Two views of one look at the dismissed place again: not provisional.
  tracker.add(kTarget, 0.9F, 4, 0.1F, {0.5F, 0.0F});
  tracker.add(kTarget + Eigen::Vector3f(0.0F, 0.0F, p.agree_radius_m), 0.9F, 5, 0.1F, {0.5F, 0.0F});
  CHECK_FALSE(tracker.confirmed());
  CHECK_FALSE(tracker.provisional());
  // Two views at the other sighting's place are: it was never dismissed.
  tracker.add(other, 0.9F, 6, 0.1F, {0.0F, 0.0F});
  tracker.add(other, 0.9F, 7, 0.1F, {0.0F, 0.0F});
  CHECK(tracker.provisional());
  check_near(other, tracker.candidate_m(), 1e-5F);
  tracker.add(other, 0.9F, 8, 0.1F, {0.0F, 1.0F});
  CHECK(tracker.confirmed());
  // The dismissed place seen from a second place too: a group as large as the other one,
  // and confirmable (here the other keeps the estimate, having more views).
  tracker.add(kTarget, 0.9F, 9, 0.1F, {0.0F, 1.0F});
  CHECK(tracker.confirmed());
  check_near(other, tracker.estimate_m(), 1e-5F);
}

// The dismissed places are a ring of the last kMaxDismissed; clear() forgets them.
TEST(TargetTracker, OnlyTheLastDismissedPlacesAreKeptAndClearForgetsThem) {
  const auto place = [](std::size_t i) -> Eigen::Vector3f {
    return kTarget + Eigen::Vector3f(static_cast<float>(i), 0.0F, 0.0F);
  };
  std::uint32_t view = 0;
  const auto two_views = [&](const Eigen::Vector3f& at) {
    tracker.add(at, 0.9F, ++view);
    tracker.add(at, 0.9F, ++view);
  };
  TargetTrackerParams p;
  p.min_baseline_m = 0.2F;
  tracker.configure(p);
  for (std::size_t i = 0; i <= TargetTracker::kMaxDismissed; ++i) {
    two_views(place(i));
    CHECK(tracker.dismiss_candidate());
  }
  UNSIGNED_LONGS_EQUAL(TargetTracker::kMaxDismissed, tracker.dismissed());
  two_views(place(0));  // the oldest place, overwritten: provisional again
  CHECK(tracker.provisional());
  CHECK(tracker.dismiss_candidate());
  two_views(place(TargetTracker::kMaxDismissed));  // a recent one: still dismissed
  CHECK_FALSE(tracker.provisional());
  tracker.clear();
  UNSIGNED_LONGS_EQUAL(0, tracker.dismissed());
  two_views(place(TargetTracker::kMaxDismissed));
  CHECK(tracker.provisional());
}
