// Benchmark suite "vs-octomap": navigation polygon from the ALN occupancy model vs from OctoMap.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <limits>
#include <memory>
#include <numbers>
#include <vector>

#include "algo/aln/aln.h"
#include "algo/aln/samples.h"
#include "algo/aln/trainer.h"
#include "algo/core/fixed_vector.h"
#include "algo/evidence/occupancy_model.h"
#include "algo/evidence/ray_samples.h"
#include "algo/mapping/aln_free_range.h"
#include "algo/mapping/extraction.h"
#include "algo/mapping/feature_guard.h"
#include "algo/mapping/polygon_ops.h"
#include "bench.h"
#include "bench_worlds.h"
#include "synthetic_rooms.h"

#if defined(BOTICELLI_HAVE_OCTOMAP)
#include <octomap/OcTree.h>
#include <octomap/Pointcloud.h>
#endif

namespace boticelli::bench {
namespace {

constexpr const char* kSuite = "vs-octomap";
constexpr std::size_t kMaxPieces = 256;
constexpr std::size_t kBudgetPieces = 40;
constexpr std::size_t kFeatures = 5000;
constexpr std::size_t kMaxRaySamples = 200000;
constexpr double kGridStepM = 0.02;  // ground-truth area integration

using Model = aln::Aln<float, 3, kMaxPieces>;
using Trainer = aln::Trainer<float, 3, kMaxPieces>;
using AlnSample = aln::Sample<float, 3>;

// Large objects live outside the stack.
Model g_model;
Trainer g_trainer;
mapping::AlnFreeRange<float, kMaxPieces> g_free_range;
core::FixedVector<evidence::RaySample, kMaxRaySamples> g_ray_samples;
mapping::LocalMap g_map;
// The readings' range error of the current rows (CameraScan::range_error_b); 0: exact.
double g_range_error_b = 0.0;
mapping::StarPolygon g_scratch;
core::FixedVector<mapping::GuardPoint, mapping::kMaxGuardCandidates> g_candidates;
core::FixedVector<core::Point2, mapping::kMaxGuardPoints> g_guard;

// The robot: PTU 1 m above the floor (the rooms' sensor height), body from 5 cm above the
// floor to the PTU, radius 0.2 m; five slices; the thesis's m_safe = 0.6.
mapping::ExtractionParams extraction_params(const SyntheticRoom& room) {
  mapping::ExtractionParams p;
  p.ptu_height_m = static_cast<float>(room.sensor().z);
  p.lowest_height_m = 0.05F;
  p.robot_height_m = static_cast<float>(room.sensor().z);
  p.height_count = 5;
  p.bounding_radius_m = 3.0F;
  return p;
}

// The two sensor models side by side: "aln", sized from the stereo's measured accuracy with
// the line of sight as evidence of free (evidence::stereo_ray_sample_params), and
// "aln-thesis", the thesis's δr = 0.1 r with the robot centre's sample only (§3.7.3).
struct SensorSetting {
  const char* method;
  evidence::RaySampleParams rays;
};

std::array<SensorSetting, 2> sensor_settings() {
  evidence::RaySampleParams stereo = evidence::stereo_ray_sample_params();
  // δr / r of the stereo-sized model; default kStereoDeltaRFraction.
  const char* dr = std::getenv("BOTICELLI_VS_OCTOMAP_DELTA_R_FRACTION");
  if (dr != nullptr && *dr != '\0') stereo.delta_r_fraction = static_cast<float>(std::atof(dr));
  const char* los = std::getenv("BOTICELLI_VS_OCTOMAP_LINE_OF_SIGHT");  // samples, default 2
  if (los != nullptr && *los != '\0') stereo.line_of_sight_samples = std::strtoul(los, nullptr, 10);
  // Length of its ramp below the plateau, in δr; default RaySampleParams' 2.
  const char* ramp = std::getenv("BOTICELLI_VS_OCTOMAP_RAMP_DELTA_R");
  if (ramp != nullptr && *ramp != '\0')
    stereo.ramp_length_delta_r = static_cast<float>(std::atof(ramp));
  return {{{"aln", stereo}, {"aln-thesis", evidence::RaySampleParams{}}}};
}

void configure_model(Model& model, const SyntheticRoom& room,
                     const evidence::RaySampleParams& rays) {
  configure_room_model(model, room, evidence::alpha_slope_bound_per_rad(rays.delta_r_fraction));
}

// Ray samples (Fig 4.2b), zero pads in featureless directions and seam copies (§4.9.1).
std::vector<AlnSample> build_samples(const SyntheticRoom& room,
                                     const std::vector<evidence::Reading>& readings,
                                     const evidence::RaySampleParams& params) {
  return room_fit_samples(room, readings, params, g_ray_samples);
}

// The fit's settings: the thesis's epsilon and 10 split rounds unless the knobs say otherwise,
// at most 40 pieces, hinge splits, damped refits, coarse to fine on every 8th sample with two
// passes over all of them (TrainerConfig::damped_refit, coarse_stride, max_fine_passes).
aln::TrainerConfig trainer_config() {
  aln::TrainerConfig cfg;
  const char* eps = std::getenv("BOTICELLI_VS_OCTOMAP_EPSILON");  // default: the thesis's 0.15
  cfg.epsilon = eps != nullptr && *eps != '\0' ? std::atof(eps) : 0.15;
  const char* rounds = std::getenv("BOTICELLI_VS_OCTOMAP_ROUNDS");  // split rounds, default 10
  cfg.max_iterations =
      rounds != nullptr && *rounds != '\0' ? std::strtoul(rounds, nullptr, 10) : 10;
  // The model's 2 KB budget: 40 pieces (and their nodes) take about 1.75 KB, which leaves
  // room for a few guard points.
  const char* pieces = std::getenv("BOTICELLI_VS_OCTOMAP_MAX_PIECES");  // default 40
  cfg.max_pieces =
      pieces != nullptr && *pieces != '\0' ? std::strtoul(pieces, nullptr, 10) : kBudgetPieces;
  cfg.split = aln::SplitCandidates::kHinges;
  const char* stride = std::getenv("BOTICELLI_VS_OCTOMAP_COARSE_STRIDE");  // default 8
  cfg.coarse_stride = stride != nullptr && *stride != '\0' ? std::strtoul(stride, nullptr, 10) : 8;
  // Passes over all samples after the coarse phase; 0: until the loss stops falling.
  const char* fine = std::getenv("BOTICELLI_VS_OCTOMAP_FINE_PASSES");  // default 2
  cfg.max_fine_passes = fine != nullptr && *fine != '\0' ? std::strtoul(fine, nullptr, 10) : 2;
  const char* refits = std::getenv("BOTICELLI_VS_OCTOMAP_REFIT_PASSES");  // per round, default 8
  if (refits != nullptr && *refits != '\0')
    cfg.max_refit_passes = std::strtoul(refits, nullptr, 10);
  const char* check = std::getenv("BOTICELLI_VS_OCTOMAP_CHECK_PRUNING");  // 0 turns it off
  cfg.check_pruning = check == nullptr || *check != '0';
  const char* damped = std::getenv("BOTICELLI_VS_OCTOMAP_DAMPED");  // 0 turns it off
  cfg.damped_refit = damped == nullptr || *damped != '0';
  const char* seed = std::getenv("BOTICELLI_VS_OCTOMAP_SEED");
  if (seed != nullptr && *seed != '\0') {
    cfg.seed = static_cast<std::uint32_t>(std::strtoul(seed, nullptr, 10));
  }
  // A round ends once a refit gains less than 1% of the loss: over trainer seeds 1-6 this
  // took 18% less training than refitting until the loss stops falling, at the same mean
  // coverage (docs/benchmarks.md).
  const char* tolerance = std::getenv("BOTICELLI_VS_OCTOMAP_ROUND_TOLERANCE");
  cfg.round_tolerance = tolerance != nullptr && *tolerance != '\0' ? std::atof(tolerance) : 0.01;
  return cfg;
}

// Trains g_model. The trainer returns the model with the least loss of all it evaluated
// (TrainerStats::robust_loss; the squared error here), so nothing is kept on the side.
void train(const std::vector<AlnSample>& samples) {
  g_trainer.configure(trainer_config());
  (void)g_trainer.train(aln::SampleSet<float, 3>(samples.data(), samples.size()), g_model);
}

// Ground truth at a floor point: free at every slice height (inside the room, not in the
// box) — the slices are where the robot's body is.
bool truly_free(const SyntheticRoom& room, const mapping::ExtractionParams& p, double x, double y) {
  for (std::size_t i = 0; i < p.height_count; ++i) {
    const double z = room.sensor().z + static_cast<double>(mapping::slice_height_m(p, i));
    if (room.solid({x, y, z}) || !room.inside_room({x, y, z})) {
      return false;
    }
  }
  return true;
}

struct Quality {
  double safety = 0.0;      // polygon area that is truly free / polygon area
  double coverage = 0.0;    // truly free area in the circle that the polygon holds
  double nav_safety = 0.0;  // navigable area whose robot disc is truly free / its area
  double area_m2 = 0.0;
};

// Area integration on a kGridStepM grid over the bounding circle around the sensor.
Quality quality(const SyntheticRoom& room, const mapping::ExtractionParams& p,
                const mapping::StarPolygon& free, const mapping::StarPolygon& nav) {
  const double cx = room.sensor().x;
  const double cy = room.sensor().y;
  const double bound = static_cast<double>(p.bounding_radius_m);
  const double robot = static_cast<double>(p.robot_radius_m);
  std::size_t in_poly = 0;
  std::size_t in_poly_free = 0;
  std::size_t free_cells = 0;
  std::size_t in_nav = 0;
  std::size_t in_nav_safe = 0;
  for (double y = -bound; y <= bound; y += kGridStepM) {
    for (double x = -bound; x <= bound; x += kGridStepM) {
      if (x * x + y * y > bound * bound) continue;
      const bool is_free = truly_free(room, p, cx + x, cy + y);
      const core::Point2 q{static_cast<float>(x), static_cast<float>(y)};
      const bool inside = free.contains(q);
      free_cells += is_free ? 1 : 0;
      in_poly += inside ? 1 : 0;
      in_poly_free += (inside && is_free) ? 1 : 0;
      if (nav.contains(q)) {
        ++in_nav;
        bool disc_free = is_free;
        for (int k = 0; k < 24 && disc_free; ++k) {
          const double a = 2.0 * std::numbers::pi * k / 24.0;
          disc_free =
              truly_free(room, p, cx + x + robot * std::cos(a), cy + y + robot * std::sin(a));
        }
        in_nav_safe += disc_free ? 1 : 0;
      }
    }
  }
  Quality qy;
  qy.safety = in_poly > 0 ? static_cast<double>(in_poly_free) / static_cast<double>(in_poly) : 1.0;
  qy.coverage =
      free_cells > 0 ? static_cast<double>(in_poly_free) / static_cast<double>(free_cells) : 0.0;
  qy.nav_safety = in_nav > 0 ? static_cast<double>(in_nav_safe) / static_cast<double>(in_nav) : 1.0;
  qy.area_m2 = static_cast<double>(in_poly) * kGridStepM * kGridStepM;
  return qy;
}

// Where our build time goes: the ray samples, the fit and the guard [ms], and the fit's size.
struct BuildParts {
  double samples_ms = 0.0;
  double train_ms = 0.0;
  double guard_ms = 0.0;
  std::size_t samples = 0;
  std::size_t passes = 0;
  std::size_t coarse_passes = 0;       // of them over every coarse_stride-th sample
  std::size_t bin_passes = 0;          // of them for the hinge sums alone
  std::size_t rounds = 0;              // split rounds kept (TrainerStats::iterations)
  std::size_t failed_rounds = 0;       // split rounds undone
  std::size_t pruning_undone = 0;      // prunings undone (they raised the loss)
  double rms = 0.0;                    // the fit's RMS over all samples
  std::size_t guard_corroborated = 0;  // guard points before keep_points_that_cut
};

void emit(const RoomSpec& spec, const char* method, double resolution_m, std::size_t model_bytes,
          double build_ms, double extract_ms, double shrink_ms, const Quality& q,
          std::size_t pieces, std::size_t guard_points, const BuildParts& parts = {}) {
  JsonLine line(kSuite, spec.name);
  line.text("method", method)
      .num("range_error_b", g_range_error_b)
      .num("resolution_m", resolution_m)
      .integer("pieces", static_cast<std::int64_t>(pieces))
      .integer("guard_points", static_cast<std::int64_t>(guard_points))
      .integer("model_bytes", static_cast<std::int64_t>(model_bytes))
      .num("build_ms", build_ms)
      .num("extract_ms", extract_ms)
      .num("shrink_ms", shrink_ms)
      .num("safety", q.safety)
      .num("coverage", q.coverage)
      .num("nav_safety", q.nav_safety);
  if (parts.samples > 0) {
    line.num("samples_ms", parts.samples_ms)
        .num("train_ms", parts.train_ms)
        .num("guard_ms", parts.guard_ms)
        .integer("samples", static_cast<std::int64_t>(parts.samples))
        .integer("passes", static_cast<std::int64_t>(parts.passes))
        .integer("coarse_passes", static_cast<std::int64_t>(parts.coarse_passes))
        .integer("bin_passes", static_cast<std::int64_t>(parts.bin_passes))
        .integer("guard_corroborated", static_cast<std::int64_t>(parts.guard_corroborated))
        .integer("rounds", static_cast<std::int64_t>(parts.rounds))
        .integer("failed_rounds", static_cast<std::int64_t>(parts.failed_rounds))
        .integer("pruning_undone", static_cast<std::int64_t>(parts.pruning_undone))
        .num("rms", parts.rms);
  }
  line.emit();
}

// Thread CPU time [ns]: the host is shared, so wall time would measure the neighbours too.
std::int64_t cpu_ns() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000000LL + ts.tv_nsec;
}

double ms_since(std::int64_t t0) {
  return static_cast<double>(cpu_ns() - t0) * 1e-6;
}

// Median over `reps` runs of fn() [ms]: robust to the odd run a busy host slows down.
template <typename Fn>
double median_ms(int reps, Fn fn) {
  std::array<double, 64> times{};
  const auto n = static_cast<std::size_t>(std::clamp(reps, 1, 64));
  for (std::size_t r = 0; r < n; ++r) {
    const std::int64_t t0 = cpu_ns();
    fn();
    times[r] = ms_since(t0);
  }
  std::sort(times.begin(), times.begin() + static_cast<std::ptrdiff_t>(n));
  return times[n / 2];
}

// The sensor model's own occupancy along a line of sight whose first surface (features with
// evidence m) is d_m away, at distance s_m from the PTU centre: the ray samples of a reading
// there (evidence::append_plausibility_samples), joined linearly in s; the plateau holds on
// beyond the farthest sample.
class SensorProfile {
 public:
  SensorProfile(const evidence::RaySampleParams& rays, double d_m, double m) {
    core::FixedVector<evidence::RaySample, 2 * evidence::kMaxSamplesPerReading> samples;
    evidence::Reading reading;
    reading.r_m = static_cast<float>(d_m);
    reading.m = static_cast<float>(m);
    (void)evidence::append_plausibility_samples(reading, rays, samples);
    for (const evidence::RaySample& q : samples) {
      knots_[count_++] = {static_cast<double>(q.r_m), static_cast<double>(q.occupancy)};
    }
    std::sort(knots_.begin(), knots_.begin() + static_cast<std::ptrdiff_t>(count_));
  }
  [[nodiscard]] double at(double s_m) const {
    if (count_ == 0) return 0.0;
    if (s_m <= knots_[0].first) return knots_[0].second;
    for (std::size_t i = 1; i < count_; ++i) {
      if (s_m <= knots_[i].first) {
        const auto& [s0, y0] = knots_[i - 1];
        const auto& [s1, y1] = knots_[i];
        return s1 > s0 ? y0 + (y1 - y0) * (s_m - s0) / (s1 - s0) : y1;
      }
    }
    return knots_[count_ - 1].second;
  }

 private:
  std::array<std::pair<double, double>, 2 * evidence::kMaxSamplesPerReading> knots_{};
  std::size_t count_ = 0;
};

// The polygon an exact fit of the sensor model would give: the same slices, threshold and
// shrink, with F at each point equal to the sensor model's profile (SensorProfile) along the
// point's line of sight from the PTU centre, and 0 where that line of sight meets no
// featured surface within range (no reading speaks there; counted free, so the figure is
// what no fit of these samples can beat, not what one must reach). Marched in steps of
// kExactStepM.
// The free and navigable polygons from a free range per slice and pan angle
// (rho_m(slice index, angle [rad]) [m]): the slices' polygons intersected, then the exact
// shrink, as extract_local_map does with the ALN's.
template <typename RhoFn>
void polygon_from_slices(const mapping::ExtractionParams& p, mapping::LocalMap& out,
                         mapping::StarPolygon& slice, RhoFn rho_m) {
  for (std::size_t i = 0; i < p.height_count; ++i) {
    mapping::StarPolygon& target = i == 0 ? out.free : slice;
    target.set_vertex_count(p.vertex_count);
    for (std::size_t k = 0; k < target.vertex_count(); ++k) {
      target.set_rho_m(k, rho_m(i, target.angle_rad(k)));
    }
    if (i > 0) {
      (void)mapping::intersect_into(out.free, slice);
    }
  }
  out.can_move =
      mapping::shrink_for_robot(out.free, p.robot_radius_m, p.clearance_margin_m, out.navigable);
}

void exact_fit_polygon(const SyntheticRoom& room, const mapping::ExtractionParams& p,
                       const evidence::RaySampleParams& rays, mapping::LocalMap& out,
                       mapping::StarPolygon& slice) {
  constexpr double kExactStepM = 0.005;
  const double m = room.spec().feature_m;
  const double threshold = static_cast<double>(p.safe_occupancy);
  polygon_from_slices(p, out, slice, [&](std::size_t i, float angle_rad) {
    const double z = static_cast<double>(mapping::slice_height_m(p, i));
    const auto a = static_cast<double>(angle_rad);
    double rho = static_cast<double>(p.bounding_radius_m);
    for (double q = kExactStepM; q < rho; q += kExactStepM) {
      const double s = std::sqrt(q * q + z * z);
      const Vec3 dir{q * std::cos(a) / s, q * std::sin(a) / s, z / s};
      const SyntheticRoom::Hit hit = room.cast_from_sensor(dir);
      if (!hit.featured || !(hit.distance_m <= room.spec().max_range_m)) continue;
      if (SensorProfile(rays, hit.distance_m, m).at(s) >= threshold) rho = q;
    }
    return static_cast<float>(rho);
  });
}

#if defined(BOTICELLI_HAVE_OCTOMAP)
// The same slices, threshold and shrink, with the free range found by OctoMap's own ray
// casting through the octree (unknown cells count as free: their prior 0.5 < m_safe).
void octomap_polygon(const octomap::OcTree& tree, const SyntheticRoom& room,
                     const mapping::ExtractionParams& p, mapping::LocalMap& out,
                     mapping::StarPolygon& slice) {
  const double max_range = static_cast<double>(p.bounding_radius_m);
  polygon_from_slices(p, out, slice, [&](std::size_t i, float a) {
    const double z = room.sensor().z + static_cast<double>(mapping::slice_height_m(p, i));
    const octomap::point3d origin(static_cast<float>(room.sensor().x),
                                  static_cast<float>(room.sensor().y), static_cast<float>(z));
    const octomap::point3d dir(std::cos(a), std::sin(a), 0.0F);
    octomap::point3d end;
    float rho = p.bounding_radius_m;
    if (tree.castRay(origin, dir, end, true, max_range)) {
      rho = std::min(rho, static_cast<float>((end - origin).norm()));
      // The hit is a cell centre; its near face is half a cell closer.
      rho = std::max(0.0F, rho - static_cast<float>(tree.getResolution()) * 0.5F);
    }
    return rho;
  });
}
#endif

Model g_refit;  // the refit's models
Model g_warm;

// A refit of the same place (the robot's next look from where it stands): other readings of
// the room (another seed), fitted from one piece and from the first fit (Trainer::start_from).
// One line per room: the fit's CPU ms, passes, pieces and RMS, cold and warm.
void refit(const RoomSpec& spec, const SyntheticRoom& room, const evidence::RaySampleParams& rays) {
  const std::vector<evidence::Reading> readings =
      room.generate_camera_readings(CameraScan{}, kFeatures, 8U);
  const std::vector<AlnSample> samples = build_samples(room, readings, rays);
  const aln::SampleSet<float, 3> set(samples.data(), samples.size());
  g_trainer.configure(trainer_config());
  configure_model(g_refit, room, rays);
  std::int64_t t0 = cpu_ns();
  (void)g_trainer.train(set, g_refit);
  const double cold_ms = ms_since(t0);
  const aln::TrainerStats cold = g_trainer.stats();
  g_warm = g_model;
  t0 = cpu_ns();
  if (g_trainer.start_from(set, g_warm)) {
    while (!g_trainer.run_unit(samples.size())) {
    }
  }
  const double warm_ms = ms_since(t0);
  const aln::TrainerStats& warm = g_trainer.stats();
  JsonLine(kSuite, spec.name)
      .text("method", "aln-refit")
      .num("cold_train_ms", cold_ms)
      .integer("cold_passes", static_cast<std::int64_t>(cold.passes))
      .integer("cold_pieces", static_cast<std::int64_t>(cold.pieces))
      .num("cold_rms", cold.rms)
      .num("warm_train_ms", warm_ms)
      .integer("warm_passes", static_cast<std::int64_t>(warm.passes))
      .integer("warm_pieces", static_cast<std::int64_t>(warm.pieces))
      .num("warm_rms", warm.rms)
      .emit();
}

int run() {
  const char* rooms[] = {"cylinder_centre", "cylinder_offcentre_outliers", "rectangle",
                         "corridor",        "cylinder_box_view1",          "rectangle_box_case1"};
  const int reps = 21;
  // Rooms to run, comma-separated names (default: all six).
  const char* only = std::getenv("BOTICELLI_VS_OCTOMAP_ROOMS");
  for (const char* name : rooms) {
    const RoomSpec* spec = find_environment(name);
    if (spec == nullptr || !listed(only, name)) continue;
    const SyntheticRoom room(*spec);
    const mapping::ExtractionParams p = extraction_params(room);
    for (const double b : {0.0, kStereoRangeErrorB}) {
      g_range_error_b = b;
      // As the camera sees the room: 15 pans × 2 tilts (level and 0.5 rad down), with exact
      // ranges and with the stereo's range error; the same readings for ours and OctoMap.
      CameraScan scan;
      scan.range_error_b = g_range_error_b;
      const std::vector<evidence::Reading> readings =
          room.generate_camera_readings(scan, kFeatures, 7U);
      // The see-through check's pan order of the readings (drop_seen_through's scratch), as
      // a look's fixed buffer would hold it: made before any build is timed.
      std::vector<std::uint32_t> pan_order(readings.size());

      // Ours: ray samples → ALN fit → inversion → slices, intersection, exact shrink; with each
      // sensor model, the refit (warm start) with the first.
      std::int64_t t0 = 0;
      const std::array<SensorSetting, 2> settings = sensor_settings();
      for (const SensorSetting& setting : settings) {
        BuildParts parts;
        t0 = cpu_ns();
        const std::vector<AlnSample> samples = build_samples(room, readings, setting.rays);
        parts.samples_ms = ms_since(t0);
        const std::int64_t t_train = cpu_ns();
        configure_model(g_model, room, setting.rays);
        train(samples);
        parts.train_ms = ms_since(t_train);
        parts.samples = samples.size();
        parts.passes = g_trainer.stats().passes;
        parts.coarse_passes = g_trainer.stats().coarse_passes;
        parts.bin_passes = g_trainer.stats().bin_passes;
        parts.rounds = g_trainer.stats().iterations;
        parts.failed_rounds = g_trainer.stats().failed_rounds;
        parts.pruning_undone = g_trainer.stats().pruning_undone;
        parts.rms = g_trainer.stats().rms;
        const std::int64_t t_guard = cpu_ns();
        // The feature guard: readings the fit calls free, kept where they cluster.
        g_candidates.clear();
        g_guard.clear();
        const auto occupancy = [](float a, float h, float r) {
          return static_cast<float>(g_model(Model::Vec(a, h, r)));
        };
        mapping::FeatureGuardParams guard;
        guard.delta_r_fraction = setting.rays.delta_r_fraction;  // the readings' range error
        // Candidates the camera saw through are dropped (FeatureGuardParams), two readings
        // beyond needed (the mission does not: docs/mapping.md).
        const char* through = std::getenv("BOTICELLI_VS_OCTOMAP_SEE_THROUGH");  // default 2
        guard.see_through_readings =
            through != nullptr && *through != '\0' ? std::strtoul(through, nullptr, 10) : 2;
        (void)mapping::collect_unexplained_features(readings, occupancy, p, guard, g_candidates);
        (void)mapping::drop_seen_through(readings, guard, g_candidates, pan_order);
        (void)mapping::corroborated_points(g_candidates, guard, g_guard);
        // Only the points that can cut the polygon, as the mission's builder keeps them.
        parts.guard_corroborated = g_guard.size();
        g_guard.resize(mapping::keep_points_that_cut(g_guard.span(), p.vertex_count));
        parts.guard_ms = ms_since(t_guard);
        const double build_ms = ms_since(t0);
        const double extract_ms = median_ms(reps, [&] {
          (void)g_free_range.set_model(g_model, p.safe_occupancy);
          mapping::extract_local_map(g_free_range, p, g_map, g_scratch, g_guard);
          do_not_optimize(g_map.navigable.rho_m(0));
        });
        const double shrink_ms = median_ms(reps, [&] {
          (void)mapping::shrink_by_radius(g_map.free, p.robot_radius_m + p.clearance_margin_m,
                                          g_scratch);
          do_not_optimize(g_scratch.rho_m(0));
        });
        const std::size_t bytes = g_model.piece_count() * sizeof(Model::PieceType) +
                                  g_model.node_count() * sizeof(Model::Node) +
                                  g_guard.size() * sizeof(core::Point2);
        emit(*spec, setting.method, 0.0, bytes, build_ms, extract_ms, shrink_ms,
             quality(room, p, g_map.free, g_map.navigable), g_model.piece_count(), g_guard.size(),
             parts);
        if (g_range_error_b > 0.0) continue;
        if (&setting == &settings.front()) refit(*spec, room, setting.rays);
        // What an exact fit of this sensor model would cover (no model, no build time).
        static mapping::LocalMap exact_map;
        exact_fit_polygon(room, p, setting.rays, exact_map, g_scratch);
        char exact_method[32];
        std::snprintf(exact_method, sizeof exact_method, "%s-exact-fit", setting.method);
        emit(*spec, exact_method, 0.0, 0, 0.0, 0.0, 0.0,
             quality(room, p, exact_map.free, exact_map.navigable), 0, 0);
      }

#if defined(BOTICELLI_HAVE_OCTOMAP)
      for (const double res : {0.1, 0.05}) {
        t0 = cpu_ns();
        octomap::OcTree tree(res);
        tree.setOccupancyThres(static_cast<double>(p.safe_occupancy));
        octomap::Pointcloud cloud;
        for (const evidence::Reading& rd : readings) {
          const Vec3 w = room.world_of(rd);
          cloud.push_back(static_cast<float>(w.x), static_cast<float>(w.y),
                          static_cast<float>(w.z));
        }
        const Vec3 s = room.sensor();
        tree.insertPointCloud(cloud,
                              octomap::point3d(static_cast<float>(s.x), static_cast<float>(s.y),
                                               static_cast<float>(s.z)));
        tree.updateInnerOccupancy();
        const double oct_build_ms = ms_since(t0);
        static mapping::LocalMap oct_map;
        static mapping::StarPolygon oct_slice;
        const int oct_reps = 7;
        const double oct_extract_ms =
            median_ms(oct_reps, [&] { octomap_polygon(tree, room, p, oct_map, oct_slice); });
        const double oct_shrink_ms = median_ms(oct_reps, [&] {
          (void)mapping::shrink_by_radius(oct_map.free, p.robot_radius_m + p.clearance_margin_m,
                                          oct_slice);
          do_not_optimize(oct_slice.rho_m(0));
        });
        emit(*spec, "octomap", res, tree.memoryUsage(), oct_build_ms, oct_extract_ms, oct_shrink_ms,
             quality(room, p, oct_map.free, oct_map.navigable), 0, 0);
      }
#endif
    }
  }
  return 0;
}

[[maybe_unused]] const bool g_registered =
    register_suite({kSuite, "navigation polygon: ALN model vs OctoMap (0.1 m, 0.05 m)", &run});

}  // namespace
}  // namespace boticelli::bench
