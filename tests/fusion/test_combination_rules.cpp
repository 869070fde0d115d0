// Tests of the classic combination rules (Eqs 4.9–4.19) and the §4.4.2 example.
#include <cmath>

#include "algo/fusion/combination_rules.h"
#include "CppUTest/TestHarness.h"

using namespace boticelli::fusion;

TEST_GROUP(CombinationRules){};

TEST(CombinationRules, IndependentOpinionTurnsTwoIdenticalPoorReadingsIntoMoreConfidence) {
  // §4.4.2: m₁ = m₂ = 0.6 → 0.36 / (0.36 + 0.16) = 0.6923, "≈ 0.7".
  DOUBLES_EQUAL(0.36 / 0.52, independent_opinion(0.6, 0.6), 1e-12);
  CHECK(independent_opinion(0.6, 0.6) > 0.69);
  // Three looks at the same bad feature: the pool keeps growing.
  CHECK(independent_opinion(independent_opinion(0.6, 0.6), 0.6) > 0.77);
}

TEST(CombinationRules, IndependentOpinionIsNeutralAtOneHalf) {
  DOUBLES_EQUAL(0.8, independent_opinion(0.8, 0.5), 1e-12);
  DOUBLES_EQUAL(0.5, independent_opinion(0.3, 0.7), 1e-12);
}

TEST(CombinationRules, ElfesWithTheReadingAsLikelihoodIsTheIndependentOpinionPool) {
  DOUBLES_EQUAL(independent_opinion(0.6, 0.7), elfes(0.6, 0.7), 1e-12);
  DOUBLES_EQUAL(0.3, elfes(0.3, 0.5), 1e-12);  // an uninformative reading changes nothing
}

TEST(CombinationRules, LinearOpinionAveragesAndDoesNotReinforce) {
  DOUBLES_EQUAL(0.6, linear_opinion(0.6, 0.6), 1e-12);
  DOUBLES_EQUAL(0.75, linear_opinion(0.6, 0.8, 0.25), 1e-12);
}

TEST(CombinationRules, LogOddsAddAndGiveTheSameAnswerAsTheIndependentPool) {
  const double l = log_odds_combine(log_odds(0.6), log_odds(0.6));
  DOUBLES_EQUAL(2.0 * std::log(1.5), l, 1e-12);
  DOUBLES_EQUAL(independent_opinion(0.6, 0.6), occupancy_from_log_odds(l), 1e-12);
  DOUBLES_EQUAL(0.0, log_odds(0.5), 1e-12);
}

TEST(CombinationRules, DempsterShaferReinforcesRepeatedOccupiedEvidence) {
  // Evidence only for "occupied": the unknown mass shrinks, belief grows 0.6 → 0.84.
  const Masses a{0.6, 0.0};
  const Masses ab = dempster_shafer(a, a);
  DOUBLES_EQUAL(0.84, ab.occupied, 1e-12);
  DOUBLES_EQUAL(0.0, ab.empty, 1e-12);
  DOUBLES_EQUAL(1.0, ab.plausibility(), 1e-12);
}

TEST(CombinationRules, DempsterShaferNormalisesAwayConflict) {
  const Masses a{0.6, 0.2};
  const Masses b{0.3, 0.5};
  const Masses ab = dempster_shafer(a, b);
  const double k = 0.6 * 0.5 + 0.3 * 0.2;
  DOUBLES_EQUAL((0.6 * 0.2 + 0.3 * 0.2 + 0.6 * 0.3) / (1.0 - k), ab.occupied, 1e-12);
  DOUBLES_EQUAL((0.2 * 0.2 + 0.5 * 0.2 + 0.2 * 0.5) / (1.0 - k), ab.empty, 1e-12);
  CHECK(ab.belief() <= ab.plausibility());
  // Total conflict has no answer; everything becomes unknown.
  const Masses none = dempster_shafer({1.0, 0.0}, {0.0, 1.0});
  DOUBLES_EQUAL(1.0, none.unknown(), 1e-12);
}
