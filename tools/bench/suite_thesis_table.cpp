// Bench suite "thesis-table": the regression-fusion table of thesis §4.8.2 beside a grid.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <memory>
#include <numbers>
#include <string_view>
#include <vector>

#include "algo/aln/aln.h"
#include "algo/aln/samples.h"
#include "algo/aln/trainer.h"
#include "algo/core/fixed_vector.h"
#include "algo/evidence/occupancy_model.h"
#include "algo/evidence/ray_samples.h"
#include "algo/fusion/evidence_grid.h"
#include "bench.h"
#include "bench_worlds.h"
#include "synthetic_rooms.h"

namespace boticelli::bench {
namespace {

constexpr const char* kSuite = "thesis-table";
constexpr std::size_t kMaxPieces = 512;
constexpr std::size_t kMaxFeatures = 50000;
constexpr float kFreeBelow = 0.6F;       // §5.4 safe occupancy
constexpr double kTestSpacingM = 0.1;    // test points: cell centres of a 0.1 m lattice
constexpr double kThesisEpsilon = 0.15;  // §4.8.2

using Model = aln::Aln<float, 3, kMaxPieces>;
using Trainer = aln::Trainer<float, 3, kMaxPieces>;
using AlnSample = aln::Sample<float, 3>;
using Grid = fusion::EvidenceGrid<64, 64, 24>;  // 6.4 x 6.4 x 2.4 m at 0.1 m

// Big buffers live in static storage (the model ~60 KB, the trainer ~1 MB).
Model g_model;
Model g_snapshot;           // the model before the current pass
Model g_snapshot_previous;  // the model before the previous pass
Model g_best;
Trainer g_trainer;
Grid g_grid;
core::FixedVector<evidence::RaySample, kMaxFeatures * 7> g_ray_samples;

struct Quality {
  double correct = 0.0;     // share of test points classified as ground truth says
  double false_free = 0.0;  // share of test points called free that are not (unsafe)
  double false_occupied = 0.0;
  std::size_t points = 0;
  // The same over the "clear" test points only: those outside the sensor model's own
  // uncertainty band [r_s − 3δr, r_s + δr] (δr = 0.1 r_s) around the first surface r_s on
  // the point's line of sight, where even a perfect fit of the ray samples is in between.
  double correct_clear = 0.0;
  double false_free_clear = 0.0;
  double clear_share = 0.0;
  // Clear points whose line of sight ends on a surface with features within the sensor's
  // range, so the sensor says something about them (the rest lie in directions with
  // nothing to see: over the walls, where there is no ceiling, or towards the bare floor).
  double correct_seen = 0.0;
  double seen_share = 0.0;
};

enum class TestPointKind { kInBand, kClearSeen, kClearUnseen };

// Where p lies relative to the first surface r_s on its line of sight: inside the sensor
// model's band [r_s − 3δr, r_s + δr] (δr = 0.1 r_s), or clear of it, and then whether that
// surface has features within the sensor's range.
TestPointKind test_point_kind(const SyntheticRoom& room, const Vec3& p) {
  const Vec3 s = room.sensor();
  const Vec3 d{p.x - s.x, p.y - s.y, p.z - s.z};
  const double dist = std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
  if (dist < 1e-9) {
    return TestPointKind::kClearSeen;
  }
  const SyntheticRoom::Hit hit = room.cast_from_sensor({d.x / dist, d.y / dist, d.z / dist});
  const bool seen = hit.featured && hit.distance_m <= room.spec().max_range_m;
  if (!std::isfinite(hit.distance_m)) {
    return TestPointKind::kClearUnseen;
  }
  if (dist >= 0.7 * hit.distance_m && dist <= 1.1 * hit.distance_m) {
    return TestPointKind::kInBand;
  }
  return seen ? TestPointKind::kClearSeen : TestPointKind::kClearUnseen;
}

// Classifies every test point of the room's bounding box with `is_free`.
template <typename IsFree>
Quality classify(const SyntheticRoom& room, IsFree&& is_free) {
  const Bounds3 b = room.bounds();
  Quality q;
  std::size_t correct = 0;
  std::size_t false_free = 0;
  std::size_t false_occ = 0;
  std::size_t clear = 0;
  std::size_t clear_correct = 0;
  std::size_t clear_false_free = 0;
  std::size_t seen = 0;
  std::size_t seen_correct = 0;
  const auto steps = [](double lo, double hi) {
    return static_cast<int>(std::floor((hi - lo) / kTestSpacingM + 1e-9));
  };
  const int nx = steps(b.min.x, b.max.x);
  const int ny = steps(b.min.y, b.max.y);
  const int nz = steps(b.min.z, b.max.z);
  for (int iz = 0; iz < nz; ++iz) {
    for (int iy = 0; iy < ny; ++iy) {
      for (int ix = 0; ix < nx; ++ix) {
        const Vec3 p{b.min.x + (ix + 0.5) * kTestSpacingM, b.min.y + (iy + 0.5) * kTestSpacingM,
                     b.min.z + (iz + 0.5) * kTestSpacingM};
        const bool truth = room.visible_free(p);
        const bool said = is_free(p);
        const TestPointKind kind = test_point_kind(room, p);
        if (kind == TestPointKind::kClearSeen) {
          ++seen;
          seen_correct += truth == said ? 1U : 0U;
        }
        if (kind != TestPointKind::kInBand) {
          ++clear;
          clear_correct += truth == said ? 1U : 0U;
          clear_false_free += (said && !truth) ? 1U : 0U;
        }
        if (truth == said) {
          ++correct;
        } else if (said) {
          ++false_free;
        } else {
          ++false_occ;
        }
        ++q.points;
      }
    }
  }
  const double n = static_cast<double>(q.points);
  q.correct = static_cast<double>(correct) / n;
  q.false_free = static_cast<double>(false_free) / n;
  q.false_occupied = static_cast<double>(false_occ) / n;
  const double nc = static_cast<double>(clear > 0 ? clear : 1);
  q.correct_clear = static_cast<double>(clear_correct) / nc;
  q.false_free_clear = static_cast<double>(clear_false_free) / nc;
  q.clear_share = static_cast<double>(clear) / n;
  q.correct_seen = static_cast<double>(seen_correct) / static_cast<double>(seen > 0 ? seen : 1);
  q.seen_share = static_cast<double>(seen) / n;
  return q;
}

std::size_t env_size(const char* name, std::size_t fallback) {
  const char* v = std::getenv(name);
  return v != nullptr && *v != '\0' ? std::strtoul(v, nullptr, 10) : fallback;
}

// RMS of a model over the samples: plain, or (robust runs) over the 95% smallest
// residuals, so that a round is not preferred for fitting the outliers; and the number of
// pieces responsible for at least one sample (the pieces the trainer would keep).
struct Residuals {
  double rms = 0.0;
  std::size_t live_pieces = 0;
};
Residuals model_rms(const Model& model, const std::vector<AlnSample>& samples, bool trimmed) {
  std::vector<double> r2(samples.size());
  std::vector<bool> used(kMaxPieces, false);
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const aln::EvalResult<float> e = model.evaluate_alpha_beta(samples[i].x);
    used[e.piece] = true;
    const double r = static_cast<double>(e.value - samples[i].y);
    r2[i] = r * r;
  }
  Residuals out;
  for (const bool u : used) {
    out.live_pieces += u ? 1U : 0U;
  }
  std::size_t n = r2.size();
  if (trimmed && n > 20) {
    n = n * 95 / 100;
    std::nth_element(r2.begin(), r2.begin() + static_cast<std::ptrdiff_t>(n), r2.end());
  }
  double sum = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    sum += r2[i];
  }
  out.rms = n > 0 ? std::sqrt(sum / static_cast<double>(n)) : 0.0;
  return out;
}

struct BestRound {
  double rms = std::numeric_limits<double>::infinity();
  std::size_t pieces = 0;
  std::size_t iteration = 0;
};

// Trains pass by pass (the trainer's resumable run_unit(), one pass per call) and keeps the
// model with the lowest RMS seen at the end of any split round, in g_best. The trainer
// returns the model of its last round, which under the per-piece rule is not always its
// best one (a round of many simultaneous splits can end worse than the round before).
BestRound train_keeping_best(const std::vector<AlnSample>& samples, bool trimmed) {
  BestRound best;
  const aln::SampleSet<float, 3> set(samples.data(), samples.size());
  if (!g_trainer.start(set, g_model)) {
    return best;
  }
  const auto consider = [&](const Model& m, std::size_t iteration) {
    const Residuals r = model_rms(m, samples, trimmed);
    if (r.rms < best.rms) {
      best = {r.rms, r.live_pieces, iteration};
      g_best = m;
    }
  };
  g_snapshot = g_model;
  while (!g_trainer.done()) {
    g_snapshot_previous = g_snapshot;
    g_snapshot = g_model;
    const std::size_t round = g_trainer.stats().iterations;
    (void)g_trainer.run_unit(samples.size());
    if (g_trainer.stats().iterations != round || g_trainer.done()) {
      // The round ended on the model evaluated in this pass, or (if the last refit made
      // it worse) on the one of the pass before; with hinge splits this pass is the one
      // that gathered the hinge sums, which evaluated the model the round ended on.
      consider(g_snapshot, round);
      consider(g_snapshot_previous, round);
    }
  }
  consider(g_model, g_trainer.stats().iterations);
  return best;
}

struct RunSpec {
  aln::SplitRule rule;
  aln::RobustWeighting robust;
  bool pads;
  const char* rule_name;
  const char* robust_name;
};

// Ray samples: 5 per feature (Fig 4.2b), optionally zero pads in featureless directions
// (§4.9.1), then the seam copies (§4.9.1); converted to the ALN's sample type.
std::vector<AlnSample> build_samples(const SyntheticRoom& room,
                                     const std::vector<evidence::Reading>& readings, bool pads,
                                     std::size_t* pad_count) {
  g_ray_samples.clear();
  const evidence::RaySampleParams params;
  (void)evidence::append_ray_samples(readings, params, g_ray_samples);
  *pad_count = 0;
  if (pads) {
    evidence::PadRegion region;
    region.h_min_m = static_cast<float>(-room.sensor().z);
    region.h_max_m = static_cast<float>(room.spec().wall_height_m - room.sensor().z);
    region.r_min_m = 0.0F;
    region.r_max_m = static_cast<float>(room.spec().max_range_m);
    const evidence::FeaturelessPadParams pad_params;
    evidence::PadRandom random{12345U};
    *pad_count =
        evidence::append_featureless_pads(readings, region, pad_params, random, g_ray_samples);
  }
  (void)evidence::append_seam_copies(g_ray_samples, evidence::kSeamMarginRad);
  return to_fit_samples(
      std::span<const evidence::RaySample>(g_ray_samples.data(), g_ray_samples.size()));
}

int parse_feature_list(std::size_t* out, int max) {
  const char* env = std::getenv("BOTICELLI_THESIS_FEATURES");
  if (env == nullptr || *env == '\0') {
    out[0] = 5000;
    return 1;
  }
  int n = 0;
  const char* p = env;
  while (*p != '\0' && n < max) {
    char* end = nullptr;
    const unsigned long v = std::strtoul(p, &end, 10);
    if (end == p) {
      break;
    }
    out[n++] = std::min<std::size_t>(v, kMaxFeatures);
    p = (*end == ',') ? end + 1 : end;
  }
  return n;
}

double epsilon() {
  const char* v = std::getenv("BOTICELLI_THESIS_EPSILON");
  return v != nullptr && *v != '\0' ? std::strtod(v, nullptr) : kThesisEpsilon;
}

// The bound on |∂F/∂α| [1/rad]: the thesis's 1 (Eq 4.28) unless BOTICELLI_THESIS_ALPHA_SLOPE.
float alpha_slope_bound() {
  const char* v = std::getenv("BOTICELLI_THESIS_ALPHA_SLOPE");
  return v != nullptr && *v != '\0' ? std::strtof(v, nullptr) : evidence::kMaxAlphaSlopePerRad;
}

int run_thesis_table() {
  const double kEpsilon = epsilon();
  const float alpha_slope = alpha_slope_bound();
  std::size_t feature_counts[8];
  const int n_counts = parse_feature_list(feature_counts, 8);
  const char* only = std::getenv("BOTICELLI_THESIS_ROWS");  // comma list of names, optional
  for (const RoomSpec& spec : thesis_environments()) {
    if (!listed(only, spec.name)) {
      continue;
    }
    const SyntheticRoom room(spec);
    for (int fc = 0; fc < n_counts; ++fc) {
      const std::size_t features = feature_counts[fc];
      const std::vector<evidence::Reading> readings = room.generate_readings(features, 2000U);

      // Grid baseline at 0.1 m on the same readings.
      const Bounds3 b = room.bounds();
      g_grid.set_box(
          {{static_cast<float>(b.min.x), static_cast<float>(b.min.y), static_cast<float>(b.min.z)},
           0.1F});
      g_grid.clear();
      const fusion::GridPoint sensor{static_cast<float>(room.sensor().x),
                                     static_cast<float>(room.sensor().y),
                                     static_cast<float>(room.sensor().z)};
      std::size_t grid_updates = 0;
      const std::int64_t g0 = now_ns();
      for (const evidence::Reading& r : readings) {
        grid_updates += g_grid.integrate(sensor, r);
      }
      const std::int64_t g1 = now_ns();
      const Quality grid_q = classify(room, [](const Vec3& p) {
        return g_grid.is_free(
            {static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z)});
      });

      // The thesis's setting first (no pads, plain least squares), then what robust
      // weights change on the outlier rows, then the featureless pads for classification.
      const RunSpec runs[] = {
          {aln::SplitRule::kPieceRms, aln::RobustWeighting::kNone, false, "piece_rms", "none"},
          {aln::SplitRule::kOverallRms, aln::RobustWeighting::kNone, false, "overall_rms", "none"},
          {aln::SplitRule::kPieceRms, aln::RobustWeighting::kTukey, false, "piece_rms", "tukey"},
          {aln::SplitRule::kOverallRms, aln::RobustWeighting::kTukey, false, "overall_rms",
           "tukey"},
          {aln::SplitRule::kPieceRms, aln::RobustWeighting::kNone, true, "piece_rms", "none"},
          {aln::SplitRule::kOverallRms, aln::RobustWeighting::kNone, true, "overall_rms", "none"},
      };
      for (const RunSpec& run : runs) {
        if (run.robust != aln::RobustWeighting::kNone && !(spec.outlier_fraction > 0.0)) {
          continue;
        }
        std::size_t pad_count = 0;
        const std::vector<AlnSample> samples = build_samples(room, readings, run.pads, &pad_count);
        configure_room_model(g_model, room, alpha_slope);
        aln::TrainerConfig cfg;
        cfg.epsilon = kEpsilon;
        cfg.max_iterations = env_size("BOTICELLI_THESIS_ITERATIONS", 10);  // rounds kept
        cfg.count_undone_rounds = false;
        cfg.max_refit_passes = env_size("BOTICELLI_THESIS_PASSES", 8);
        cfg.damped_refit = env_size("BOTICELLI_THESIS_DAMPED", 0) != 0;
        cfg.check_pruning = env_size("BOTICELLI_THESIS_CHECK_PRUNING", 0) != 0;
        cfg.restarts = env_size("BOTICELLI_THESIS_RESTARTS", 2);  // fresh starts above epsilon
        if (const char* t = std::getenv("BOTICELLI_THESIS_ROUND_TOLERANCE");
            t != nullptr && *t != '\0') {
          cfg.round_tolerance = std::atof(t);
        }
        cfg.seed = static_cast<std::uint32_t>(env_size("BOTICELLI_THESIS_SEED", 1));  // the split's
        cfg.max_pieces = kMaxPieces;
        cfg.split_rule = run.rule;
        cfg.robust = run.robust;
        // Hinge splits unless BOTICELLI_THESIS_SPLIT=v (the V at the centroid, as the mission).
        const char* split = std::getenv("BOTICELLI_THESIS_SPLIT");
        cfg.split = split != nullptr && std::string_view(split) == "v"
                        ? aln::SplitCandidates::kCentroidV
                        : aln::SplitCandidates::kHinges;
        g_trainer.configure(cfg);
        const std::int64_t t0 = now_ns();
        const BestRound best =
            train_keeping_best(samples, run.robust != aln::RobustWeighting::kNone);
        const std::int64_t t1 = now_ns();
        const aln::TrainerStats& st = g_trainer.stats();
        const Quality q = classify(room, [&room](const Vec3& p) {
          const evidence::Reading r = room.reading_of(p, 0.0F);
          return g_best(Eigen::Vector3f(r.alpha_rad, r.h_m, r.r_m)) < kFreeBelow;
        });
        JsonLine(kSuite, spec.name)
            .integer("features", static_cast<std::int64_t>(readings.size()))
            .integer("samples", static_cast<std::int64_t>(samples.size()))
            .num("outliers", spec.outlier_fraction)
            .num("epsilon", kEpsilon)
            .text("split_rule", run.rule_name)
            .text("robust", run.robust_name)
            .integer("pads", static_cast<std::int64_t>(pad_count))
            .integer("thesis_pieces", spec.thesis_pieces)
            .integer("pieces", static_cast<std::int64_t>(st.pieces))
            .integer("iterations", static_cast<std::int64_t>(st.iterations))
            .integer("restarts", static_cast<std::int64_t>(st.restarts))
            .num("rms", st.rms)
            .num("robust_rms", st.robust_rms)
            .flag("reached_epsilon", st.robust_rms <= kEpsilon)
            .integer("best_pieces", static_cast<std::int64_t>(best.pieces))
            .integer("best_iteration", static_cast<std::int64_t>(best.iteration))
            .num("best_rms", best.rms)
            .num("fit_s", static_cast<double>(t1 - t0) * 1e-9)
            .integer("test_points", static_cast<std::int64_t>(q.points))
            .num("aln_correct", q.correct)
            .num("aln_false_free", q.false_free)
            .num("aln_correct_clear", q.correct_clear)
            .num("aln_false_free_clear", q.false_free_clear)
            .num("aln_correct_seen", q.correct_seen)
            .num("grid_correct", grid_q.correct)
            .num("grid_false_free", grid_q.false_free)
            .num("grid_correct_clear", grid_q.correct_clear)
            .num("grid_correct_seen", grid_q.correct_seen)
            .num("clear_share", q.clear_share)
            .num("seen_share", q.seen_share)
            .integer("grid_cells", static_cast<std::int64_t>(g_grid.cells()))
            .integer("grid_updates", static_cast<std::int64_t>(grid_updates))
            .num("grid_s", static_cast<double>(g1 - g0) * 1e-9)
            .emit();
        std::fflush(stdout);
      }
    }
  }
  return 0;
}

// The hyphenated command name is not a C identifier, so the suite registers itself.
[[maybe_unused]] const bool g_registered = register_suite(
    {kSuite,
     "regression fusion (ALN) vs a 0.1 m log-odds grid on the thesis's simulated rooms "
     "(4.8.2); env BOTICELLI_THESIS_FEATURES=500,5000 BOTICELLI_THESIS_ROWS=name,... "
     "BOTICELLI_THESIS_EPSILON=0.15 BOTICELLI_THESIS_ITERATIONS=10 "
     "BOTICELLI_THESIS_ALPHA_SLOPE=1 BOTICELLI_THESIS_DAMPED=0 BOTICELLI_THESIS_RESTARTS=2",
     &run_thesis_table});

}  // namespace
}  // namespace boticelli::bench
