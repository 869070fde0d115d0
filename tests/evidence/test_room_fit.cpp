// Tests of the occupancy fit on the thesis's simulated rooms: ray samples -> ALN trainer.
#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include "algo/aln/aln.h"
#include "algo/aln/samples.h"
#include "algo/aln/trainer.h"
#include "algo/core/fixed_vector.h"
#include "algo/evidence/occupancy_model.h"
#include "algo/evidence/ray_samples.h"
#include "synthetic_rooms.h"
#include "CppUTest/TestHarness.h"

using namespace boticelli;
using namespace boticelli::bench;

namespace {
using Model = aln::Aln<float, 3, 256>;
using Trainer = aln::Trainer<float, 3, 256>;
Model g_model;
Trainer g_trainer;
core::FixedVector<evidence::RaySample, 40000> g_ray_samples;

// The thesis table's samples of one room (suite thesis-table: 5 per reading, seam copies,
// no pads) with the sensor model's δr = delta_r_fraction · r.
std::vector<aln::Sample<float, 3>> room_samples(const SyntheticRoom& room, std::size_t features,
                                                const evidence::RaySampleParams& params) {
  const std::vector<evidence::Reading> readings = room.generate_readings(features, 2000U);
  g_ray_samples.clear();
  (void)evidence::append_ray_samples(readings, params, g_ray_samples);
  (void)evidence::append_seam_copies(g_ray_samples, evidence::kSeamMarginRad);
  return to_fit_samples(
      std::span<const evidence::RaySample>(g_ray_samples.data(), g_ray_samples.size()));
}

std::vector<aln::Sample<float, 3>> room_samples(const SyntheticRoom& room, std::size_t features,
                                                float delta_r_fraction) {
  evidence::RaySampleParams params;
  params.delta_r_fraction = delta_r_fraction;
  return room_samples(room, features, params);
}

// Trains g_model on the room's samples with the sensor model `rays` (its pan-slope bound too).
void fit_room(const SyntheticRoom& room, const std::vector<aln::Sample<float, 3>>& samples,
              const evidence::RaySampleParams& rays) {
  configure_room_model(g_model, room, evidence::alpha_slope_bound_per_rad(rays.delta_r_fraction));
  aln::TrainerConfig cfg;
  cfg.split = aln::SplitCandidates::kHinges;
  g_trainer.configure(cfg);
  CHECK(g_trainer.train(aln::SampleSet<float, 3>(samples.data(), samples.size()), g_model));
}

// The range [m] at which the model's occupancy at (α, h) first reaches m (bisection: the
// model grows with r); `far` if it never does.
float crossing_m(const Model& model, float alpha, float h, float m, float far) {
  if (model(Model::Vec(alpha, h, far)) < m) return far;
  float lo = 0.0F;
  float hi = far;
  for (int i = 0; i < 40; ++i) {
    const float mid = 0.5F * (lo + hi);
    (model(Model::Vec(alpha, h, mid)) < m ? lo : hi) = mid;
  }
  return lo;
}

double rms_of(const Model& model, const std::vector<aln::Sample<float, 3>>& samples) {
  double sse = 0.0;
  for (const auto& s : samples) {
    const double r = static_cast<double>(model(s.x) - s.y);
    sse += r * r;
  }
  return std::sqrt(sse / static_cast<double>(samples.size()));
}
}  // namespace

TEST_GROUP(RoomFit){};

TEST(RoomFit, TheRectangleRoomWithASharperSensorModelIsFittedToEpsilon) {
  // δr = 0.03 r (about the stereo's measured accuracy) makes the occupancy ramp before each
  // wall three times steeper than the thesis's 0.1 r. A fit whose splits were only a V at a
  // piece's centroid ended these 15 rounds at RMS 0.174 (34 pieces; 0.218 with 2 pieces when
  // one failed round ended training); hinges placed where the residuals bend reach epsilon.
  const SyntheticRoom room(*find_environment("rectangle"));
  const std::vector<aln::Sample<float, 3>> samples = room_samples(room, 3000, 0.03F);
  configure_room_model(g_model, room);
  aln::TrainerConfig cfg;
  cfg.epsilon = 0.15;
  cfg.max_iterations = 15;
  cfg.split = aln::SplitCandidates::kHinges;
  g_trainer.configure(cfg);
  CHECK(g_trainer.train(aln::SampleSet<float, 3>(samples.data(), samples.size()), g_model));
  const double rms = rms_of(g_model, samples);
  CHECK_TEXT(rms <= 0.15, std::to_string(rms).c_str());
  DOUBLES_EQUAL(g_trainer.stats().rms, rms, 1e-3);
  CHECK(g_model.piece_count() > 2);
}

TEST(RoomFit, TheStereoSizedSensorModelPutsTheSafeCrossingNearerTheWallThanTheThesissModel) {
  // The cylindrical room of radius 2.5 m seen from its centre: at the PTU's height the
  // occupancy should reach m_safe = 0.6 just before the wall. The thesis's δr = 0.1 r ramp
  // reaches 0.6 at about 0.8 r even for an exact fit; δr = 0.05 r (the stereo's accuracy) at
  // about 0.9 r. Mean crossing over 24 pan angles, at most a wall's range error beyond it.
  const SyntheticRoom room(*find_environment("cylinder_centre"));
  const float wall = 2.5F;
  double crossing[2] = {0.0, 0.0};
  const evidence::RaySampleParams settings[2] = {evidence::RaySampleParams{},
                                                 evidence::stereo_ray_sample_params()};
  for (int k = 0; k < 2; ++k) {
    const std::vector<aln::Sample<float, 3>> samples = room_samples(room, 3000, settings[k]);
    fit_room(room, samples, settings[k]);
    for (int i = 0; i < 24; ++i) {
      const float alpha = 2.0F * 3.14159265F * static_cast<float>(i) / 24.0F;
      const float r = crossing_m(g_model, alpha, 0.0F, 0.6F, 5.0F);
      CHECK(r <= wall * (1.0F + settings[k].delta_r_fraction));
      crossing[k] += static_cast<double>(r) / 24.0;
    }
  }
  CHECK_TEXT(crossing[0] < 0.85 * double{wall}, std::to_string(crossing[0]).c_str());
  CHECK_TEXT(crossing[1] > 0.87 * double{wall}, std::to_string(crossing[1]).c_str());
}

TEST(RoomFit, DampedRefitsKeepTheCorridorsSplitRoundsThatPlainRefitsUndo) {
  // The corridor as vs-octomap fits it with the thesis's sensor model (camera readings, ray
  // samples with pads and seam copies, hinges, coarse to fine on every 8th sample). A plain
  // refit of the pieces after a split raised the loss (a piece's least squares ignore that
  // moving it changes which piece is responsible where), so most rounds were undone and the
  // fit stopped near RMS 0.2; refits damped towards the round's best model keep them.
  const SyntheticRoom room(*find_environment("corridor"));
  const std::vector<evidence::Reading> readings =
      room.generate_camera_readings(CameraScan{}, 5000, 7U);
  const evidence::RaySampleParams rays;
  const std::vector<aln::Sample<float, 3>> samples =
      room_fit_samples(room, readings, rays, g_ray_samples);
  aln::TrainerConfig cfg;
  cfg.split = aln::SplitCandidates::kHinges;
  cfg.coarse_stride = 8;
  cfg.max_fine_passes = 2;
  double rms[2] = {0.0, 0.0};
  std::size_t failed[2] = {0, 0};
  for (int damped = 0; damped < 2; ++damped) {
    cfg.damped_refit = damped == 1;
    configure_room_model(g_model, room, evidence::alpha_slope_bound_per_rad(rays.delta_r_fraction));
    g_trainer.configure(cfg);
    CHECK(g_trainer.train(aln::SampleSet<float, 3>(samples.data(), samples.size()), g_model));
    rms[damped] = rms_of(g_model, samples);
    failed[damped] = g_trainer.stats().failed_rounds;
    CHECK(g_model.pieces_within_bounds());
  }
  const std::string text = std::to_string(rms[0]) + " " + std::to_string(failed[0]) + " / " +
                           std::to_string(rms[1]) + " " + std::to_string(failed[1]);
  // Plain refits (measured on x86-64: RMS 0.199, 6 rounds undone) are not checked: that they
  // fail is the problem, not a contract. Damped: RMS 0.107, 1 round undone.
  CHECK_TEXT(failed[1] <= 2 && rms[1] <= 0.15, text.c_str());
}
