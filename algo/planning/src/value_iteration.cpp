// Fitted value iteration with an ALN value function (Eqs 5.7, 5.8; §5.5.3), in resumable slices.
#include "algo/planning/value_iteration.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "algo/core/angles.h"

namespace boticelli::planning {
namespace {

float point_segment_distance_m(core::Point2 p, core::Point2 a, core::Point2 b) {
  const float ex = b.x_m - a.x_m;
  const float ey = b.y_m - a.y_m;
  const float len2 = ex * ex + ey * ey;
  float t = len2 > 0.0F ? ((p.x_m - a.x_m) * ex + (p.y_m - a.y_m) * ey) / len2 : 0.0F;
  t = std::clamp(t, 0.0F, 1.0F);
  const float dx = p.x_m - (a.x_m + t * ex);
  const float dy = p.y_m - (a.y_m + t * ey);
  return std::sqrt(dx * dx + dy * dy);
}

}  // namespace

float action_heading_rad(std::size_t action) {
  return static_cast<float>(action) * core::kTwoPi<float> / static_cast<float>(kActionCount);
}

void ValueIteration::start(const ValueIterationParams& params, const RewardParams& rewards,
                           const RewardSources& sources, core::Point2 centre) {
  params_ = params;
  params_.state_count = std::clamp<std::size_t>(params.state_count, 1, kMaxStates);
  params_.max_pieces = std::clamp<std::size_t>(params.max_pieces, 1, kMaxValuePieces);
  rewards_ = rewards;
  sources_ = sources;
  centre_ = centre;
  rng_ = params.seed * 2654435761U + 0x9E3779B9U;
  cursor_ = 0;
  tries_ = 0;
  sweep_ = 0;
  rejected_fits_ = 0;
  fit_attempt_ = 0;
  state_count_ = 0;
  have_model_ = false;
  model_ = ValueAln{};
  const float w = params_.window_half_size_m;
  for (int i = 0; i < 2; ++i) {
    model_.set_input_range(i, -w, w);
    training_.set_input_range(i, -w, w);
  }
  phase_ = Phase::kSample;
}

float ValueIteration::uniform(float lo, float hi) {
  rng_ ^= rng_ << 13;
  rng_ ^= rng_ >> 17;
  rng_ ^= rng_ << 5;
  return lo + (hi - lo) * static_cast<float>(rng_ >> 8) / 16777216.0F;
}

bool ValueIteration::inside_window(core::Point2 p) const {
  const float w = params_.window_half_size_m;
  return std::fabs(p.x_m - centre_.x_m) <= w && std::fabs(p.y_m - centre_.y_m) <= w;
}

bool ValueIteration::state_clear(core::Point2 p) const {
  return std::all_of(sources_.obstacles.begin(), sources_.obstacles.end(), [&](core::Point2 o) {
    const float dx = p.x_m - o.x_m;
    const float dy = p.y_m - o.y_m;
    return dx * dx + dy * dy >= params_.robot_radius_m * params_.robot_radius_m;
  });
}

bool ValueIteration::move_clear(core::Point2 a, core::Point2 b) const {
  return std::all_of(sources_.obstacles.begin(), sources_.obstacles.end(), [&](core::Point2 o) {
    return point_segment_distance_m(o, a, b) >= params_.robot_radius_m;
  });
}

float ValueIteration::value(core::Point2 world) const {
  if (!have_model_) {
    return 0.0F;
  }
  ValueAln::Vec x;
  x << world.x_m - centre_.x_m, world.y_m - centre_.y_m;
  return model_.evaluate_alpha_beta(x).value;
}

// Jittered grid anchored to the world frame: cell (i, j) of size g holds one state at a
// pseudo-random offset that depends only on (i, j) and the seed. Plans made from nearby
// poses share most of their states, so their value functions agree and the robot does
// not dither between two of them; the samples still fill the window evenly.
std::size_t ValueIteration::sample_states(std::size_t budget) {
  const float w = params_.window_half_size_m;
  const auto per_side =
      static_cast<std::size_t>(std::ceil(std::sqrt(static_cast<float>(params_.state_count))));
  const float g = 2.0F * w / static_cast<float>(per_side);
  const auto i0 = static_cast<std::int64_t>(std::floor((centre_.x_m - w) / g));
  const auto j0 = static_cast<std::int64_t>(std::floor((centre_.y_m - w) / g));
  const std::size_t side = per_side + 1;
  std::size_t used = 0;
  while (used < budget && tries_ < side * side && state_count_ < kMaxStates) {
    const std::int64_t i = i0 + static_cast<std::int64_t>(tries_ % side);
    const std::int64_t j = j0 + static_cast<std::int64_t>(tries_ / side);
    ++tries_;
    ++used;
    std::uint32_t h = static_cast<std::uint32_t>(i) * 73856093U ^
                      static_cast<std::uint32_t>(j) * 19349663U ^ params_.seed * 83492791U;
    rng_ = h == 0 ? 1U : h;
    const float jx = uniform(0.0F, 1.0F);
    const float jy = uniform(0.0F, 1.0F);
    const core::Point2 s{(static_cast<float>(i) + jx) * g, (static_cast<float>(j) + jy) * g};
    if (inside_window(s) && state_clear(s)) {
      states_[state_count_++] = s;
    }
  }
  if (tries_ >= side * side || state_count_ >= kMaxStates) {
    cursor_ = 0;
    phase_ = state_count_ == 0 ? Phase::kDone : Phase::kRewards;
  }
  return used;
}

std::size_t ValueIteration::compute_rewards(std::size_t budget) {
  std::size_t used = 0;
  while (used < budget && cursor_ < state_count_) {
    const core::Point2 s = states_[cursor_];
    allowed_[cursor_] = 0;
    for (std::size_t a = 0; a < kActionCount; ++a) {
      const float h = action_heading_rad(a);
      const core::Point2 next{s.x_m + params_.step_m * std::cos(h),
                              s.y_m + params_.step_m * std::sin(h)};
      reward_[cursor_][a] = reward_at(rewards_, sources_, next);
      if (inside_window(next) && move_clear(s, next)) {
        allowed_[cursor_] = static_cast<std::uint8_t>(allowed_[cursor_] | (1U << a));
      }
    }
    ++cursor_;
    used += kActionCount;
  }
  if (cursor_ >= state_count_) {
    cursor_ = 0;
    phase_ = Phase::kTargets;
  }
  return used;
}

std::size_t ValueIteration::compute_targets(std::size_t budget) {
  std::size_t used = 0;
  const float gamma = params_.discount;
  while (used < budget && cursor_ < state_count_) {
    const core::Point2 s = states_[cursor_];
    float best = -std::numeric_limits<float>::infinity();
    for (std::size_t a = 0; a < kActionCount; ++a) {
      if ((allowed_[cursor_] & (1U << a)) == 0) {
        continue;
      }
      const float h = action_heading_rad(a);
      const core::Point2 next{s.x_m + params_.step_m * std::cos(h),
                              s.y_m + params_.step_m * std::sin(h)};
      best = std::max(best, reward_[cursor_][a] + gamma * value(next));  // Eq 5.8
    }
    if (!(best > -std::numeric_limits<float>::infinity())) {
      best = gamma * value(s);  // boxed in: it can only stay
    }
    Sample& sample = samples_[cursor_];
    sample.x << s.x_m - centre_.x_m, s.y_m - centre_.y_m;
    sample.y = best;
    sample.weight = 1.0F;
    ++cursor_;
    ++used;
  }
  if (cursor_ >= state_count_) {
    begin_fit();
  }
  return used;
}

float ValueIteration::rms_on_samples(const ValueAln& v) const {
  double sse = 0.0;
  for (std::size_t i = 0; i < state_count_; ++i) {
    const double r =
        static_cast<double>(v.evaluate_alpha_beta(samples_[i].x).value - samples_[i].y);
    sse += r * r;
  }
  return static_cast<float>(
      std::sqrt(sse / static_cast<double>(std::max<std::size_t>(state_count_, 1))));
}

void ValueIteration::begin_fit() {
  float lo = std::numeric_limits<float>::infinity();
  float hi = -std::numeric_limits<float>::infinity();
  for (std::size_t i = 0; i < state_count_; ++i) {
    lo = std::min(lo, samples_[i].y);
    hi = std::max(hi, samples_[i].y);
  }
  aln::TrainerConfig config;
  config.epsilon = std::max(1e-4, static_cast<double>(params_.fit_tolerance * (hi - lo)));
  config.max_pieces = params_.max_pieces;
  config.max_iterations = params_.fit_rounds;
  config.max_refit_passes = params_.fit_passes;
  config.seed = params_.seed + static_cast<std::uint32_t>(sweep_ * 7919U + fit_attempt_ * 104729U);
  trainer_.configure(config);
  training_.set_output_range(lo, hi);
  (void)trainer_.start(aln::SampleSet<float, 2>(samples_.data(), state_count_), training_);
  phase_ = Phase::kFit;
}

bool ValueIteration::run_unit(std::size_t budget) {
  std::size_t left = std::max<std::size_t>(budget, 1);
  while (left > 0 && phase_ != Phase::kDone && phase_ != Phase::kIdle) {
    std::size_t used = 0;
    switch (phase_) {
      case Phase::kSample:
        used = sample_states(left);
        break;
      case Phase::kRewards:
        used = compute_rewards(left);
        break;
      case Phase::kTargets:
        used = compute_targets(left);
        break;
      case Phase::kFit: {
        const std::uint64_t before = trainer_.stats().sample_visits;
        const bool fitted = trainer_.run_unit(left);
        used = static_cast<std::size_t>(trainer_.stats().sample_visits - before);
        if (fitted) {
          // The trainer restarts from one piece each sweep and now and then lands in a
          // poor fit (or one worse than its own statistics say): measure it, retry with
          // another seed, and keep the previous V if that still fits the targets better.
          used += 2 * state_count_;
          const bool better = !have_model_ || rms_on_samples(training_) <= rms_on_samples(model_);
          if (!better && fit_attempt_ + 1 < kFitAttempts) {
            ++fit_attempt_;
            begin_fit();
            break;
          }
          if (better) {
            model_ = training_;
          } else {
            ++rejected_fits_;
          }
          have_model_ = true;
          ++sweep_;
          fit_attempt_ = 0;
          cursor_ = 0;
          phase_ = sweep_ >= params_.sweeps ? Phase::kDone : Phase::kTargets;
        }
        break;
      }
      case Phase::kIdle:
      case Phase::kDone:
        break;
    }
    left -= std::min(left, std::max<std::size_t>(used, 1));
  }
  return phase_ == Phase::kDone;
}

}  // namespace boticelli::planning
