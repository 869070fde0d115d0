// §4.4.2: independent opinion reinforces a repeated poor reading; regression does not.
#include <cmath>
#include <cstddef>

#include <Eigen/Core>

#include "algo/aln/aln.h"
#include "algo/aln/samples.h"
#include "algo/aln/trainer.h"
#include "algo/core/angles.h"
#include "algo/core/fixed_vector.h"
#include "algo/evidence/ray_samples.h"
#include "algo/fusion/combination_rules.h"
#include "CppUTest/TestHarness.h"

using namespace boticelli;

namespace {

constexpr std::size_t kPieces = 16;
using Model = aln::Aln<float, 3, kPieces>;
using Trainer = aln::Trainer<float, 3, kPieces>;
using AlnSample = aln::Sample<float, 3>;
constexpr std::size_t kReadings = 120;
constexpr std::size_t kSamples = 2 * 5 * kReadings;

// Static: the trainer holds its working memory inside (about 0.5 KB per piece).
Model g_once;
Model g_twice;
Trainer g_trainer;
core::FixedVector<evidence::RaySample, kSamples> g_ray;
AlnSample g_samples[kSamples];

void configure(Model& m) {
  m.set_input_range(0, 0.0F, core::kTwoPi<float>);
  m.set_input_range(1, -1.0F, 1.0F);
  m.set_input_range(2, 0.0F, 4.0F);
  m.set_weight_bounds(0, -1.0F, 1.0F);                                    // Eq 4.28, per rad
  m.set_weight_bounds(1, -10.0F, 10.0F);                                  // Eq 4.28, 1/dm
  m.set_weight_bounds(2, 1e-4F, std::numeric_limits<float>::infinity());  // Eq 4.27
}

// Poor features (m = 0.6, §4.4.2) on a wall 2 m away whose distance grows with α.
std::size_t make_samples() {
  g_ray.clear();
  for (std::size_t i = 0; i < kReadings; ++i) {
    const float a = core::kTwoPi<float> * (static_cast<float>(i) + 0.5F) / kReadings;
    const float h = -0.8F + 1.6F * static_cast<float>(i % 7) / 6.0F;
    const evidence::Reading reading{a, h, 2.0F + 0.15F * a, 0.6F};
    (void)evidence::append_plausibility_samples(reading, evidence::RaySampleParams{}, g_ray);
  }
  for (std::size_t i = 0; i < g_ray.size(); ++i) {
    g_samples[i].x = Eigen::Vector3f(g_ray[i].alpha_rad, g_ray[i].h_m, g_ray[i].r_m);
    g_samples[i].y = g_ray[i].occupancy;
    g_samples[i].weight = 1.0F;
  }
  return g_ray.size();
}

void train(Model& model, std::size_t n) {
  configure(model);
  aln::TrainerConfig cfg;
  cfg.epsilon = 0.05;
  cfg.max_iterations = 6;
  g_trainer.configure(cfg);
  CHECK(g_trainer.train(aln::SampleSet<float, 3>(g_samples, n), model));
}

}  // namespace

TEST_GROUP(RegressionFusion){};

TEST(RegressionFusion, RefittingOnTheSameSamplesTwiceLeavesThePredictionUnchanged) {
  const std::size_t n = make_samples();
  train(g_once, n);
  const std::size_t pieces_once = g_once.piece_count();
  CHECK(pieces_once > 1);  // a real fit with splits, not one flat piece
  // The same readings seen a second time: every sample duplicated.
  for (std::size_t i = 0; i < n; ++i) {
    g_samples[n + i] = g_samples[i];
  }
  train(g_twice, 2 * n);
  LONGS_EQUAL(pieces_once, g_twice.piece_count());
  double worst = 0.0;
  double at_features = 0.0;
  for (int i = 0; i < 200; ++i) {
    const float a = core::kTwoPi<float> * (static_cast<float>(i) + 0.25F) / 200.0F;
    for (float r = 0.2F; r < 3.5F; r += 0.3F) {
      const Eigen::Vector3f x(a, 0.1F, r);
      worst = std::fmax(worst, std::fabs(static_cast<double>(g_once(x) - g_twice(x))));
    }
    const Eigen::Vector3f feature(a, 0.0F, 2.0F + 0.15F * a);
    at_features = std::fmax(at_features, static_cast<double>(g_twice(feature)));
  }
  DOUBLES_EQUAL(0.0, worst, 1e-4);
  // The fused occupancy at the features stays near their evidence 0.6 ...
  DOUBLES_EQUAL(0.6, at_features, 0.06);
  // ... while the independent opinion pool of the two looks claims 0.69 (Eq 4.10).
  CHECK(fusion::independent_opinion(0.6, 0.6) > 0.69);
}
