// Value function V(x, y) as a 2-D ALN fitted by value iteration over sampled states (Eqs 5.7, 5.8;
// §5.5.3–5.5.4).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "algo/aln/aln.h"
#include "algo/aln/samples.h"
#include "algo/aln/trainer.h"
#include "algo/core/geometry.h"
#include "algo/planning/rewards.h"

namespace boticelli::planning {

inline constexpr std::size_t kActionCount = 8;  // §5.5.4: eight directions for the robot
inline constexpr std::size_t kMaxStates = 512;
inline constexpr std::size_t kMaxValuePieces = 64;

using ValueAln = aln::Aln<float, 2, kMaxValuePieces>;

struct ValueIterationParams {
  float discount = 0.9F;            // γ of Eqs 5.7, 5.8
  float step_m = 0.3F;              // constant action distance (§5.5.4)
  std::size_t state_count = 200;    // about this many states per plan (jittered grid)
  std::size_t sweeps = 20;          // Bellman backups, each followed by an ALN fit
  float window_half_size_m = 4.0F;  // states are sampled in this square around the robot
  // A state and a move must keep this far [m] from every obstacle point: the robot radius
  // plus the polygon's clearance margin, so plans keep off walls as the polygon does.
  float robot_radius_m = 0.25F;
  float fit_tolerance = 0.005F;  // ALN fit RMS, as a fraction of the targets' spread
  std::size_t max_pieces = 48;   // ALN piece cap (≤ kMaxValuePieces)
  std::size_t fit_rounds = 12;   // ALN split rounds per fit (trainer max_iterations)
  std::size_t fit_passes = 8;    // assign/refit passes per round (trainer max_refit_passes)
  std::uint32_t seed = 1;        // state sampling: same seed, same plan
};

// Direction of action a [rad, world frame]: a·45°.
float action_heading_rad(std::size_t action);

// Fitted value iteration (§5.5.3): states s_i are sampled (one per cell of a jittered grid
// fixed in the world frame) in the window where the robot's
// disc keeps clear of every known obstacle point (the space not known to be blocked, so
// values can flow around walls into parts not yet seen); each sweep computes the Bellman
// targets y_i = max_a (r(s_i, a) + γ V(s'_ia)) over the actions whose straight move keeps
// clear (Eq 5.8), then refits the ALN V to {(s_i, y_i)} (resumable trainer). Rewards at the
// arrival states are computed once per plan. Resumable: run_unit(budget) does one bounded unit.
class ValueIteration {
 public:
  ValueIteration() = default;
  ValueIteration(const ValueIteration&) = delete;
  ValueIteration& operator=(const ValueIteration&) = delete;

  // Starts a plan around `centre` [world]. `sources` must stay valid until done().
  void start(const ValueIterationParams& params, const RewardParams& rewards,
             const RewardSources& sources, core::Point2 centre);
  // Does about `budget` units of work (one unit: a state-action's reward, a state's
  // Bellman target, or a sample visit of the ALN trainer). True when the plan is done.
  bool run_unit(std::size_t budget);
  [[nodiscard]] bool done() const { return phase_ == Phase::kDone; }

  // V(s) [reward] of the last completed fit (0 before the first).
  [[nodiscard]] float value(core::Point2 world) const;
  [[nodiscard]] const ValueAln& model() const { return model_; }
  [[nodiscard]] std::size_t state_count() const { return state_count_; }
  [[nodiscard]] core::Point2 state(std::size_t i) const { return states_[i]; }
  [[nodiscard]] std::size_t sweeps_done() const { return sweep_; }
  // The ALN trainer's statistics of the last fit (pieces, RMS error in reward units).
  [[nodiscard]] const aln::TrainerStats& fit_stats() const { return trainer_.stats(); }
  // Sweeps whose fit was worse than the previous V on the same targets and was not kept.
  [[nodiscard]] std::size_t rejected_fits() const { return rejected_fits_; }
  [[nodiscard]] const ValueIterationParams& params() const { return params_; }
  [[nodiscard]] const RewardParams& rewards() const { return rewards_; }
  [[nodiscard]] const RewardSources& sources() const { return sources_; }

  // True if the robot's disc moving straight from a to b keeps clear of every obstacle point.
  [[nodiscard]] bool move_clear(core::Point2 a, core::Point2 b) const;

 private:
  enum class Phase : std::uint8_t { kIdle, kSample, kRewards, kTargets, kFit, kDone };
  using Trainer = aln::Trainer<float, 2, kMaxValuePieces, 0>;  // V splits, no hinge sums
  using Sample = aln::Sample<float, 2>;

  std::size_t sample_states(std::size_t budget);
  std::size_t compute_rewards(std::size_t budget);
  std::size_t compute_targets(std::size_t budget);
  void begin_fit();
  [[nodiscard]] bool inside_window(core::Point2 p) const;
  [[nodiscard]] bool state_clear(core::Point2 p) const;
  [[nodiscard]] float uniform(float lo, float hi);
  [[nodiscard]] float rms_on_samples(const ValueAln& v) const;

  ValueIterationParams params_{};
  RewardParams rewards_{};
  RewardSources sources_{};
  core::Point2 centre_{};
  Phase phase_ = Phase::kIdle;
  std::uint32_t rng_ = 1;
  std::size_t cursor_ = 0;
  std::size_t tries_ = 0;
  std::size_t sweep_ = 0;
  std::size_t rejected_fits_ = 0;
  std::size_t fit_attempt_ = 0;
  static constexpr std::size_t kFitAttempts = 3;
  std::size_t state_count_ = 0;
  bool have_model_ = false;
  std::array<core::Point2, kMaxStates> states_{};
  std::array<std::array<float, kActionCount>, kMaxStates> reward_{};
  std::array<std::uint8_t, kMaxStates> allowed_{};  // bit a: action a keeps clear
  std::array<Sample, kMaxStates> samples_{};
  ValueAln model_{};
  ValueAln training_{};
  Trainer trainer_{};
};

}  // namespace boticelli::planning
