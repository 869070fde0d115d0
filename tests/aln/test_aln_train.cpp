// Tests of ALN training: exact recovery, constrained fits, robust weights, resumable slices.
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>

#include <Eigen/Core>

#include "algo/aln/aln.h"
#include "algo/aln/constrained_lsq.h"
#include "algo/aln/samples.h"
#include "algo/aln/trainer.h"
#include "aln_test_util.h"
#include "alloc_guard.h"
#include "CppUTest/TestHarness.h"

namespace aln = boticelli::aln;

namespace {

// MIN(MAX(p0, p1), MAX(p2, p3)) on [0, 1]^2: a ridge along x with a valley along y.
double known_pl(double x, double y) {
  const double a = std::fmax(2.0 * x + y - 0.5, 2.0 * x - y + 0.5);
  const double b = std::fmax(2.0 - 2.0 * x + 0.8 * y - 0.24, 2.0 - 2.0 * x - 0.8 * y + 0.24);
  return std::fmin(a, b);
}

// Thesis Eq 5.2, cylindrical room observed from its centre: m = MIN((r / R)^n, 1),
// with r and R in decimetres (R = 50 dm), n = 2; alpha in rad, h in dm.
double cylinder_room(double r_dm) {
  const double u = r_dm / 50.0;
  return std::fmin(u * u, 1.0);
}

// Both ways of splitting a piece, for tests that must hold with either.
constexpr std::array<aln::SplitCandidates, 2> kBothSplits = {aln::SplitCandidates::kCentroidV,
                                                             aln::SplitCandidates::kHinges};

using Model2 = aln::Aln<double, 2, 64>;
using Trainer2 = aln::Trainer<double, 2, 64>;
using Model3 = aln::Aln<float, 3, 256>;
using Trainer3 = aln::Trainer<float, 3, 256>;

aln::Sample<double, 2> g_samples2[2500];
aln::Sample<float, 3> g_samples3[6000];
Model2 g_model2;
Model2 g_model2b;
Trainer2 g_trainer2;
Model3 g_model3;
Model3 g_model3b;
Trainer3 g_trainer3;

void fill_known_pl() {
  aln_test::Rng rng(21);
  for (auto& s : g_samples2) {
    s.x = Eigen::Vector2d(rng.uniform(0.0, 1.0), rng.uniform(0.0, 1.0));
    s.y = known_pl(s.x(0), s.x(1));
    s.weight = 1.0;
  }
}

// Samples of the cylindrical room: alpha in [-pi, pi] rad, h in [0, 20] dm, r in [0, 100] dm.
// `outliers` of them (every k-th) get a uniformly random occupancy instead.
std::size_t fill_room(std::size_t n, double outlier_fraction, std::uint64_t seed) {
  aln_test::Rng rng(seed);
  for (std::size_t k = 0; k < n; ++k) {
    auto& s = g_samples3[k];
    s.x = Eigen::Vector3f(static_cast<float>(rng.uniform(-3.14159, 3.14159)),
                          static_cast<float>(rng.uniform(0.0, 20.0)),
                          static_cast<float>(rng.uniform(0.0, 100.0)));
    s.y = static_cast<float>(cylinder_room(static_cast<double>(s.x(2))));
    if (rng.uniform(0.0, 1.0) < outlier_fraction) s.y = static_cast<float>(rng.uniform(0.0, 1.0));
    s.weight = 1.0F;
  }
  return n;
}

void set_room_ranges(Model3& m) {
  m.set_input_range(0, -3.14159F, 3.14159F);
  m.set_input_range(1, 0.0F, 20.0F);
  m.set_input_range(2, 0.0F, 100.0F);
  m.set_output_range(-0.1F, 1.1F);
  // Eqs 4.27-4.28: c > 0 (monotone increasing in r), |a| <= 1, |b| <= 1 per rad / dm.
  m.set_weight_bounds(0, -1.0F, 1.0F);
  m.set_weight_bounds(1, -1.0F, 1.0F);
  m.set_weight_bounds(2, 1e-4F, 1.0F);
}

bool same_model(const Model3& a, const Model3& b) {
  if (a.piece_count() != b.piece_count() || a.node_count() != b.node_count()) return false;
  for (std::size_t n = 0; n < a.node_count(); ++n) {
    if (a.node(n).kind != b.node(n).kind || a.node(n).a != b.node(n).a ||
        a.node(n).b != b.node(n).b) {
      return false;
    }
  }
  for (std::size_t p = 0; p < a.piece_count(); ++p) {
    if (a.piece(p).weight != b.piece(p).weight || a.piece(p).centroid != b.piece(p).centroid ||
        a.piece(p).centroid_output != b.piece(p).centroid_output) {
      return false;
    }
  }
  return true;
}

// A wall step seen along a corridor: the distance to the wall is 1 m up to x = 0.5 and 2 m
// beyond (a recess), rising 0.3 m across y, with +-1 cm noise; `outlier_fraction` of the
// samples get a uniformly random distance in [0, 3] m instead.
std::size_t fill_wall_step(std::size_t n, double outlier_fraction, std::uint64_t seed) {
  aln_test::Rng rng(seed);
  for (std::size_t k = 0; k < n; ++k) {
    auto& s = g_samples2[k];
    s.x = Eigen::Vector2d(rng.uniform(0.0, 1.0), rng.uniform(0.0, 1.0));
    s.y = (s.x(0) < 0.5 ? 1.0 : 2.0) + 0.3 * s.x(1) + 0.01 * rng.uniform(-1.0, 1.0);
    if (rng.uniform(0.0, 1.0) < outlier_fraction) s.y = rng.uniform(0.0, 3.0);
    s.weight = 1.0;
  }
  return n;
}

void set_unit_ranges(Model2& m) {
  m.set_input_range(0, 0.0, 1.0);
  m.set_input_range(1, 0.0, 1.0);
}

// The M-estimator's loss rho(r / s) s^2 (Huber: r^2 / 2 inside 1.345 s, then linear; Tukey:
// constant c^2 s^2 / 6 beyond c = 4.685 s), r^2 without robust weights.
double robust_loss(aln::RobustWeighting kind, double r, double s) {
  const double u = std::fabs(r) / s;
  if (kind == aln::RobustWeighting::kHuber) {
    constexpr double k = 1.345;
    return u <= k ? 0.5 * r * r : s * s * (k * u - 0.5 * k * k);
  }
  if (kind == aln::RobustWeighting::kTukey) {
    constexpr double c = 4.685;
    const double t = u < c ? 1.0 - (u / c) * (u / c) : 0.0;
    return c * c / 6.0 * (1.0 - t * t * t) * s * s;
  }
  return r * r;
}

// Sum of w rho(r / s) s^2 of a model over the first n samples, evaluated here, not by the
// trainer.
template <typename Model, typename Sample>
double loss_over(const Model& m, const Sample* samples, std::size_t n, aln::RobustWeighting kind,
                 double s) {
  double loss = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    const double r =
        static_cast<double>(samples[k].y) - static_cast<double>(m.evaluate(samples[k].x).value);
    loss += static_cast<double>(samples[k].weight) * robust_loss(kind, r, s);
  }
  return loss;
}

// Share of the first n samples a model fits to within tol.
template <typename Model, typename Sample>
double share_within(const Model& m, const Sample* samples, std::size_t n, double tol) {
  std::size_t fitted = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const double r =
        static_cast<double>(samples[k].y) - static_cast<double>(m.evaluate(samples[k].x).value);
    if (std::fabs(r) <= tol) ++fitted;
  }
  return static_cast<double>(fitted) / static_cast<double>(n);
}

// Values and responsible pieces of a 2-input model at four points (one block evaluation).
struct Lanes4 {
  std::array<double, 4> value{};
  std::array<std::uint16_t, 4> piece{};
};
Lanes4 evaluate_four(const Model2& m, const std::array<Eigen::Vector2d, 4>& x) {
  Lanes4 out;
  m.evaluate_block(std::span<const Eigen::Vector2d>(x.data(), x.size()), out.value, out.piece);
  return out;
}

}  // namespace

TEST_GROUP(AlnTrain){};

TEST(AlnTrain, RecoversAKnownMinOfMaxesWithNoMorePiecesThanItHas) {
  fill_known_pl();
  aln::TrainerConfig cfg;
  cfg.epsilon = 1e-5;
  cfg.max_iterations = 10;
  cfg.max_refit_passes = 20;
  g_trainer2.configure(cfg);
  CHECK(g_trainer2.train(aln::SampleSet<double, 2>(g_samples2), g_model2));
  CHECK(g_model2.piece_count() <= 4);
  // RMS on fresh points.
  aln_test::Rng rng(99);
  double sse = 0.0;
  constexpr int kTest = 5000;
  for (int k = 0; k < kTest; ++k) {
    const Eigen::Vector2d x(rng.uniform(0.0, 1.0), rng.uniform(0.0, 1.0));
    const double e = g_model2.evaluate(x).value - known_pl(x(0), x(1));
    sse += e * e;
  }
  const double rms = std::sqrt(sse / kTest);
  CHECK_TEXT(rms < 1e-4, "known piecewise-linear function not recovered to 1e-4 RMS");
  CHECK(g_trainer2.stats().rms < 1e-4);
}

TEST(AlnTrain, FitsTheCylindricalRoomToEpsilonWithEveryPieceInsideItsBounds) {
  const std::size_t n = fill_room(6000, 0.0, 5);
  set_room_ranges(g_model3);
  aln::TrainerConfig cfg;
  cfg.epsilon = 0.02;
  cfg.max_iterations = 12;
  g_trainer3.configure(cfg);
  CHECK(g_trainer3.train(aln::SampleSet<float, 3>(g_samples3, n), g_model3));
  CHECK(g_trainer3.stats().rms <= 0.02);
  CHECK(g_model3.pieces_within_bounds());
  // Per piece RMS <= epsilon (the thesis's split rule), and monotone increasing in r.
  double sse[256] = {};
  double cnt[256] = {};
  for (std::size_t k = 0; k < n; ++k) {
    const auto e = g_model3.evaluate(g_samples3[k].x);
    const double r = static_cast<double>(e.value - g_samples3[k].y);
    sse[e.piece] += r * r;
    cnt[e.piece] += 1.0;
  }
  for (std::size_t p = 0; p < g_model3.piece_count(); ++p) {
    if (cnt[p] > 0.0) CHECK(std::sqrt(sse[p] / cnt[p]) <= 0.02 + 1e-6);
    CHECK(g_model3.piece(p).weight(2) >= 1e-4F);
    CHECK(std::fabs(g_model3.piece(p).weight(0)) <= 1.0F);
  }
  aln_test::Rng rng(4);
  for (int k = 0; k < 2000; ++k) {
    Eigen::Vector3f x(static_cast<float>(rng.uniform(-3.0, 3.0)),
                      static_cast<float>(rng.uniform(0.0, 20.0)),
                      static_cast<float>(rng.uniform(0.0, 99.0)));
    const float m0 = g_model3.evaluate(x).value;
    x(2) += 1.0F;
    CHECK(g_model3.evaluate(x).value > m0);
  }
  CHECK(g_model3.piece_count() < 64);
}

TEST(AlnTrain, ARoundEndsAtTheFirstRefitThatGainsLessThanTheRoundTolerance) {
  const std::size_t n = fill_room(6000, 0.0, 5);
  std::size_t passes[2] = {};
  std::size_t rounds[2] = {};
  constexpr double kTolerance[2] = {0.0, 1.0};  // 1: any refit that gains ends the round
  for (std::size_t t = 0; t < 2; ++t) {
    set_room_ranges(g_model3);
    aln::TrainerConfig cfg;
    cfg.epsilon = 0.05;
    cfg.max_iterations = 12;
    cfg.round_tolerance = kTolerance[t];
    g_trainer3.configure(cfg);
    CHECK(g_trainer3.train(aln::SampleSet<float, 3>(g_samples3, n), g_model3));
    CHECK(g_trainer3.stats().rms <= 0.05);
    passes[t] = g_trainer3.stats().passes;
    rounds[t] = g_trainer3.stats().rounds;
  }
  // Without the tolerance a round refits until the loss stops falling; with it, after the
  // round's first pass a refit that lowered the loss ends the round, so a round takes at most
  // the first pass, stalled refits (at most 2 without damping) and one that gained.
  CHECK(passes[1] < passes[0]);
  CHECK(passes[1] <= 4 * (rounds[1] + 1));
  CHECK(passes[0] > 4 * (rounds[0] + 1));
}

TEST(AlnTrain, SlicedTrainingEqualsOneShotTraining) {
  // With either split (the hinges keep sums of their own, which slices must not disturb).
  const std::size_t n = fill_room(2000, 0.03, 8);
  for (const aln::SplitCandidates split : kBothSplits) {
    set_room_ranges(g_model3);
    set_room_ranges(g_model3b);
    aln::TrainerConfig cfg;
    cfg.epsilon = 0.05;
    cfg.robust = aln::RobustWeighting::kHuber;
    cfg.seed = 17;
    cfg.split = split;
    g_trainer3.configure(cfg);
    CHECK(g_trainer3.train(aln::SampleSet<float, 3>(g_samples3, n), g_model3));
    const aln::TrainerStats one_shot = g_trainer3.stats();
    CHECK(g_trainer3.start(aln::SampleSet<float, 3>(g_samples3, n), g_model3b));
    std::size_t steps = 0;
    std::size_t budget = 1;
    while (!g_trainer3.run_unit(budget)) {
      budget = budget * 3 % 997 + 1;  // uneven slices, some of them a single sample
      ++steps;
    }
    CHECK(steps > 20);
    CHECK(g_model3.piece_count() > 2);
    CHECK(same_model(g_model3, g_model3b));
    LONGS_EQUAL(one_shot.passes, g_trainer3.stats().passes);
    LONGS_EQUAL(one_shot.sample_visits, g_trainer3.stats().sample_visits);
    CHECK(one_shot.rms == g_trainer3.stats().rms);
  }
}

// Trains `model` (the room's ranges) from one piece on the first n room samples with `cfg`.
aln::TrainerStats train_room_model(const aln::TrainerConfig& cfg, std::size_t n, Model3& model) {
  g_trainer3.configure(cfg);
  set_room_ranges(model);
  CHECK(g_trainer3.train(aln::SampleSet<float, 3>(g_samples3, n), model));
  return g_trainer3.stats();
}

TEST(AlnTrain, ARestartTrainsAfreshWithTheNextSeedAndTheLeastLossOfAllStartsIsReturned) {
  // Two split rounds cannot reach this epsilon, so every start ends above it: with two
  // restarts the trainer trains seeds 5, 6 and 7 from one piece, as three trainings would,
  // and returns the model of the least loss, whichever start it came from.
  static std::array<Model3, 3> alone;
  const std::size_t n = fill_room(2000, 0.0, 12);
  aln::TrainerConfig cfg;
  cfg.epsilon = 0.001;
  cfg.max_iterations = 2;
  cfg.split = aln::SplitCandidates::kHinges;
  std::array<aln::TrainerStats, 3> stats;
  std::size_t best = 0;
  for (std::size_t k = 0; k < alone.size(); ++k) {
    cfg.seed = 5 + static_cast<std::uint32_t>(k);
    stats[k] = train_room_model(cfg, n, alone[k]);
    CHECK(stats[k].robust_rms > cfg.epsilon);
    if (stats[k].robust_loss < stats[best].robust_loss) best = k;
  }
  // The starts differ, so which one is returned matters (on x86-64 the best is the second,
  // neither the first nor the last).
  CHECK(stats[0].robust_loss != stats[1].robust_loss);
  CHECK(stats[2].robust_loss != stats[1].robust_loss);
  CHECK(stats[0].robust_loss != stats[2].robust_loss);
  cfg.seed = 5;
  cfg.restarts = 2;
  const aln::TrainerStats with = train_room_model(cfg, n, g_model3);
  LONGS_EQUAL(2, with.restarts);
  CHECK(same_model(alone[best], g_model3));
  CHECK(with.robust_loss == stats[best].robust_loss);
  CHECK(with.rms == stats[best].rms);
  LONGS_EQUAL(stats[best].pieces, with.pieces);
  LONGS_EQUAL(stats[0].passes + stats[1].passes + stats[2].passes, with.passes);
  LONGS_EQUAL(stats[0].sample_visits + stats[1].sample_visits + stats[2].sample_visits,
              with.sample_visits);
  // In uneven slices, the same.
  set_room_ranges(g_model3b);
  CHECK(g_trainer3.start(aln::SampleSet<float, 3>(g_samples3, n), g_model3b));
  std::size_t budget = 1;
  while (!g_trainer3.run_unit(budget)) budget = budget * 3 % 997 + 1;
  CHECK(same_model(g_model3, g_model3b));
  LONGS_EQUAL(with.passes, g_trainer3.stats().passes);
}

TEST(AlnTrain, NoRestartIsMadeOnceAStartReachesEpsilon) {
  const std::size_t n = fill_room(2000, 0.0, 12);
  aln::TrainerConfig cfg;
  cfg.epsilon = 0.03;
  cfg.seed = 5;
  const aln::TrainerStats alone = train_room_model(cfg, n, g_model3);
  CHECK(alone.robust_rms <= cfg.epsilon);
  cfg.restarts = 3;
  const aln::TrainerStats with = train_room_model(cfg, n, g_model3b);
  LONGS_EQUAL(0, with.restarts);
  LONGS_EQUAL(alone.passes, with.passes);
  CHECK(same_model(g_model3, g_model3b));
}

TEST(AlnTrain, TheSameSeedGivesTheSameModel) {
  const std::size_t n = fill_room(2000, 0.0, 12);
  set_room_ranges(g_model3);
  set_room_ranges(g_model3b);
  aln::TrainerConfig cfg;
  cfg.epsilon = 0.03;
  cfg.seed = 5;
  g_trainer3.configure(cfg);
  CHECK(g_trainer3.train(aln::SampleSet<float, 3>(g_samples3, n), g_model3));
  CHECK(g_trainer3.train(aln::SampleSet<float, 3>(g_samples3, n), g_model3b));
  CHECK(same_model(g_model3, g_model3b));
}

TEST(AlnTrain, DifferentSeedsGiveDifferentModelsOfTheSameQuality) {
  // The seed jitters the V's tilt, or picks among near-equal hinge candidates and shifts the
  // hinge a little: another seed, another model, fitted as well.
  const std::size_t n = fill_room(2000, 0.0, 12);
  for (const aln::SplitCandidates split : kBothSplits) {
    set_room_ranges(g_model3);
    set_room_ranges(g_model3b);
    aln::TrainerConfig cfg;
    cfg.epsilon = 0.03;
    cfg.split = split;
    cfg.seed = 5;
    g_trainer3.configure(cfg);
    CHECK(g_trainer3.train(aln::SampleSet<float, 3>(g_samples3, n), g_model3));
    const double rms5 = g_trainer3.stats().rms;
    cfg.seed = 6;
    g_trainer3.configure(cfg);
    CHECK(g_trainer3.train(aln::SampleSet<float, 3>(g_samples3, n), g_model3b));
    const double rms6 = g_trainer3.stats().rms;
    CHECK_FALSE(same_model(g_model3, g_model3b));
    CHECK(rms5 < 0.03 && rms6 < 0.03);
  }
}

TEST(AlnTrain, ATrainerWithoutHingeSumsSplitsByTheVWhateverItIsConfigured) {
  // SplitBins = 0 (the mission's trainers) keeps no hinge sums: asked for hinges, it gives
  // exactly the model the V gives.
  static aln::Trainer<float, 3, 256, 0> no_hinges;
  const std::size_t n = fill_room(2000, 0.05, 9);
  set_room_ranges(g_model3);
  set_room_ranges(g_model3b);
  aln::TrainerConfig cfg;
  cfg.epsilon = 0.03;
  cfg.split = aln::SplitCandidates::kCentroidV;
  g_trainer3.configure(cfg);
  CHECK(g_trainer3.train(aln::SampleSet<float, 3>(g_samples3, n), g_model3));
  cfg.split = aln::SplitCandidates::kHinges;
  no_hinges.configure(cfg);
  CHECK(no_hinges.train(aln::SampleSet<float, 3>(g_samples3, n), g_model3b));
  CHECK(g_model3.piece_count() > 2);
  CHECK(same_model(g_model3, g_model3b));
  CHECK(sizeof(no_hinges) * 4 < sizeof(g_trainer3));
}

TEST(AlnTrain, AHingeSplitBendsWhereTheResidualsOfTheModelItsRoundEndedOnBend) {
  // Without refits the one piece (0 everywhere) is split as it is, from the hinge sums of
  // its residuals y, which a pass of their own gathers (the refit passes leave them out):
  // y = 0.3 + 2 max(0, x0 - 0.5) is the candidate at the middle edge of 4 bins over [0, 1]
  // (the edges beside it explain far less), so the split is 0.3 + 2 max(0, x0 - t), t
  // within the seeded quarter bin of 0.5.
  static aln::Trainer<double, 2, 64, 4> trainer;
  aln_test::Rng rng(5);
  for (auto& s : g_samples2) {
    s.x = Eigen::Vector2d(rng.uniform(0.0, 1.0), rng.uniform(0.0, 1.0));
    s.y = 0.3 + 2.0 * std::fmax(0.0, s.x(0) - 0.5);
    s.weight = 1.0;
  }
  for (const std::uint32_t seed : {1U, 2U, 3U}) {
    set_unit_ranges(g_model2);
    g_model2.set_weight_bounds(0, -5.0, 5.0);
    g_model2.set_weight_bounds(1, -5.0, 5.0);
    aln::TrainerConfig cfg;
    cfg.epsilon = 1e-3;
    cfg.split = aln::SplitCandidates::kHinges;
    cfg.max_iterations = 1;
    cfg.max_refit_passes = 0;
    cfg.seed = seed;
    trainer.configure(cfg);
    CHECK(trainer.train(aln::SampleSet<double, 2>(g_samples2, 2500), g_model2));
    LONGS_EQUAL(2, g_model2.piece_count());
    LONGS_EQUAL(1, trainer.stats().bin_passes);
    constexpr double kQuarterBin = 0.25 / 4.0;
    for (const double y : {0.0, 0.5, 1.0}) {
      const Lanes4 at = evaluate_four(g_model2, {Eigen::Vector2d(0.1, y), Eigen::Vector2d(0.4, y),
                                                 Eigen::Vector2d(0.8, y), Eigen::Vector2d(0.9, y)});
      const std::array<double, 4>& v = at.value;
      DOUBLES_EQUAL(0.3, v[0], 1e-9);
      DOUBLES_EQUAL(0.3, v[1], 1e-9);
      DOUBLES_EQUAL(1.1, v[3], 2.0 * kQuarterBin);
      DOUBLES_EQUAL(0.2, v[3] - v[2], 1e-9);  // the slope beyond the hinge is the residuals'
    }
  }
}

TEST(AlnTrain, AHingeSplitOfARobustFitLeavesOutWhatTheRobustWeightsLeaveOut) {
  // A step along x0 (1 below 0.5, 2 beyond) and 5% gross outliers (20), all at x1 > 0.75:
  // weighted as the pass that fitted them weighs them, the outliers (Tukey weight 0) do not
  // count and the one split divides the step along x0; counted, they would draw it to x1.
  static aln::Trainer<double, 2, 64, 4> trainer;
  aln_test::Rng rng(7);
  for (auto& s : g_samples2) {
    s.x = Eigen::Vector2d(rng.uniform(0.0, 1.0), rng.uniform(0.0, 1.0));
    s.y = s.x(0) < 0.5 ? 1.0 : 2.0;
    if (s.x(1) > 0.75 && rng.uniform(0.0, 1.0) < 0.2) s.y = 20.0;
    s.weight = 1.0;
  }
  for (const std::uint32_t seed : {1U, 2U, 3U}) {
    set_unit_ranges(g_model2);
    aln::TrainerConfig cfg;
    cfg.epsilon = 0.1;
    cfg.robust = aln::RobustWeighting::kTukey;
    cfg.split = aln::SplitCandidates::kHinges;
    cfg.max_iterations = 1;
    cfg.seed = seed;
    trainer.configure(cfg);
    CHECK(trainer.train(aln::SampleSet<double, 2>(g_samples2, 2500), g_model2));
    LONGS_EQUAL(2, g_model2.piece_count());
    const Lanes4 at =
        evaluate_four(g_model2, {Eigen::Vector2d(0.1, 0.3), Eigen::Vector2d(0.9, 0.3),
                                 Eigen::Vector2d(0.9, 0.1), Eigen::Vector2d(0.9, 0.9)});
    const std::array<std::uint16_t, 4>& who = at.piece;
    CHECK(who[0] != who[1]);      // split along x0 ...
    LONGS_EQUAL(who[2], who[3]);  // ... not along x1
  }
}

TEST(AlnTrain, EveryPieceOfATrainedModelIsResponsibleForSomeSample) {
  // Pieces no sample uses are pruned after each round (they would only cost evaluation
  // time and could take over where there are no data).
  for (const std::uint64_t seed : {3U, 31U, 77U}) {
    const std::size_t n = fill_room(3000, 0.1, seed);
    set_room_ranges(g_model3);
    aln::TrainerConfig cfg;
    cfg.epsilon = 0.02;
    cfg.max_iterations = 10;
    g_trainer3.configure(cfg);
    CHECK(g_trainer3.train(aln::SampleSet<float, 3>(g_samples3, n), g_model3));
    CHECK(g_model3.piece_count() > 4);
    std::array<std::uint8_t, 256> used{};
    for (std::size_t k = 0; k < n; ++k)
      used[g_model3.evaluate_alpha_beta(g_samples3[k].x).piece] = 1;
    std::size_t unused = 0;
    for (std::size_t p = 0; p < g_model3.piece_count(); ++p) unused += used[p] == 0 ? 1U : 0U;
    LONGS_EQUAL(0, unused);
  }
}

TEST(AlnTrain, MoreSplitRoundsNeverGiveAWorseFit) {
  // A round whose splits did not lower the error is undone, so the error of the model
  // training ends with never rises with the number of rounds allowed.
  const std::size_t n = fill_room(3000, 0.3, 77);
  set_room_ranges(g_model3);
  aln::TrainerConfig cfg;
  cfg.epsilon = 0.02;
  double previous = 1e9;
  for (std::size_t rounds = 1; rounds <= 12; ++rounds) {
    cfg.max_iterations = rounds;
    g_trainer3.configure(cfg);
    CHECK(g_trainer3.train(aln::SampleSet<float, 3>(g_samples3, n), g_model3));
    const double rms = g_trainer3.stats().rms;
    CHECK_TEXT(rms <= previous * (1.0 + 1e-9), std::to_string(rounds).c_str());
    previous = rms;
  }
}

TEST(AlnTrain, RobustWeightsStopOutliersForcingExtraPieces) {
  const std::size_t n = fill_room(3000, 0.05, 31);
  set_room_ranges(g_model3);
  set_room_ranges(g_model3b);
  aln::TrainerConfig cfg;
  cfg.epsilon = 0.1;
  cfg.max_iterations = 8;
  g_trainer3.configure(cfg);
  CHECK(g_trainer3.train(aln::SampleSet<float, 3>(g_samples3, n), g_model3));
  const std::size_t plain_pieces = g_model3.piece_count();
  cfg.robust = aln::RobustWeighting::kTukey;
  g_trainer3.configure(cfg);
  CHECK(g_trainer3.train(aln::SampleSet<float, 3>(g_samples3, n), g_model3b));
  const std::size_t robust_pieces = g_model3b.piece_count();
  CHECK(robust_pieces < plain_pieces);
  // ... and the robust model is close to the clean function.
  aln_test::Rng rng(6);
  double sse = 0.0;
  for (int k = 0; k < 2000; ++k) {
    const Eigen::Vector3f x(static_cast<float>(rng.uniform(-3.0, 3.0)),
                            static_cast<float>(rng.uniform(0.0, 20.0)),
                            static_cast<float>(rng.uniform(0.0, 100.0)));
    const double e =
        static_cast<double>(g_model3b.evaluate(x).value) - cylinder_room(static_cast<double>(x(2)));
    sse += e * e;
  }
  CHECK(std::sqrt(sse / 2000.0) < 0.1);
}

TEST(AlnTrain, PieceCapAndIterationCapAreHonoured) {
  const std::size_t n = fill_room(2000, 0.0, 2);
  set_room_ranges(g_model3);
  aln::TrainerConfig cfg;
  cfg.epsilon = 0.001;
  cfg.max_pieces = 5;
  g_trainer3.configure(cfg);
  CHECK(g_trainer3.train(aln::SampleSet<float, 3>(g_samples3, n), g_model3));
  CHECK(g_model3.piece_count() <= 5);
  cfg.max_pieces = 0;
  cfg.max_iterations = 2;
  g_trainer3.configure(cfg);
  CHECK(g_trainer3.train(aln::SampleSet<float, 3>(g_samples3, n), g_model3));
  CHECK(g_trainer3.stats().iterations <= 2);
  CHECK(g_model3.piece_count() <= 4);
  CHECK(g_model3.pieces_within_bounds());
}

TEST(AlnTrain, AnUndoneSplitRoundDoesNotEndTheTraining) {
  // Noisy room samples at a tight epsilon: some rounds' splits do not lower the error. With
  // either split (the hinges split again from the sums of the model the undone round had
  // split).
  const std::size_t n = fill_room(3000, 0.3, 77);
  for (const aln::SplitCandidates split : kBothSplits) {
    set_room_ranges(g_model3);
    set_room_ranges(g_model3b);
    aln::TrainerConfig cfg;
    cfg.epsilon = 0.02;
    cfg.max_iterations = 12;
    cfg.max_failed_rounds = 0;  // the first undone round ends it
    cfg.split = split;
    g_trainer3.configure(cfg);
    CHECK(g_trainer3.train(aln::SampleSet<float, 3>(g_samples3, n), g_model3));
    const aln::TrainerStats stopped = g_trainer3.stats();
    CHECK_EQUAL(1U, stopped.failed_rounds);
    CHECK(stopped.iterations < cfg.max_iterations);
    cfg.max_failed_rounds = 8;
    g_trainer3.configure(cfg);
    CHECK(g_trainer3.train(aln::SampleSet<float, 3>(g_samples3, n), g_model3b));
    const aln::TrainerStats went_on = g_trainer3.stats();
    CHECK(went_on.failed_rounds >= 1);
    CHECK(went_on.iterations > stopped.iterations);  // it split again after the undone round
    CHECK(went_on.rms < stopped.rms);
    CHECK(g_model3b.pieces_within_bounds());
  }
}

TEST(AlnTrain, ATrainersModelDoesNotDependOnWhatItTrainedBefore) {
  // The mission reuses its trainers look after look: nothing left from one training (sums,
  // counts of undone rounds, pieces already tried) may reach the next. A trainer that
  // trained another room first gives the model a fresh trainer gives, undone rounds and
  // their retried splits included.
  static Trainer3 fresh;
  std::size_t undone = 0;
  for (const std::uint64_t seed : {77U, 3U, 31U}) {
    aln::TrainerConfig cfg;
    cfg.epsilon = 0.02;
    cfg.max_iterations = 12;
    cfg.split = aln::SplitCandidates::kHinges;
    cfg.seed = static_cast<std::uint32_t>(seed);
    g_trainer3.configure(cfg);
    fresh.configure(cfg);
    std::size_t n = fill_room(3000, 0.3, seed + 1000);
    set_room_ranges(g_model3);
    CHECK(g_trainer3.train(aln::SampleSet<float, 3>(g_samples3, n), g_model3));
    n = fill_room(3000, 0.3, seed);
    set_room_ranges(g_model3);
    set_room_ranges(g_model3b);
    CHECK(g_trainer3.train(aln::SampleSet<float, 3>(g_samples3, n), g_model3));
    CHECK(fresh.train(aln::SampleSet<float, 3>(g_samples3, n), g_model3b));
    CHECK(same_model(g_model3, g_model3b));
    undone += g_trainer3.stats().failed_rounds;
  }
  CHECK(undone > 0);
}

// MIN(MAX(P, Q), R) on [0, 2] with P = 4x - 4, Q = 0.5, R = 1, and samples of it on [0, 1]
// (Q's, 0.5) and [1.5, 2] (R's, 1): P is responsible for no sample, but it wins MAX(P, Q) on
// [1.5, 2] where R then wins the MIN. Without P, Q wins there and the model is 0.5, not 1.
struct PrunedPieceScene {
  using Model1 = aln::Aln<double, 1, 8>;
  using Vec1 = Model1::Vec;
  std::array<aln::Sample<double, 1>, 200> samples{};
  Model1 model;

  PrunedPieceScene() {
    for (std::size_t k = 0; k < samples.size(); ++k) {
      const double u = static_cast<double>(k % 100) / 99.0;
      samples[k].x(0) = k < 100 ? u : 1.5 + 0.5 * u;
      samples[k].y = k < 100 ? 0.5 : 1.0;
    }
    model.set_input_range(0, 0.0, 2.0);
    using Node = Model1::Node;
    const std::array<Node, 5> nodes = {
        Node{aln::NodeKind::kMin, 1, 2}, Node{aln::NodeKind::kMax, 3, 4},
        Node{aln::NodeKind::kPiece, 2, 0}, Node{aln::NodeKind::kPiece, 0, 0},
        Node{aln::NodeKind::kPiece, 1, 0}};
    std::array<aln::Piece<double, 1>, 3> pieces{};
    pieces[0].set(Vec1(4.0), Vec1(1.0), 0.0);  // P
    pieces[1].set(Vec1(0.0), Vec1(1.0), 0.5);  // Q
    pieces[2].set(Vec1(0.0), Vec1(1.0), 1.0);  // R
    CHECK(model.assign(nodes, pieces));
  }

  // Trains the model as it is, without refits or splits: what is left is the pruning.
  void train(bool check_pruning, aln::Trainer<double, 1, 8>& trainer) {
    aln::TrainerConfig cfg;
    cfg.max_refit_passes = 0;
    cfg.max_iterations = 0;
    cfg.check_pruning = check_pruning;
    trainer.configure(cfg);
    CHECK(trainer.start_from(aln::SampleSet<double, 1>(samples.data(), samples.size()), model));
    while (!trainer.run_unit(64)) {
    }
  }

  double worst_error() const {
    double worst = 0.0;
    for (const auto& s : samples)
      worst = std::fmax(worst, std::fabs(model.evaluate(s.x).value - s.y));
    return worst;
  }
};

TEST(AlnTrain, APruningThatChangesTheModelAtSamplesIsUndoneWhenPruningsAreChecked) {
  static aln::Trainer<double, 1, 8> trainer;
  PrunedPieceScene unchecked;
  LONGS_EQUAL(3, unchecked.model.piece_count());
  DOUBLES_EQUAL(0.0, unchecked.worst_error(), 1e-12);  // the model fits every sample
  unchecked.train(false, trainer);
  LONGS_EQUAL(2, unchecked.model.piece_count());  // P pruned: 0.5 where 1 was fitted
  DOUBLES_EQUAL(0.5, unchecked.worst_error(), 1e-12);
  PrunedPieceScene checked;
  checked.train(true, trainer);
  LONGS_EQUAL(3, checked.model.piece_count());
  DOUBLES_EQUAL(0.0, checked.worst_error(), 1e-12);
  LONGS_EQUAL(1, trainer.stats().pruning_undone);
  DOUBLES_EQUAL(0.0, trainer.stats().rms, 1e-12);  // the stats are the kept model's
}

TEST(AlnTrain, UndoneSplitRoundsCountAgainstTheRoundCapOnlyWhenConfiguredSo) {
  // Noisy rooms at a tight epsilon: rounds are undone on the way (which ones depends on the
  // seed and on the platform's rounding, so several rooms and caps are tried). Counting
  // them (the default), every round begun counts; without, training that neither reached
  // epsilon nor gave up on failures ends with max_iterations kept rounds, having begun as
  // many more as it undid.
  std::size_t with_undone = 0;
  for (const std::uint64_t seed : {77U, 3U, 31U, 5U}) {
    const std::size_t n = fill_room(3000, 0.3, seed);
    for (const std::size_t cap : {std::size_t{3}, std::size_t{4}, std::size_t{5}}) {
      set_room_ranges(g_model3);
      aln::TrainerConfig cfg;
      cfg.epsilon = 0.02;
      cfg.max_iterations = cap;
      g_trainer3.configure(cfg);
      CHECK(g_trainer3.train(aln::SampleSet<float, 3>(g_samples3, n), g_model3));
      LONGS_EQUAL(g_trainer3.stats().rounds, g_trainer3.stats().iterations);
      CHECK(g_trainer3.stats().iterations <= cap);
      cfg.count_undone_rounds = false;
      g_trainer3.configure(cfg);
      set_room_ranges(g_model3);
      CHECK(g_trainer3.train(aln::SampleSet<float, 3>(g_samples3, n), g_model3));
      const aln::TrainerStats& st = g_trainer3.stats();
      LONGS_EQUAL(st.iterations + st.failed_rounds, st.rounds);
      CHECK(st.iterations <= cap);
      if (st.failed_rounds <= cfg.max_failed_rounds && st.rms > cfg.epsilon) {
        LONGS_EQUAL(cap, st.iterations);  // neither the failures nor epsilon ended it
        with_undone += st.failed_rounds > 0 ? 1U : 0U;
      }
    }
  }
  CHECK(with_undone > 0);
}

TEST(AlnTrain, AWarmStartKeepsTheLastFitsPiecesSoRefitsAloneReachEpsilon) {
  // The last fit of a place, then new samples of the same room (another noise draw, as a
  // later look from where the robot stands). With no split rounds allowed, a cold start is
  // one plane, far from epsilon; a warm start from the last fit refits its pieces to the new
  // samples and is within it.
  aln::TrainerConfig cfg;
  cfg.epsilon = 0.1;
  g_trainer3.configure(cfg);
  std::size_t n = fill_room(3000, 0.03, 8);
  set_room_ranges(g_model3b);
  CHECK(g_trainer3.train(aln::SampleSet<float, 3>(g_samples3, n), g_model3b));
  CHECK(g_trainer3.stats().rms <= cfg.epsilon);
  const std::size_t last_fit_pieces = g_model3b.piece_count();
  CHECK(last_fit_pieces >= 4);
  n = fill_room(3000, 0.03, 9);
  cfg.max_iterations = 0;  // refits only
  g_trainer3.configure(cfg);
  set_room_ranges(g_model3);
  CHECK(g_trainer3.train(aln::SampleSet<float, 3>(g_samples3, n), g_model3));
  CHECK(g_trainer3.stats().rms > 1.5 * cfg.epsilon);
  CHECK(g_trainer3.start_from(aln::SampleSet<float, 3>(g_samples3, n), g_model3b));
  while (!g_trainer3.run_unit(997)) {
  }
  CHECK(g_trainer3.stats().rms <= cfg.epsilon);
  CHECK(g_model3b.piece_count() >= 2);
  CHECK(g_model3b.piece_count() <= last_fit_pieces);
  CHECK(g_model3b.pieces_within_bounds());
}

TEST(AlnTrain, AWarmStartClampsTheWeightsIntoTheirBoundsAndRefusesTooManyPieces) {
  const std::size_t n = fill_room(2000, 0.0, 4);
  set_room_ranges(g_model3);
  aln::TrainerConfig cfg;
  cfg.epsilon = 0.05;
  cfg.max_iterations = 3;
  g_trainer3.configure(cfg);
  CHECK(g_trainer3.train(aln::SampleSet<float, 3>(g_samples3, n), g_model3));
  const std::size_t pieces = g_model3.piece_count();
  CHECK(pieces > 2);
  // A weight beyond its bound (as a model read from another configuration might have).
  aln::Piece<float, 3>& p = g_model3.piece(0);
  p.set(Eigen::Vector3f(p.weight(0), p.weight(1), g_model3.weight_hi(2) + 5.0F), p.centroid,
        p.centroid_output);
  CHECK(!g_model3.pieces_within_bounds());
  cfg.max_iterations = 0;  // refits only
  g_trainer3.configure(cfg);
  CHECK(g_trainer3.start_from(aln::SampleSet<float, 3>(g_samples3, n), g_model3));
  CHECK(g_model3.pieces_within_bounds());
  while (!g_trainer3.run_unit(500)) {
  }
  CHECK(g_model3.pieces_within_bounds());
  CHECK(g_model3.piece_count() <= pieces);
  // More pieces than the cap: refused, the model left as it is.
  cfg.max_pieces = 2;
  g_trainer3.configure(cfg);
  const std::size_t before = g_model3.piece_count();
  CHECK_FALSE(g_trainer3.start_from(aln::SampleSet<float, 3>(g_samples3, n), g_model3));
  LONGS_EQUAL(before, g_model3.piece_count());
  CHECK(g_trainer3.done());
  // An empty sample set is refused too.
  cfg.max_pieces = 0;
  g_trainer3.configure(cfg);
  CHECK_FALSE(g_trainer3.start_from(aln::SampleSet<float, 3>(), g_model3));
}

// Every k-th of the first n room samples, copied behind them in g_samples3 (from index n).
aln::SampleSet<float, 3> every_kth_room_sample(std::size_t n, std::size_t k) {
  std::size_t m = 0;
  for (std::size_t i = 0; i < n; i += k) g_samples3[n + m++] = g_samples3[i];
  return {g_samples3 + n, m};
}

double sse_over(const Model3& m, aln::SampleSet<float, 3> samples) {
  double sse = 0.0;
  for (const auto& s : samples) {
    const double r = static_cast<double>(m.evaluate(s.x).value - s.y);
    sse += r * r;
  }
  return sse;
}

TEST(AlnTrain, CoarseToFineSplitsOnEveryKthSampleThenRefitsOnAllWithoutSplitting) {
  // The coarse phase is training on every 4th sample, pass for pass; the fine phase then
  // refits that model on all samples: no more pieces, no worse a fit of them, and the stats
  // (RMS) of the model returned, on all samples.
  const std::size_t n = fill_room(2400, 0.03, 6);
  const aln::SampleSet<float, 3> all(g_samples3, n);
  const aln::SampleSet<float, 3> quarter = every_kth_room_sample(n, 4);
  aln::TrainerConfig cfg;
  cfg.epsilon = 0.03;
  cfg.seed = 3;
  g_trainer3.configure(cfg);
  set_room_ranges(g_model3b);
  CHECK(g_trainer3.train(quarter, g_model3b));
  const aln::TrainerStats coarse = g_trainer3.stats();
  CHECK(g_model3b.piece_count() > 2);
  cfg.coarse_stride = 4;
  g_trainer3.configure(cfg);
  set_room_ranges(g_model3);
  CHECK(g_trainer3.train(all, g_model3));
  const aln::TrainerStats& fine = g_trainer3.stats();
  LONGS_EQUAL(coarse.passes, fine.coarse_passes);
  LONGS_EQUAL(coarse.iterations, fine.iterations);
  CHECK(fine.passes > fine.coarse_passes);
  CHECK(g_model3.piece_count() <= g_model3b.piece_count());
  CHECK(sse_over(g_model3, all) <= sse_over(g_model3b, all) * (1.0 + 1e-6));
  DOUBLES_EQUAL(std::sqrt(sse_over(g_model3, all) / static_cast<double>(n)), fine.rms, 1e-4);
  CHECK(g_model3.pieces_within_bounds());
  // Sliced, the same model.
  set_room_ranges(g_model3b);
  CHECK(g_trainer3.start(all, g_model3b));
  std::size_t budget = 1;
  while (!g_trainer3.run_unit(budget)) budget = budget * 3 % 997 + 1;
  CHECK(same_model(g_model3, g_model3b));
}

TEST(AlnTrain, TheFinePhaseStopsAfterMaxFinePassesWithTheBestModelOfThem) {
  // The same coarse phase three times; the fine phase unbounded, capped at 2 passes (the
  // coarse model evaluated on all samples, then one refit) and at 1 (evaluated only).
  const std::size_t n = fill_room(2400, 0.03, 6);
  const aln::SampleSet<float, 3> all(g_samples3, n);
  aln::TrainerConfig cfg;
  cfg.epsilon = 0.03;
  cfg.seed = 3;
  cfg.coarse_stride = 4;
  g_trainer3.configure(cfg);
  set_room_ranges(g_model3);
  CHECK(g_trainer3.train(all, g_model3));
  const aln::TrainerStats unbounded = g_trainer3.stats();
  const std::size_t unbounded_fine = unbounded.passes - unbounded.coarse_passes;
  CHECK(unbounded_fine > 2);
  const double sse_unbounded = sse_over(g_model3, all);
  cfg.max_fine_passes = 2;
  g_trainer3.configure(cfg);
  set_room_ranges(g_model3b);
  CHECK(g_trainer3.train(all, g_model3b));
  const aln::TrainerStats two = g_trainer3.stats();
  LONGS_EQUAL(unbounded.coarse_passes, two.coarse_passes);
  LONGS_EQUAL(2, two.passes - two.coarse_passes);
  const double sse_two = sse_over(g_model3b, all);
  DOUBLES_EQUAL(std::sqrt(sse_two / static_cast<double>(n)), two.rms, 1e-4);
  CHECK(sse_unbounded <= sse_two * (1.0 + 1e-6));  // more passes, never a worse best
  cfg.max_fine_passes = 1;
  g_trainer3.configure(cfg);
  set_room_ranges(g_model3b);
  CHECK(g_trainer3.train(all, g_model3b));
  LONGS_EQUAL(1, g_trainer3.stats().passes - g_trainer3.stats().coarse_passes);
  CHECK(sse_two <= sse_over(g_model3b, all) * (1.0 + 1e-6));  // the refit was kept: better
  CHECK(sse_two < sse_over(g_model3b, all));
}

TEST(AlnTrain, TheFinePhaseRefitsButNeverSplitsHoweverBadlyTheCoarseModelFitsAllSamples) {
  // Every 4th sample lies on a plane, the others on a V: the coarse phase sees the plane
  // only and ends with one piece at once; the fine phase refits that piece to the V's
  // samples (RMS far over epsilon) and still does not split.
  aln_test::Rng rng(5);
  const std::size_t n = 2000;
  for (std::size_t k = 0; k < n; ++k) {
    auto& s = g_samples2[k];
    s.x = Eigen::Vector2d(rng.uniform(0.0, 1.0), rng.uniform(0.0, 1.0));
    s.y = k % 4 == 0 ? 0.5 : 2.0 * std::fabs(s.x(0) - 0.5);
    s.weight = 1.0;
  }
  set_unit_ranges(g_model2);
  aln::TrainerConfig cfg;
  cfg.epsilon = 0.05;
  cfg.coarse_stride = 4;
  g_trainer2.configure(cfg);
  CHECK(g_trainer2.train(aln::SampleSet<double, 2>(g_samples2, n), g_model2));
  LONGS_EQUAL(1, g_model2.piece_count());
  LONGS_EQUAL(0, g_trainer2.stats().iterations);
  CHECK(g_trainer2.stats().rms > 4.0 * cfg.epsilon);
  // One phase splits the V.
  cfg.coarse_stride = 1;
  g_trainer2.configure(cfg);
  set_unit_ranges(g_model2b);
  CHECK(g_trainer2.train(aln::SampleSet<double, 2>(g_samples2, n), g_model2b));
  CHECK(g_model2b.piece_count() > 1);
}

TEST(AlnTrain, ACoarseStrideThatLeavesTooFewSamplesTrainsInOnePhase) {
  const std::size_t n = fill_room(400, 0.0, 2);
  aln::TrainerConfig cfg;
  cfg.epsilon = 0.05;
  cfg.coarse_stride = 8;  // 50 samples: fewer than the trainer fits a coarse phase on
  g_trainer3.configure(cfg);
  set_room_ranges(g_model3);
  CHECK(g_trainer3.train(aln::SampleSet<float, 3>(g_samples3, n), g_model3));
  LONGS_EQUAL(0, g_trainer3.stats().coarse_passes);
  cfg.coarse_stride = 1;
  g_trainer3.configure(cfg);
  set_room_ranges(g_model3b);
  CHECK(g_trainer3.train(aln::SampleSet<float, 3>(g_samples3, n), g_model3b));
  CHECK(same_model(g_model3, g_model3b));
}

TEST(AlnTrain, TrainingStepsDoNotAllocate) {
  const std::size_t n = fill_room(3000, 0.02, 3);
  set_room_ranges(g_model3);
  aln::TrainerConfig cfg;
  cfg.epsilon = 0.05;
  cfg.robust = aln::RobustWeighting::kTukey;
  g_trainer3.configure(cfg);
  bool done = false;
  CHECK_NO_ALLOCATION({
    CHECK(g_trainer3.start(aln::SampleSet<float, 3>(g_samples3, n), g_model3));
    while (!done) done = g_trainer3.run_unit(500);
  });
  CHECK(g_model3.piece_count() > 1);
  // A wall step whose Tukey training ends on a pruned model that fits worse than before
  // its pruning: the trainer evaluates it once more and returns the model before.
  const std::size_t m = fill_wall_step(2500, 0.05, 1);
  set_unit_ranges(g_model2);
  cfg.epsilon = 0.1;
  // Trains g_model2 on the wall step with `cfg`, 500 sample visits a step, from one piece or
  // (warm) from the model it holds.
  const auto train_wall_step = [&](bool warm) {
    g_trainer2.configure(cfg);
    const aln::SampleSet<double, 2> set(g_samples2, m);
    bool finished = false;
    CHECK_NO_ALLOCATION({
      CHECK(warm ? g_trainer2.start_from(set, g_model2) : g_trainer2.start(set, g_model2));
      while (!finished) finished = g_trainer2.run_unit(500);
    });
  };
  train_wall_step(false);
  CHECK(g_model2.piece_count() > 1);
  train_wall_step(true);  // a warm start from that model
  // Coarse to fine.
  cfg.coarse_stride = 4;
  train_wall_step(false);
  CHECK(g_trainer2.stats().coarse_passes > 0);
  // Damped refits, two fine passes.
  cfg.damped_refit = true;
  cfg.max_fine_passes = 2;
  train_wall_step(false);
  CHECK(g_trainer2.stats().coarse_passes > 0);
  // Hinge splits, their sums gathered in passes of their own.
  cfg.split = aln::SplitCandidates::kHinges;
  train_wall_step(false);
  CHECK(g_trainer2.stats().bin_passes > 0);
  // Restarts: every start ends above this epsilon, so two more starts from one piece.
  cfg.epsilon = 1e-4;
  cfg.max_iterations = 2;
  cfg.restarts = 2;
  train_wall_step(false);
  LONGS_EQUAL(2, g_trainer2.stats().restarts);
  // Checked prunings: a pruning judged, undone and the model evaluated again (the scene's
  // pieces are set by hand, so this holds on every platform; the wall step's fits differ
  // in the last bit between x86-64 and aarch64).
  static aln::Trainer<double, 1, 8> trainer1;
  PrunedPieceScene scene;
  CHECK_NO_ALLOCATION(scene.train(true, trainer1));
  LONGS_EQUAL(1, trainer1.stats().pruning_undone);
}

TEST(AlnTrain, AnEmptySampleSetIsRefused) {
  g_trainer3.configure(aln::TrainerConfig{});
  CHECK_FALSE(g_trainer3.start(aln::SampleSet<float, 3>(), g_model3));
  CHECK(g_trainer3.run_unit(10));
}

TEST_GROUP(ConstrainedLsq){};

// The KKT conditions certify the optimum of a convex QP: the gradient 2 (C w - g) is zero
// in free coordinates, >= 0 at a lower bound and <= 0 at an upper bound.
TEST(ConstrainedLsq, TheSolutionMeetsTheOptimalityConditionsAndBeatsClipping) {
  aln_test::Rng rng(77);
  int constrained = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    Eigen::Matrix3d a;
    for (int i = 0; i < 9; ++i) a(i / 3, i % 3) = rng.uniform(-1.0, 1.0);
    const Eigen::Matrix3d c = a * a.transpose() + 0.01 * Eigen::Matrix3d::Identity();
    const Eigen::Vector3d g(rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0));
    std::array<double, 3> lo{-0.5, -INFINITY, 0.1};
    std::array<double, 3> hi{0.5, 0.3, INFINITY};
    Eigen::Vector3d w;
    CHECK(aln::solve_box_constrained_lsq<3>(c, g, lo, hi, w));
    const Eigen::Vector3d grad = 2.0 * (c * w - g);
    bool any_active = false;
    for (int i = 0; i < 3; ++i) {
      const auto k = static_cast<std::size_t>(i);
      CHECK(w(i) >= lo[k] && w(i) <= hi[k]);
      if (w(i) == lo[k]) {
        CHECK(grad(i) >= -1e-9);
        any_active = true;
      } else if (w(i) == hi[k]) {
        CHECK(grad(i) <= 1e-9);
        any_active = true;
      } else {
        DOUBLES_EQUAL(0.0, grad(i), 1e-9);
      }
    }
    if (any_active) ++constrained;
    // Clipping the unconstrained optimum is never better.
    Eigen::Vector3d clipped = c.ldlt().solve(g);
    for (int i = 0; i < 3; ++i) {
      const auto k = static_cast<std::size_t>(i);
      clipped(i) = std::fmin(std::fmax(clipped(i), lo[k]), hi[k]);
    }
    const auto q = [&](const Eigen::Vector3d& v) { return v.dot(c * v) - 2.0 * g.dot(v); };
    CHECK(q(w) <= q(clipped) + 1e-12);
  }
  CHECK(constrained > 500);
}

TEST(AlnTrain, TrainsInOneAndFourDimensions) {
  static aln::Sample<double, 1> s1[400];
  static aln::Aln<double, 1, 8> m1;
  static aln::Trainer<double, 1, 8> t1;
  aln_test::Rng rng(71);
  for (auto& s : s1) {
    s.x(0) = rng.uniform(-1.0, 1.0);
    s.y = std::fabs(s.x(0) - 0.2);
  }
  m1.set_input_range(0, -1.0, 1.0);
  aln::TrainerConfig cfg;
  cfg.epsilon = 1e-6;
  t1.configure(cfg);
  CHECK(t1.train(aln::SampleSet<double, 1>(s1), m1));
  LONGS_EQUAL(2, m1.piece_count());
  DOUBLES_EQUAL(0.5, m1.evaluate(Eigen::Matrix<double, 1, 1>(0.7)).value, 1e-6);

  static aln::Sample<float, 4> s4[3000];
  static aln::Aln<float, 4, 16> m4;
  static aln::Trainer<float, 4, 16> t4;
  for (auto& s : s4) {
    for (int i = 0; i < 4; ++i) s.x(i) = static_cast<float>(rng.uniform(0.0, 1.0));
    s.y = std::fmax(s.x(0) + 0.5F * s.x(3), 1.2F - s.x(1) + 0.25F * s.x(2));
  }
  for (int i = 0; i < 4; ++i) m4.set_input_range(i, 0.0F, 1.0F);
  cfg.epsilon = 1e-3;
  t4.configure(cfg);
  CHECK(t4.train(aln::SampleSet<float, 4>(s4), m4));
  CHECK(m4.piece_count() <= 2);
  CHECK(t4.stats().rms < 1e-3);
}

TEST(AlnTrain, TheOverallRmsRuleStopsAtEpsilonWithNoMorePiecesThanThePerPieceRule) {
  const std::size_t n = fill_room(2000, 0.0, 44);
  set_room_ranges(g_model3);
  set_room_ranges(g_model3b);
  aln::TrainerConfig cfg;
  cfg.epsilon = 0.02;
  g_trainer3.configure(cfg);
  CHECK(g_trainer3.train(aln::SampleSet<float, 3>(g_samples3, n), g_model3));
  cfg.split_rule = aln::SplitRule::kOverallRms;
  g_trainer3.configure(cfg);
  CHECK(g_trainer3.train(aln::SampleSet<float, 3>(g_samples3, n), g_model3b));
  CHECK(g_trainer3.stats().rms <= 0.02);
  CHECK(g_model3b.piece_count() <= g_model3.piece_count());
  CHECK(g_model3b.pieces_within_bounds());
}

TEST(AlnTrain, HuberWeightsKeepTheFitCloseToTheCleanFunctionDespiteOutliers) {
  const std::size_t n = fill_room(3000, 0.05, 45);
  set_room_ranges(g_model3);
  aln::TrainerConfig cfg;
  cfg.epsilon = 0.1;
  cfg.max_iterations = 6;
  cfg.robust = aln::RobustWeighting::kHuber;
  g_trainer3.configure(cfg);
  CHECK(g_trainer3.train(aln::SampleSet<float, 3>(g_samples3, n), g_model3));
  CHECK(g_trainer3.stats().robust_rms < g_trainer3.stats().rms);
  aln_test::Rng rng(46);
  double sse = 0.0;
  for (int k = 0; k < 1000; ++k) {
    const Eigen::Vector3f x(static_cast<float>(rng.uniform(-3.0, 3.0)),
                            static_cast<float>(rng.uniform(0.0, 20.0)),
                            static_cast<float>(rng.uniform(0.0, 100.0)));
    const double e =
        static_cast<double>(g_model3.evaluate(x).value) - cylinder_room(static_cast<double>(x(2)));
    sse += e * e;
  }
  CHECK(std::sqrt(sse / 1000.0) < 0.1);
}

TEST(AlnTrain, TukeyTrainingOfAWallStepWithOutliersEndsOnAModelThatFitsTheWall) {
  // 5% outliers: a Tukey piece can lower its robust-weighted squared error by pushing its
  // samples out of the weights' window, so judged by that error, training could end on a
  // model that fits only one side of the step. Judged by the robust loss it cannot.
  for (const std::uint64_t seed : {1U, 3U, 5U}) {
    const std::size_t n = fill_wall_step(2500, 0.05, seed);
    set_unit_ranges(g_model2);
    aln::TrainerConfig cfg;
    cfg.epsilon = 0.1;
    cfg.robust = aln::RobustWeighting::kTukey;
    cfg.max_iterations = 0;  // the one-piece start
    g_trainer2.configure(cfg);
    CHECK(g_trainer2.train(aln::SampleSet<double, 2>(g_samples2, n), g_model2));
    const double start = loss_over(g_model2, g_samples2, n, cfg.robust, cfg.epsilon);
    cfg.max_iterations = 10;
    g_trainer2.configure(cfg);
    CHECK(g_trainer2.train(aln::SampleSet<double, 2>(g_samples2, n), g_model2));
    const std::string text = "seed " + std::to_string(seed);
    CHECK_TEXT(share_within(g_model2, g_samples2, n, cfg.epsilon) >= 0.9, text.c_str());
    CHECK_TEXT(loss_over(g_model2, g_samples2, n, cfg.robust, cfg.epsilon) < 0.2 * start,
               text.c_str());
  }
}

TEST(AlnTrain, TheRobustLossOfTheModelTrainingEndsWithNeverRisesWithMoreRounds) {
  // The model after k rounds is the one training with max_iterations = k returns: the loss
  // of the final model is never above the one-piece start's nor above any round's model.
  struct Run {
    aln::RobustWeighting kind;
    std::uint64_t seed;
    double epsilon;
  };
  for (const Run run :
       {Run{aln::RobustWeighting::kTukey, 1, 0.1}, Run{aln::RobustWeighting::kTukey, 5, 0.1},
        Run{aln::RobustWeighting::kTukey, 8, 0.05}, Run{aln::RobustWeighting::kHuber, 1, 0.1},
        Run{aln::RobustWeighting::kHuber, 8, 0.05}}) {
    const std::size_t n = fill_wall_step(2500, 0.05, run.seed);
    aln::TrainerConfig cfg;
    cfg.epsilon = run.epsilon;
    cfg.robust = run.kind;
    double start = 0.0;
    double previous = 0.0;
    for (std::size_t rounds = 0; rounds <= 12; ++rounds) {
      set_unit_ranges(g_model2);
      cfg.max_iterations = rounds;
      g_trainer2.configure(cfg);
      CHECK(g_trainer2.train(aln::SampleSet<double, 2>(g_samples2, n), g_model2));
      const double loss = loss_over(g_model2, g_samples2, n, run.kind, run.epsilon);
      if (rounds == 0) start = loss;
      const std::string text = "seed " + std::to_string(run.seed) + ", " + std::to_string(rounds) +
                               " rounds: " + std::to_string(loss);
      CHECK_TEXT(loss <= start * (1.0 + 1e-6), text.c_str());
      if (rounds > 0) CHECK_TEXT(loss <= previous * (1.0 + 1e-6), text.c_str());
      previous = loss;
    }
  }
}

TEST(AlnTrain, TheStatsReportTheRobustLossOfTheModelReturned) {
  const std::size_t n = fill_wall_step(2500, 0.05, 1);
  for (const auto kind : {aln::RobustWeighting::kHuber, aln::RobustWeighting::kTukey}) {
    set_unit_ranges(g_model2);
    aln::TrainerConfig cfg;
    cfg.epsilon = 0.1;
    cfg.robust = kind;
    g_trainer2.configure(cfg);
    CHECK(g_trainer2.train(aln::SampleSet<double, 2>(g_samples2, n), g_model2));
    const double loss = loss_over(g_model2, g_samples2, n, kind, cfg.epsilon);
    DOUBLES_EQUAL(loss, g_trainer2.stats().robust_loss, 1e-9 * loss);
    LONGS_EQUAL(g_model2.piece_count(), g_trainer2.stats().pieces);
  }
  // Without robust weights the loss is the sum of squared residuals.
  set_unit_ranges(g_model2);
  aln::TrainerConfig cfg;
  cfg.epsilon = 0.1;
  g_trainer2.configure(cfg);
  CHECK(g_trainer2.train(aln::SampleSet<double, 2>(g_samples2, n), g_model2));
  const double rms = g_trainer2.stats().rms;
  DOUBLES_EQUAL(rms * rms * static_cast<double>(n), g_trainer2.stats().robust_loss,
                1e-9 * g_trainer2.stats().robust_loss);
}
