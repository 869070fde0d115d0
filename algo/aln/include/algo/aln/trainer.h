// ALN training: grow a MIN/MAX tree from samples by splitting pieces until the error is below
// epsilon.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>

#include <Eigen/Core>

#include "algo/aln/aln.h"
#include "algo/aln/constrained_lsq.h"
#include "algo/aln/hinge_split.h"
#include "algo/aln/robust_loss.h"
#include "algo/aln/samples.h"
#include "algo/aln/trainer_config.h"
#include "algo/aln/trainer_pass.h"
#include "algo/aln/trainer_sums.h"

namespace boticelli::aln {

// Trains an Aln<Scalar, N, MaxPieces>. The method (docs/architecture.md, "ALN library"): every pass
// assigns each sample to its responsible piece (block evaluation, Aln::evaluate_block) and
// accumulates that piece's normal equations; then each piece is refitted exactly by box-constrained
// least squares (its weight bounds, Eqs 4.27-4.28), a k-plane / Lloyd iteration. When the error
// stops falling, pieces whose error exceeds epsilon are split, pieces no sample uses are
// pruned, and the next round starts. A split (TrainerConfig::split) is either a V at the
// piece's centroid (two tilted copies, MAX if the residuals rise towards the rim of its
// region, else MIN) or the best of many hinge candidates scored from the same pass's sums
// (as in max-affine regression, Magnani & Boyd 2009): a hinge on each input at each of
// kSplitBins - 1 positions across the piece's samples, on either side, as MAX(piece,
// piece + tilt) where the residuals rise beyond the hinge or MIN where they fall. Stops at
// epsilon, at the piece cap or at the iteration cap (and above epsilon may start afresh with
// another seed, TrainerConfig::restarts); the model is always one that was
// evaluated, with every piece inside its bounds. Models are compared by the robust loss at a fixed
// scale (TrainerStats::robust_loss), not by the robust-weighted squared error, which a Tukey fit
// could lower by pushing its samples out of the weights' window: a refit is kept only if it
// lowers that loss, a round's splits are undone unless they lower it, so the model returned
// has the least loss of all models training evaluated.
// Resumable: run_unit(budget) visits at most about `budget` samples and returns; the sequence of
// operations does not depend on the budgets, so sliced training equals one-shot training.
// All working memory is inside the object (no per-sample memory, so the sample count is
// unbounded): make it static. For N = 3 about 1.3 KB per piece (330 KB for 256) with
// SplitBins = 0, which keeps no hinge sums and splits every piece by the V whatever the
// configuration says; about 9 KB per piece (2.4 MB for 256) with the default 16, most of it
// four copies of the hinge candidates' sums.
template <typename Scalar, int N, std::size_t MaxPieces, std::size_t SplitBins = 16>
class Trainer {
 public:
  static_assert(SplitBins == 0 || SplitBins >= 2, "a hinge needs at least one inner bin edge");
  // Hinge positions per input a split chooses from: the edges between kSplitBins equal bins
  // over the range the piece's samples spanned in the pass before.
  static constexpr std::size_t kSplitBins = SplitBins;

  using Model = Aln<Scalar, N, MaxPieces>;
  using PieceType = Piece<Scalar, N>;
  using Vec = Eigen::Matrix<Scalar, N, 1>;
  using VecD = Eigen::Matrix<double, N, 1>;
  using MatD = Eigen::Matrix<double, N, N>;

  Trainer() = default;
  Trainer(const Trainer&) = delete;
  Trainer& operator=(const Trainer&) = delete;

  void configure(const TrainerConfig& config) { config_ = config; }
  [[nodiscard]] const TrainerConfig& config() const { return config_; }

  // Resets `model` to one piece (keeping its ranges and weight bounds) and prepares to train
  // it on `samples`, which must stay valid and unchanged until done. False if empty.
  bool start(SampleSet<Scalar, N> samples, Model& model) {
    if (!begin(samples, model)) return false;
    reset_to_one_piece();
    return begin_first_pass();
  }

  // A warm start: trains `model` as it is (its tree and pieces, e.g. the last fit of a
  // nearby pose) on `samples` instead of from one piece. Weights outside their bounds are
  // clamped into them first; the first round refits every piece from the samples, prunes
  // those no sample uses and splits on. False if empty or if the model has more pieces than
  // the cap (then it is left as it was).
  bool start_from(SampleSet<Scalar, N> samples, Model& model) {
    if (model.piece_count() > piece_cap()) {
      model_ = nullptr;
      stats_ = TrainerStats{};
      stats_.done = true;
      return false;
    }
    if (!begin(samples, model)) return false;
    for (std::size_t p = 0; p < model.piece_count(); ++p) {
      PieceType& piece = model.piece(p);
      VecD w = piece.weight.template cast<double>();
      for (int i = 0; i < N; ++i) w(i) = std::clamp(w(i), lo(i), hi(i));
      piece.set(w.template cast<Scalar>(), piece.centroid, piece.centroid_output);
    }
    return begin_first_pass();
  }
  // Advances by about max_sample_visits samples (at least one). True when training is done.
  bool run_unit(std::size_t max_sample_visits) {
    if (stats_.done || model_ == nullptr) return true;
    std::size_t budget = std::max<std::size_t>(max_sample_visits, 1);
    while (budget > 0 && !stats_.done) {
      const std::size_t count = visit_count();
      const std::size_t end = std::min(count, cursor_ + budget);
      visit_range(cursor_, end);
      budget -= end - cursor_;
      stats_.sample_visits += end - cursor_;
      cursor_ = end;
      if (cursor_ == count) finish_pass();
    }
    return stats_.done;
  }

  // One-shot training: start() and run_unit() to completion.
  bool train(SampleSet<Scalar, N> samples, Model& model) {
    if (!start(samples, model)) return false;
    while (!run_unit(std::numeric_limits<std::size_t>::max() / 2)) {
    }
    return true;
  }

  [[nodiscard]] bool done() const { return stats_.done; }
  [[nodiscard]] const TrainerStats& stats() const { return stats_; }

 private:
  // The piece cap of the configuration: max_pieces, or the model's capacity.
  std::size_t piece_cap() const {
    return config_.max_pieces == 0 ? MaxPieces : std::min(config_.max_pieces, MaxPieces);
  }

  // The samples a pass visits: every stride_-th (the coarse phase) or all.
  std::size_t visit_count() const { return (samples_.size() + stride_ - 1) / stride_; }

  // What start() and start_from() share: the samples, the model, the stats and the cap.
  bool begin(SampleSet<Scalar, N> samples, Model& model) {
    samples_ = samples;
    model_ = &model;
    stride_ = first_stride();
    refining_ = false;
    stats_ = TrainerStats{};
    start_index_ = 0;
    have_best_start_ = false;
    rng_ = seed_state(config_.seed);
    cap_ = piece_cap();
    if (samples.empty()) {
      stats_.done = true;
      return false;
    }
    return true;
  }

  // Coarse only where it leaves more samples than a piece needs to be fitted.
  std::size_t first_stride() const {
    return config_.coarse_stride > 1 && samples_.size() / config_.coarse_stride > 64
               ? config_.coarse_stride
               : 1;
  }

  static std::uint32_t seed_state(std::uint32_t seed) { return seed * 2654435761U + 0x9E3779B9U; }

  // The model as one piece (keeping its ranges and weight bounds): zero slopes where the
  // bounds allow, through output 0 at the middle of the input box.
  void reset_to_one_piece() {
    PieceType first{};
    VecD w0 = VecD::Zero();
    Vec centre = Vec::Zero();
    for (int i = 0; i < N; ++i) {
      w0(i) = std::clamp(0.0, lo(i), hi(i));
      const Range<Scalar> r = model_->input_range(i);
      centre(i) = (r.lo + r.hi) / Scalar(2);
    }
    first.set(w0.template cast<Scalar>(), centre, Scalar(0));
    model_->reset(first);
  }

  // Every piece of the model as training's starting point: no residual scale yet, its split
  // bins over the whole input box; then the first pass.
  bool begin_first_pass() {
    for (std::size_t p = 0; p < model_->piece_count(); ++p) {
      scale_[p] = std::numeric_limits<double>::infinity();
      for (int i = 0; i < N; ++i) {
        const Range<Scalar> r = model_->input_range(i);
        span_lo_[p](i) = static_cast<double>(r.lo);
        span_hi_[p](i) = static_cast<double>(r.hi);
      }
    }
    cursor_ = 0;
    pass_in_round_ = 0;
    best_objective_ = 0.0;
    stall_ = 0;
    split_limit_ = 0;
    last_made_ = 0;
    failed_rounds_ = 0;
    check_ = Check::kNone;
    unevaluated_ = false;
    tried_.fill(0);
    begin_pass();
    stats_.pieces = model_->piece_count();
    return true;
  }

  // Per-piece sums over the samples it is responsible for (trainer_sums.h).
  using Accumulator = train_detail::Accumulator<N, SplitBins>;
  using Accumulators = std::array<Accumulator, MaxPieces>;

  double lo(int i) const { return static_cast<double>(model_->weight_lo(i)); }
  double hi(int i) const { return static_cast<double>(model_->weight_hi(i)); }
  double width(int i) const {
    const Range<Scalar> r = model_->input_range(i);
    const double w = static_cast<double>(r.hi) - static_cast<double>(r.lo);
    return w > 0.0 ? w : 1.0;
  }

  std::uint32_t next_random() {
    rng_ ^= rng_ << 13;
    rng_ ^= rng_ >> 17;
    rng_ ^= rng_ << 5;
    return rng_;
  }

  // The fixed residual scale models are compared at (the pieces' own scales only weight
  // their refits).
  double base_scale() const {
    return config_.robust_scale > 0.0 ? config_.robust_scale : config_.epsilon;
  }

  // The robust weight of residual r at scale s, and its loss at base_scale() (robust_loss.h).
  double robust_weight(double r, double s) const {
    return train_detail::robust_weight(config_.robust, r, s);
  }
  double robust_loss(double r) const {
    return train_detail::robust_loss(config_.robust, r, base_scale());
  }

  void begin_pass() {
    Accumulators& acc = *current_;
    if (check_ == Check::kBins) {
      // The model the sums belong to, evaluated again for the split candidates' sums alone,
      // in the bins its own pass placed.
      for (std::size_t p = 0; p < model_->piece_count(); ++p) {
        acc[p].bins = {};
        acc[p].binned = true;
      }
      return;
    }
    // A check pass's sums go on to the round's splits as they are (finish_check()).
    gather_bins_ = hinges() && (check_ == Check::kPruned || check_ == Check::kReverted);
    for (std::size_t p = 0; p < model_->piece_count(); ++p) {
      acc[p] = Accumulator{};
      acc[p].binned = gather_bins_;
      for (int j = 0; j < N; ++j) {
        const double lo_j = span_lo_[p](j);
        const double span = span_hi_[p](j) - lo_j;
        acc[p].bin_lo(j) = lo_j;
        acc[p].bin_step(j) = kSplitBins > 0 && span > 0.0 && std::isfinite(span)
                                 ? span / static_cast<double>(kSplitBins)
                                 : 1.0;
        acc[p].bin_scale(j) = 1.0 / acc[p].bin_step(j);
      }
    }
  }

  // Visits [begin, end) of the pass (sample k·stride_ for visit k): the model evaluated a
  // block of samples at a time (trainer_pass.h), then each sample added to its responsible
  // piece's sums.
  void visit_range(std::size_t begin, std::size_t end) {
    if (check_ == Check::kBins) {
      train_detail::visit_in_blocks(
          *model_, samples_, stride_, begin, end,
          [this](const Sample<Scalar, N>& s, Scalar value, std::uint16_t responsible) {
            visit_bins(s, value, responsible);
          });
      return;
    }
    train_detail::visit_in_blocks(
        *model_, samples_, stride_, begin, end,
        [this](const Sample<Scalar, N>& s, Scalar value, std::uint16_t responsible) {
          visit(s, value, responsible);
        });
  }

  // One sample, the model's value at it and its responsible piece.
  void visit(const Sample<Scalar, N>& s, Scalar value, std::uint16_t responsible) {
    const PieceType& piece = model_->piece(responsible);
    Accumulator& a = (*current_)[responsible];
    const double r = static_cast<double>(s.y) - static_cast<double>(value);
    const double w_plain = static_cast<double>(s.weight);
    const double w = w_plain * robust_weight(r, scale_[responsible]);
    const VecD x = (s.x - piece.centroid).template cast<double>();
    const double y = static_cast<double>(s.y) - static_cast<double>(piece.centroid_output);
    a.count += 1;
    a.sw_plain += w_plain;
    a.sse_plain += w_plain * r * r;
    a.sw += w;
    a.sx += w * x;
    a.sy += w * y;
    a.sxx.noalias() += (w * x) * x.transpose();
    a.sxy += (w * y) * x;
    a.sse += w * r * r;
    a.loss += config_.robust == RobustWeighting::kNone ? w * r * r : w_plain * robust_loss(r);
    a.sr += w * r;
    if (!hinges()) {
      for (int j = 0; j < N; ++j) {
        const double d = std::fabs(x(j)) / width(j);
        a.sa(j) += w * d;
        a.saa(j) += w * d * d;
        a.sra(j) += w * r * d;
      }
      return;
    }
    if constexpr (kSplitBins > 0) {
      train_detail::keep_span(s, a);
      if (gather_bins_) train_detail::add_to_bins(s, w, r, a);
    }
  }

  // One sample of a bins-only pass (Check::kBins): its residual and weight as visit() has
  // them, added to its piece's hinge sums only.
  void visit_bins(const Sample<Scalar, N>& s, Scalar value, std::uint16_t responsible) {
    if constexpr (kSplitBins > 0) {
      const double r = static_cast<double>(s.y) - static_cast<double>(value);
      const double w = static_cast<double>(s.weight) * robust_weight(r, scale_[responsible]);
      train_detail::add_to_bins(s, w, r, (*current_)[responsible]);
    }
  }

  // Hinge splits only where the trainer keeps their sums (SplitBins > 0).
  [[nodiscard]] bool hinges() const {
    return kSplitBins > 0 && config_.split == SplitCandidates::kHinges;
  }

  // The span of each piece's samples in the pass whose sums `acc` holds: where the next
  // pass puts its split candidates' bins.
  void keep_spans(const Accumulators& acc) {
    for (std::size_t p = 0; p < model_->piece_count(); ++p) {
      if (acc[p].count == 0) continue;
      span_lo_[p] = acc[p].seen_lo;
      span_hi_[p] = acc[p].seen_hi;
    }
  }

  // Least-squares refit of piece p from its sums, honouring the weight bounds exactly.
  void refit(std::size_t p, const Accumulator& a, double step = 1.0) {
    if (a.sw <= 0.0 || a.count == 0) return;
    PieceType& piece = model_->piece(p);
    const VecD xbar = a.sx / a.sw;
    const double ybar = a.sy / a.sw;
    MatD c = a.sxx / a.sw - xbar * xbar.transpose();
    VecD g = a.sxy / a.sw - xbar * ybar;
    // A tiny ridge towards the current slopes keeps directions without data where they were.
    const VecD w_now = piece.weight.template cast<double>();
    std::array<double, static_cast<std::size_t>(N)> lo_b{};
    std::array<double, static_cast<std::size_t>(N)> hi_b{};
    for (int i = 0; i < N; ++i) {
      const double ridge = 1e-9 * std::max(c(i, i), 0.0) + 1e-12 * width(i) * width(i);
      c(i, i) += ridge;
      g(i) += ridge * w_now(i);
      lo_b[static_cast<std::size_t>(i)] = lo(i);
      hi_b[static_cast<std::size_t>(i)] = hi(i);
    }
    VecD w = w_now;
    if (!solve_box_constrained_lsq<N>(c, g, lo_b, hi_b, w)) return;
    const Vec centroid = piece.centroid + xbar.template cast<Scalar>();
    Scalar cy = piece.centroid_output + static_cast<Scalar>(ybar);
    if (step < 1.0) {
      // Part of the way from the piece as it is to its least-squares fit, both taken at the
      // refitted centroid (a convex combination: the weights stay within their bounds).
      const double old_at = static_cast<double>(piece.centroid_output) + w_now.dot(xbar);
      w = (1.0 - step) * w_now + step * w;
      cy = static_cast<Scalar>((1.0 - step) * old_at + step * static_cast<double>(cy));
    }
    piece.set(w.template cast<Scalar>(), centroid, cy);
  }

  double loss_of(const Accumulators& acc) const {
    double loss = 0.0;
    for (std::size_t p = 0; p < model_->piece_count(); ++p) loss += acc[p].loss;
    return loss;
  }

  double sse_of(const Accumulators& acc) const {
    double sse = 0.0;
    for (std::size_t p = 0; p < model_->piece_count(); ++p) sse += acc[p].sse;
    return sse;
  }

  // After a pass over the samples: keep the best model of this round (by the robust loss),
  // then either refit (one Lloyd step) or, when the loss has stopped falling, end the round.
  void finish_pass() {
    stats_.passes += 1;
    stats_.coarse_passes += stride_ > 1 ? 1 : 0;
    if (check_ != Check::kNone) {
      finish_check();
      return;
    }
    const std::size_t pieces = model_->piece_count();
    const double objective = loss_of(*current_);
    const bool improved = pass_in_round_ == 0 || objective < best_objective_ * (1.0 - 1e-4);
    const bool converged = improved && pass_in_round_ > 0 &&
                           objective >= best_objective_ * (1.0 - config_.round_tolerance);
    if (improved) {
      best_objective_ = objective;
      for (std::size_t p = 0; p < pieces; ++p) {
        best_pieces_[p] = model_->piece(p);
        best_scale_[p] = scale_[p];
      }
      std::swap(current_, best_);  // *best_ now holds the sums of the best model
      stall_ = 0;
    } else {
      ++stall_;
    }
    if (config_.damped_refit) {
      step_ = improved ? 1.0 : 0.5 * step_;
      if (!improved) {
        for (std::size_t p = 0; p < pieces; ++p) {
          model_->piece(p) = best_pieces_[p];
          scale_[p] = best_scale_[p];
        }
      }
    }
    const Accumulators& evaluated = improved || config_.damped_refit ? *best_ : *current_;
    const std::size_t pass_cap = refining_ && config_.max_fine_passes > 0
                                     ? config_.max_fine_passes - 1
                                     : config_.max_refit_passes;
    const std::size_t stall_cap = config_.damped_refit ? 3 : 2;
    if (stall_ >= stall_cap || pass_in_round_ >= pass_cap || converged) {
      for (std::size_t p = 0; p < pieces; ++p) {
        model_->piece(p) = best_pieces_[p];
        scale_[p] = best_scale_[p];
      }
      std::swap(current_, best_);  // the best model's sums become the current ones
      finish_round();
      return;
    }
    update_scales(evaluated);
    keep_spans(evaluated);
    for (std::size_t p = 0; p < pieces; ++p) refit(p, evaluated[p], step_);
    pass_in_round_ += 1;
    next_pass();
  }

  void next_pass() {
    cursor_ = 0;
    begin_pass();
  }

  void update_scales(const Accumulators& acc) {
    const double base = base_scale();
    for (std::size_t p = 0; p < model_->piece_count(); ++p) {
      const double rms = acc[p].sw > 0.0 ? std::sqrt(acc[p].sse / acc[p].sw) : 0.0;
      scale_[p] = std::max(base, rms);
    }
  }

  // The current model and the sums in *current_ belong together: undo the round's splits
  // or prune, then split or stop. Every round's model is judged against the one before it by
  // the robust loss, so that loss never rises from one round to the next (pruning included:
  // finish_check()).
  void finish_round() {
    double objective = loss_of(*current_);
    double sse = sse_of(*current_);  // for the overall-RMS split rule
    if (split_limit_ > 0 && objective >= saved_objective_ * (1.0 - 1e-4)) {
      // The last round's splits did not lower the loss: undo them, so the loss never rises
      // from one round to the next, and split half as many of the worst pieces; once a single
      // split fails, that piece is left and the next worst tried. Training ends when every
      // candidate has been tried on this model or after max_failed_rounds such rounds.
      *model_ = saved_model_;
      std::copy_n(saved_acc_.begin(), model_->piece_count(), current_->begin());  // with bins
      scale_ = saved_scale_;
      objective = saved_objective_;
      sse = saved_sse_;
      if (last_made_ > 1) {
        split_limit_ = last_made_ / 2;  // fewer of the worst pieces
      } else {
        // One piece's split did not help either: leave it and try the next worst.
        for (std::size_t i = 0; i < last_split_count_; ++i) tried_[last_split_[i]] = 1;
        split_limit_ = 1;
      }
      stats_.failed_rounds = ++failed_rounds_;
      if (!config_.count_undone_rounds) stats_.iterations -= 1;
      if (failed_rounds_ > config_.max_failed_rounds) {
        finish_stats(*current_);
        end_training();
        return;
      }
      continue_round(objective, sse);
      return;
    }
    split_limit_ = MaxPieces;
    tried_.fill(0);  // another model now: every piece is a candidate again
    if (needs_bins_before_pruning(*current_, sse)) {
      gather_bins(AfterBins::kKeepRound, objective, sse);
      return;
    }
    keep_round(objective, sse);
  }

  // The round's splits stand (or it had none): prune, then split or stop.
  void keep_round(double objective, double sse) {
    const std::size_t evaluated_pieces = model_->piece_count();
    // What undoing the pruning needs: all of it when prunings are checked, the model alone
    // for the robust check at the end (end_training()), nothing otherwise.
    if (config_.check_pruning || config_.robust != RobustWeighting::kNone) {
      unpruned_model_ = *model_;
      unpruned_loss_ = objective;
    }
    if (config_.check_pruning) {
      unpruned_scale_ = scale_;
      unpruned_span_lo_ = span_lo_;
      unpruned_span_hi_ = span_hi_;
    }
    prune(*current_);
    const bool pruned = model_->piece_count() != evaluated_pieces;
    if (pruned && config_.check_pruning) {
      // Pruning a piece no sample uses can still change the model at samples: the piece may
      // win an inner node there whose branch then loses higher up (in the coarse phase, the
      // samples between the visited ones may also be its own). A pass over the samples
      // judges the pruned model; finish_check() keeps the pieces if pruning raised the loss.
      check_ = Check::kPruned;
      next_pass();
      return;
    }
    unevaluated_ = pruned;  // judged only if training ends on it (end_training())
    continue_round(objective, sse);
  }

  // Whether the round that ends may be followed by splits (else training ends).
  bool may_split() const {
    return !refining_ && stats_.iterations < config_.max_iterations && model_->piece_count() < cap_;
  }

  // Whether the round that ends will split its model by hinges from the sums `acc` (robust-
  // weighted squared error `sse`) while they lack the hinge sums, and its pruning is not
  // followed by a check pass, which gathers them (pruning changes the model: a pass on the
  // pruned model would not see the samples as the round's sums did).
  bool needs_bins_before_pruning(const Accumulators& acc, double sse) {
    if (!hinges() || acc[0].binned || !may_split()) return false;
    if (config_.check_pruning) {
      for (std::size_t p = 0; p < model_->piece_count(); ++p) {
        if (acc[p].count == 0) return false;  // pruned and checked
      }
    }
    finish_stats(acc);  // the split rule's overall RMS
    std::array<std::uint8_t, MaxPieces> want{};
    return pieces_to_split(acc, sse, want) > 0;
  }

  // The hinge sums (add_to_bins) cost two thirds of a visit, and only the sums of the model a
  // round ends on are split from, which is not known before the next pass: so the passes
  // leave them out, and one more pass gathers them for that model (Check::kBins), the same
  // sums its own pass would have given. Then `then` goes on with `objective` and `sse`.
  enum class AfterBins : std::uint8_t { kKeepRound, kSplitRound };
  void gather_bins(AfterBins then, double objective, double sse) {
    after_bins_ = then;
    bins_objective_ = objective;
    bins_sse_ = sse;
    check_ = Check::kBins;
    stats_.bin_passes += 1;
    next_pass();
  }

  // The end of a round whose model and sums (*current_) belong together and whose loss and
  // robust-weighted squared error are `objective` and `sse`: the stats, then splits, or the
  // end of training.
  void continue_round(double objective, double sse) {
    finish_stats(*current_);
    if (!may_split()) {
      end_training();
      return;
    }
    split_round(objective, sse);
  }

  // After a pass over a pruned model (Check::kPruned): if pruning raised the loss, the
  // pieces are put back and the model evaluated once more (Check::kReverted); else the round
  // goes on with the pruned model and its own sums.
  void finish_check() {
    const Check what = check_;
    check_ = Check::kNone;
    if (what == Check::kBins) {
      if (after_bins_ == AfterBins::kKeepRound) {
        keep_round(bins_objective_, bins_sse_);
      } else {
        split_round(bins_objective_, bins_sse_);
      }
      return;
    }
    const double loss = loss_of(*current_);
    if (what == Check::kAtEnd) {
      if (loss > unpruned_loss_ * (1.0 + 1e-9)) {
        // The stats, from the round's sums, are those of the model before its pruning.
        *model_ = unpruned_model_;
        stats_.pieces = model_->piece_count();
        stats_.pruning_undone += 1;
      } else {
        finish_stats(*current_);
      }
      finish_start();
      return;
    }
    if (what == Check::kPruned && loss > unpruned_loss_ * (1.0 + 1e-9)) {
      *model_ = unpruned_model_;
      scale_ = unpruned_scale_;
      span_lo_ = unpruned_span_lo_;
      span_hi_ = unpruned_span_hi_;
      stats_.pruning_undone += 1;
      check_ = Check::kReverted;
      next_pass();
      return;
    }
    continue_round(loss, sse_of(*current_));
  }

  // The pieces of the model whose sums are `acc` that the split rule wants split (want[p] =
  // 1), pieces already tried excepted; `sse` is the model's robust-weighted squared error.
  std::size_t pieces_to_split(const Accumulators& acc, double sse,
                              std::array<std::uint8_t, MaxPieces>& want) const {
    const std::size_t pieces = model_->piece_count();
    std::size_t wanted = 0;
    const double eps2 = config_.epsilon * config_.epsilon;
    const auto enough = [&](const Accumulator& a) {
      return a.count > static_cast<std::size_t>(N) + 1 && a.sw > 0.0;
    };
    if (config_.split_rule == SplitRule::kPieceRms) {
      for (std::size_t p = 0; p < pieces; ++p) {
        if (tried_[p] == 0 && enough(acc[p]) && acc[p].sse > eps2 * acc[p].sw) {
          want[p] = 1;
          ++wanted;
        }
      }
    } else if (stats_.robust_rms > config_.epsilon) {
      const double mean_sse = sse / static_cast<double>(pieces);
      for (std::size_t p = 0; p < pieces; ++p) {
        if (tried_[p] == 0 && enough(acc[p]) && acc[p].sse >= mean_sse) {
          want[p] = 1;
          ++wanted;
        }
      }
    }
    return wanted;
  }

  // Splits the worst of the wanted pieces (up to split_limit_) of the model whose sums
  // *current_ holds, after saving it to undo them; `objective` and `sse` are its loss and
  // robust-weighted squared error.
  void split_round(double objective, double sse) {
    Accumulators& acc = *current_;
    const std::size_t pieces = model_->piece_count();
    std::array<std::uint8_t, MaxPieces> want{};
    if (pieces_to_split(acc, sse, want) == 0) {
      end_training();
      return;
    }
    if (hinges() && !acc[0].binned) {
      // Only where the pruning left the model as it was (needs_bins_before_pruning()).
      gather_bins(AfterBins::kSplitRound, objective, sse);
      return;
    }
    update_scales(acc);
    saved_model_ = *model_;
    std::copy_n(acc.begin(), pieces, saved_acc_.begin());
    saved_scale_ = scale_;
    saved_objective_ = objective;
    saved_sse_ = sse;
    // Split the worst first until the cap or the limit.
    std::size_t made = 0;
    last_split_count_ = 0;
    while (model_->piece_count() < cap_ && made < split_limit_) {
      std::size_t best = MaxPieces;
      for (std::size_t p = 0; p < pieces; ++p) {
        if (want[p] != 0 && (best == MaxPieces || acc[p].sse > acc[best].sse)) best = p;
      }
      if (best == MaxPieces) break;
      want[best] = 0;
      last_split_[last_split_count_++] = static_cast<std::uint16_t>(best);
      if (split(best, acc[best])) ++made;
    }
    if (made == 0) {
      split_limit_ = 0;
      end_training();
      return;
    }
    last_made_ = made;
    stats_.iterations += 1;
    stats_.rounds += 1;
    stats_.pieces = model_->piece_count();
    pass_in_round_ = 0;
    stall_ = 0;
    next_pass();
  }

  // The coarse phase (if any) hands over to the fine one; else training is done. Without
  // check_pruning, robust training that would end on a pruned model no pass has evaluated
  // evaluates it once more and returns the model before its pruning if pruning raised the
  // loss (robust fits leave sample-less pieces often: a Tukey piece can drift off all its
  // samples); other training returns the pruned model as it is.
  void end_training() {
    if (stride_ > 1) {
      // The coarse phase is over: refit its model on all samples (a round with no splits).
      stride_ = 1;
      refining_ = true;
      (void)begin_first_pass();
      return;
    }
    if (unevaluated_ && config_.robust != RobustWeighting::kNone) {
      check_ = Check::kAtEnd;
      next_pass();
      return;
    }
    finish_start();
  }

  // This start's training is over (its model and stats final): it is kept if it is the best
  // start so far (the least loss), and training starts afresh from one piece with the next
  // seed if this start ended above epsilon and restarts are left; else the best start's
  // model and stats are returned, with the passes and visits of all the starts.
  void finish_start() {
    if (config_.restarts == 0) {
      stats_.done = true;
      return;
    }
    if (!have_best_start_ || stats_.robust_loss < best_start_stats_.robust_loss) {
      best_start_model_ = *model_;
      best_start_stats_ = stats_;
      have_best_start_ = true;
    }
    const TrainerStats effort = stats_;
    if (start_index_ < config_.restarts && stats_.robust_rms > config_.epsilon) {
      ++start_index_;
      stats_ = TrainerStats{};
      keep_effort(effort);
      rng_ = seed_state(config_.seed + static_cast<std::uint32_t>(start_index_));
      stride_ = first_stride();
      refining_ = false;
      reset_to_one_piece();
      (void)begin_first_pass();
      return;
    }
    *model_ = best_start_model_;
    stats_ = best_start_stats_;
    keep_effort(effort);
    stats_.done = true;
  }

  // The counts of all the starts so far (`effort` holds them) in stats_.
  void keep_effort(const TrainerStats& effort) {
    stats_.passes = effort.passes;
    stats_.coarse_passes = effort.coarse_passes;
    stats_.bin_passes = effort.bin_passes;
    stats_.sample_visits = effort.sample_visits;
    stats_.restarts = start_index_;
  }

  void finish_stats(const Accumulators& acc) {
    double sse = 0.0;
    double sw = 0.0;
    double sse_plain = 0.0;
    double sw_plain = 0.0;
    for (std::size_t p = 0; p < model_->piece_count(); ++p) {
      sse += acc[p].sse;
      sw += acc[p].sw;
      sse_plain += acc[p].sse_plain;
      sw_plain += acc[p].sw_plain;
    }
    stats_.rms = sw_plain > 0.0 ? std::sqrt(sse_plain / sw_plain) : 0.0;
    stats_.robust_rms = sw > 0.0 ? std::sqrt(sse / sw) : 0.0;
    stats_.robust_loss = loss_of(acc);
    stats_.pieces = model_->piece_count();
  }

  // A hinge split's candidates and how they are scored (hinge_split.h).
  using SplitChoice = train_detail::SplitChoice;
  static constexpr double kSplitTie = train_detail::kSplitTie;
  static constexpr std::size_t kSplitCandidates = train_detail::kSplitCandidates<N, SplitBins>;

  bool split(std::size_t p, const Accumulator& a) {
    return hinges() ? split_hinge(p, a) : split_v(p, a);
  }

  // Splits piece p by the hinge drawn (seeded) among its best candidates (hinge_split.h).
  bool split_hinge(std::size_t p, const Accumulator& a) {
    if (!(a.sw > 0.0)) return false;
    const PieceType old = model_->piece(p);
    std::array<SplitChoice, kSplitCandidates> candidates{};
    train_detail::split_candidates(*model_, a, old, candidates);
    // The best gain, then a seeded draw among the candidates close to it.
    double top = 0.0;
    for (const SplitChoice& c : candidates) top = std::max(top, c.gain);
    std::size_t near = 0;
    for (const SplitChoice& c : candidates) near += c.axis >= 0 && c.gain >= kSplitTie * top;
    if (near == 0) return false;
    std::size_t pick = next_random() % near;
    SplitChoice best{};
    for (const SplitChoice& c : candidates) {
      if (c.axis < 0 || c.gain < kSplitTie * top) continue;
      if (pick == 0) {
        best = c;
        break;
      }
      --pick;
    }
    if (best.axis < 0) return false;
    const int j = best.axis;
    // A seeded shift of the hinge within a quarter bin either way: the bins' edges are not
    // special, the refits move the hinge to where the data put it, and another seed starts
    // them elsewhere.
    best.t += (static_cast<double>(next_random() >> 8) / 16777216.0 - 0.5) * 0.5 * a.bin_step(j);
    const double slope = best.side * best.g;  // B's extra weight along j
    Vec wb = old.weight;
    wb(j) = std::clamp(static_cast<Scalar>(static_cast<double>(old.weight(j)) + slope),
                       model_->weight_lo(j), model_->weight_hi(j));
    const double at_centroid = static_cast<double>(old.centroid(j)) - best.t;
    PieceType first{};
    PieceType second{};
    first.set(old.weight, old.centroid, old.centroid_output + static_cast<Scalar>(best.c0));
    second.set(wb, old.centroid,
               old.centroid_output + static_cast<Scalar>(best.c0 + slope * at_centroid));
    const NodeKind kind = best.g > 0.0 ? NodeKind::kMax : NodeKind::kMin;
    const std::size_t q = model_->piece_count();
    if (!model_->split_piece(p, kind, first, second)) return false;
    scale_[q] = scale_[p];
    // Both halves start from the parent's span; the next pass narrows them.
    if (a.count > 0) {
      span_lo_[p] = a.seen_lo;
      span_hi_[p] = a.seen_hi;
    }
    span_lo_[q] = span_lo_[p];
    span_hi_[q] = span_hi_[p];
    return true;
  }

  // Splits piece p into kind(A, B): two copies of it tilted up and down along one input,
  // crossing at its centroid, so kind(A, B) = piece + c0 + k |x_j - c_j|. For each input j,
  // k and c0 are the least-squares fit of the residuals r ~ c0 + k |d_j|; the input with the
  // largest reduction cov(r, |d_j|)^2 / var(|d_j|) is used, and MAX if k > 0 (the data rise
  // above the piece towards the rim of its region: convex), MIN if k < 0 (concave).
  bool split_v(std::size_t p, const Accumulator& a) {
    const PieceType old = model_->piece(p);
    const double rbar = a.sr / a.sw;
    int axis = -1;
    double best_gain = -1.0;
    double best_k = 0.0;
    double best_c0 = 0.0;
    for (int j = 0; j < N; ++j) {
      const double mean_a = a.sa(j) / a.sw;
      const double var_a = a.saa(j) / a.sw - mean_a * mean_a;
      const double w = static_cast<double>(old.weight(j));
      const bool room = hi(j) > w || lo(j) < w;
      if (!(var_a > 1e-12) || !room) continue;
      const double cov = a.sra(j) / a.sw - rbar * mean_a;
      const double gain = cov * cov / var_a;
      if (gain > best_gain) {
        best_gain = gain;
        best_k = cov / var_a;
        best_c0 = rbar - best_k * mean_a;
        axis = j;
      }
    }
    if (axis < 0) return false;
    // A little seeded jitter in the tilt keeps the copies from being exactly symmetric.
    const double jitter = 0.9 + 0.2 * static_cast<double>(next_random() >> 8) / 16777216.0;
    double tilt = jitter * std::fabs(best_k) / width(axis);  // output units per input unit
    if (!(tilt > 0.0)) tilt = 1e-6 / width(axis);
    const double w = static_cast<double>(old.weight(axis));
    const double up = std::max(std::min(tilt, hi(axis) - w), 0.0);
    const double down = std::max(std::min(tilt, w - lo(axis)), 0.0);
    if (!(up + down > 0.0)) return false;
    Vec wa = old.weight;
    Vec wb = old.weight;
    wa(axis) =
        std::clamp(static_cast<Scalar>(w + up), model_->weight_lo(axis), model_->weight_hi(axis));
    wb(axis) =
        std::clamp(static_cast<Scalar>(w - down), model_->weight_lo(axis), model_->weight_hi(axis));
    const Scalar cy = old.centroid_output + static_cast<Scalar>(best_c0);
    PieceType first{};
    PieceType second{};
    first.set(wa, old.centroid, cy);
    second.set(wb, old.centroid, cy);
    const NodeKind kind = best_k > 0.0 ? NodeKind::kMax : NodeKind::kMin;
    const std::size_t q = model_->piece_count();
    if (!model_->split_piece(p, kind, first, second)) return false;
    scale_[q] = scale_[p];
    return true;
  }

  // Removes pieces no sample is responsible for (their parent becomes their sibling). The
  // value at every sample is unchanged, so the sums stay valid; they are renumbered.
  void prune(Accumulators& acc) {
    std::array<std::uint8_t, Model::kMaxNodes> alive{};
    std::size_t dead = 0;
    for (const std::uint16_t n : model_->post_order()) {
      const auto& node = model_->node(n);
      if (node.kind == NodeKind::kPiece) {
        alive[n] = acc[node.a].count > 0 ? 1 : 0;
        if (alive[n] == 0) ++dead;
      } else {
        alive[n] = (alive[node.a] != 0 || alive[node.b] != 0) ? 1 : 0;
      }
    }
    if (dead == 0 || alive[0] == 0) return;
    // Copy the live tree top-down into scratch arrays (explicit stack, no recursion).
    struct Job {
      std::uint16_t from;
      std::uint16_t to;
    };
    std::array<Job, Model::kMaxNodes> stack{};
    std::size_t top = 0;
    std::size_t new_nodes = 1;
    std::size_t new_pieces = 0;
    stack[top++] = Job{0, 0};
    while (top > 0) {
      const Job job = stack[--top];
      std::uint16_t from = job.from;
      // Skip inner nodes with one dead child.
      while (model_->node(from).kind != NodeKind::kPiece) {
        const auto& n = model_->node(from);
        if (alive[n.a] != 0 && alive[n.b] != 0) break;
        from = alive[n.a] != 0 ? n.a : n.b;
      }
      const auto& n = model_->node(from);
      if (n.kind == NodeKind::kPiece) {
        tmp_pieces_[new_pieces] = model_->piece(n.a);
        tmp_acc_[new_pieces] = acc[n.a];
        tmp_scale_[new_pieces] = scale_[n.a];
        tmp_span_lo_[new_pieces] = span_lo_[n.a];
        tmp_span_hi_[new_pieces] = span_hi_[n.a];
        tmp_nodes_[job.to] =
            typename Model::Node{NodeKind::kPiece, static_cast<std::uint16_t>(new_pieces), 0};
        ++new_pieces;
      } else {
        const auto left = static_cast<std::uint16_t>(new_nodes);
        const auto right = static_cast<std::uint16_t>(new_nodes + 1);
        new_nodes += 2;
        tmp_nodes_[job.to] = typename Model::Node{n.kind, left, right};
        stack[top++] = Job{n.b, right};
        stack[top++] = Job{n.a, left};
      }
    }
    if (!model_->assign(std::span<const typename Model::Node>(tmp_nodes_.data(), new_nodes),
                        std::span<const PieceType>(tmp_pieces_.data(), new_pieces))) {
      return;
    }
    for (std::size_t p = 0; p < new_pieces; ++p) {
      acc[p] = tmp_acc_[p];
      scale_[p] = tmp_scale_[p];
      span_lo_[p] = tmp_span_lo_[p];
      span_hi_[p] = tmp_span_hi_[p];
    }
  }

  TrainerConfig config_{};
  TrainerStats stats_{};
  SampleSet<Scalar, N> samples_{};
  Model* model_ = nullptr;
  std::size_t cap_ = MaxPieces;
  std::size_t cursor_ = 0;
  std::size_t pass_in_round_ = 0;
  double best_objective_ = 0.0;
  std::size_t stall_ = 0;
  double step_ = 1.0;  // of the refits (TrainerConfig::damped_refit)
  // The model before the last round's splits, to undo them if they did not help.
  Model saved_model_{};
  Accumulators saved_acc_{};
  std::array<double, MaxPieces> saved_scale_{};
  double saved_objective_ = 0.0;  // its robust loss
  double saved_sse_ = 0.0;        // its robust-weighted squared error
  // The last round's model as evaluated, before pruning, with its scales, spans and loss;
  // whether a pass is judging the pruned model or evaluating the unpruned one again.
  // A bins-only pass (gather_bins()) is one more such check.
  enum class Check : std::uint8_t { kNone, kPruned, kReverted, kAtEnd, kBins };
  Model unpruned_model_{};
  std::array<double, MaxPieces> unpruned_scale_{};
  std::array<VecD, MaxPieces> unpruned_span_lo_{};
  std::array<VecD, MaxPieces> unpruned_span_hi_{};
  double unpruned_loss_ = 0.0;
  bool unevaluated_ = false;  // the model was pruned since its last evaluation
  Check check_ = Check::kNone;
  // Whether this pass gathers the hinge sums; after a bins-only pass, what goes on and with
  // the loss and robust-weighted squared error of the model it evaluated.
  bool gather_bins_ = false;
  AfterBins after_bins_ = AfterBins::kKeepRound;
  double bins_objective_ = 0.0;
  double bins_sse_ = 0.0;
  std::size_t stride_ = 1;       // every stride_-th sample per pass (TrainerConfig::coarse_stride)
  bool refining_ = false;        // the fine phase: refits on all samples, no splits
  std::size_t split_limit_ = 0;  // 0: no split to judge yet
  std::size_t last_made_ = 0;
  // Pieces of the current model whose split did not lower the error (not tried again), the
  // pieces the last round split, and the failed rounds so far.
  std::array<std::uint8_t, MaxPieces> tried_{};
  std::array<std::uint16_t, MaxPieces> last_split_{};
  std::size_t last_split_count_ = 0;
  std::size_t failed_rounds_ = 0;
  std::uint32_t rng_ = 1;
  // Restarts: the starts made after the first, and the best start's model and stats so far.
  std::size_t start_index_ = 0;
  bool have_best_start_ = false;
  Model best_start_model_{};
  TrainerStats best_start_stats_{};
  Accumulators acc_a_{};
  Accumulators acc_b_{};
  Accumulators tmp_acc_{};
  Accumulators* current_ = &acc_a_;
  Accumulators* best_ = &acc_b_;
  std::array<PieceType, MaxPieces> best_pieces_{};
  std::array<double, MaxPieces> scale_{};
  std::array<double, MaxPieces> best_scale_{};
  std::array<PieceType, MaxPieces> tmp_pieces_{};
  std::array<typename Model::Node, Model::kMaxNodes> tmp_nodes_{};
  std::array<double, MaxPieces> tmp_scale_{};
  // Per piece, the span of its samples in the last evaluated pass (split candidates' bins).
  std::array<VecD, MaxPieces> span_lo_{};
  std::array<VecD, MaxPieces> span_hi_{};
  std::array<VecD, MaxPieces> tmp_span_lo_{};
  std::array<VecD, MaxPieces> tmp_span_hi_{};
};

}  // namespace boticelli::aln
