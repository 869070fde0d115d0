// Benchmark suite "aln": evaluation cost (plain, alpha-beta, DTREE, fixed point) and training time.
#include <cmath>
#include <cstddef>
#include <cstdint>

#include <time.h>

#include <Eigen/Core>

#include "algo/aln/aln.h"
#include "algo/aln/dtree.h"
#include "algo/aln/fixed_point.h"
#include "algo/aln/samples.h"
#include "algo/aln/trainer.h"
#include "bench.h"

namespace {

namespace aln = boticelli::aln;
using Model = aln::Aln<float, 3, 256>;
using Trainer = aln::Trainer<float, 3, 256>;
using Dtree = aln::Dtree<float, 3, 256>;
using Fixed = aln::FixedPointAln<3, 256>;

constexpr double kPi = 3.14159265358979;
constexpr std::size_t kSamples = 20000;
constexpr std::size_t kQueries = 4096;

aln::Sample<float, 3> g_samples[kSamples];
Model g_model;
Trainer g_trainer;
Dtree g_dtree;
Fixed g_fixed;
Eigen::Vector3f g_queries[kQueries];
Eigen::Vector3f g_rays[kQueries];  // 64 rays of 64 points, r rising along each
Fixed::Input g_queries_q[kQueries];

std::uint64_t g_state = 0x12345678ULL;
double uniform(double lo, double hi) {
  g_state ^= g_state >> 12;
  g_state ^= g_state << 25;
  g_state ^= g_state >> 27;
  const std::uint64_t v = g_state * 0x2545F4914F6CDD1DULL;
  return lo + (hi - lo) * static_cast<double>(v >> 11) / 9007199254740992.0;
}

// A room-like occupancy function in the thesis's quasi-cylindrical coordinates (alpha rad,
// h dm, r dm): a 8 m x 5 m rectangular room seen from off-centre, with a 0.5 m high box,
// occupancy m = MIN((r / d(alpha, h))^2, 1) along each ray (the Eq 5.2 sensor profile).
double room(double alpha, double h, double r) {
  const double c = std::cos(alpha);
  const double s = std::sin(alpha);
  double d = 1e9;
  if (c > 1e-9) d = std::fmin(d, 50.0 / c);
  if (c < -1e-9) d = std::fmin(d, -30.0 / c);
  if (s > 1e-9) d = std::fmin(d, 20.0 / s);
  if (s < -1e-9) d = std::fmin(d, -30.0 / s);
  if (h < 5.0 && alpha > 0.4 && alpha < 0.9) d = std::fmin(d, 15.0);
  const double u = r / d;
  return std::fmin(u * u, 1.0);
}

// Thesis bounds (Eqs 4.27-4.28); `loose` widens the slope bounds on alpha and h so the
// capped models of the evaluation benchmark can keep refining the room's jumps.
void set_ranges(Model& m, bool loose = false) {
  m.set_input_range(0, static_cast<float>(-kPi), static_cast<float>(kPi));
  m.set_input_range(1, 0.0F, 20.0F);
  m.set_input_range(2, 0.0F, 60.0F);
  m.set_output_range(-0.1F, 1.1F);
  const float b = loose ? 20.0F : 1.0F;
  m.set_weight_bounds(0, -b, b);        // Eq 4.28 (per rad)
  m.set_weight_bounds(1, -b, b);        // Eq 4.28 (per dm)
  m.set_weight_bounds(2, 1e-4F, 1.0F);  // Eq 4.27: monotone increasing in r
}

void make_samples() {
  for (auto& s : g_samples) {
    s.x = Eigen::Vector3f(static_cast<float>(uniform(-kPi, kPi)),
                          static_cast<float>(uniform(0.0, 20.0)),
                          static_cast<float>(uniform(0.0, 60.0)));
    s.y = static_cast<float>(room(static_cast<double>(s.x(0)), static_cast<double>(s.x(1)),
                                  static_cast<double>(s.x(2))));
  }
  for (std::size_t ray = 0; ray < kQueries / 64; ++ray) {
    const auto alpha = static_cast<float>(uniform(-kPi, kPi));
    const auto h = static_cast<float>(uniform(0.0, 20.0));
    for (std::size_t k = 0; k < 64; ++k) {
      g_rays[ray * 64 + k] = Eigen::Vector3f(alpha, h, static_cast<float>(k) * (60.0F / 64.0F));
    }
  }
  for (std::size_t k = 0; k < kQueries; ++k) {
    g_queries[k] = Eigen::Vector3f(static_cast<float>(uniform(-kPi, kPi)),
                                   static_cast<float>(uniform(0.0, 20.0)),
                                   static_cast<float>(uniform(0.0, 60.0)));
    for (int i = 0; i < 3; ++i) {
      g_queries_q[k][static_cast<std::size_t>(i)] =
          Fixed::to_fixed(static_cast<double>(g_queries[k](i)));
    }
  }
}

// CPU time of this thread in ns: on a shared, loaded host this is far steadier than wall time
// (it does not count time spent preempted).
std::int64_t cpu_ns() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000000LL + ts.tv_nsec;
}

// ns per query of f(k, sink) over the queries, after a round that warms up and counts what
// f returns (pieces evaluated) into `touched`. f has one call site, in a loop, so it is
// inlined as in a caller's loop and the sum stays in a register.
template <typename F>
double ns_per_call(F&& f, std::size_t& touched) {
  constexpr int kRounds = 100;
  double sink = 0.0;
  std::int64_t t0 = 0;
  for (int r = -1; r < kRounds; ++r) {
    if (r == 0) t0 = cpu_ns();
    std::size_t t = 0;
    for (std::size_t k = 0; k < kQueries; ++k) t += f(k, sink);
    if (r < 0) touched = t;
  }
  const std::int64_t t1 = cpu_ns();
  boticelli::bench::do_not_optimize(sink);
  return static_cast<double>(t1 - t0) / (kRounds * static_cast<double>(kQueries));
}

void bench_model(std::size_t cap) {
  set_ranges(g_model, true);
  aln::TrainerConfig cfg;
  cfg.epsilon = 1e-3;  // never reached: grow to the piece cap
  cfg.max_pieces = cap;
  cfg.max_iterations = 40;
  g_trainer.configure(cfg);
  g_trainer.train(aln::SampleSet<float, 3>(g_samples, kSamples), g_model);
  const std::size_t pieces = g_model.piece_count();
  const std::int64_t c0 = cpu_ns();
  const bool dtree_ok = g_dtree.compile(g_model);
  const double compile_ms = static_cast<double>(cpu_ns() - c0) * 1e-6;
  const bool fixed_ok = g_fixed.compile(g_model);
  std::size_t t_plain = 0;
  std::size_t t_ab = 0;
  std::size_t t_dt = 0;
  std::size_t t_fx = 0;
  const double plain = ns_per_call(
      [](std::size_t k, double& sink) {
        const auto e = g_model.evaluate(g_queries[k]);
        sink += static_cast<double>(e.value);
        return static_cast<std::size_t>(e.pieces_evaluated);
      },
      t_plain);
  const double ab = ns_per_call(
      [](std::size_t k, double& sink) {
        const auto e = g_model.evaluate_alpha_beta(g_queries[k]);
        sink += static_cast<double>(e.value);
        return static_cast<std::size_t>(e.pieces_evaluated);
      },
      t_ab);
  const double dt = ns_per_call(
      [](std::size_t k, double& sink) {
        const auto e = g_dtree.evaluate(g_queries[k]);
        sink += static_cast<double>(e.value);
        return static_cast<std::size_t>(e.pieces_evaluated);
      },
      t_dt);
  const double fx = ns_per_call(
      [](std::size_t k, double& sink) {
        const auto e = g_fixed.evaluate(g_queries_q[k]);
        sink += static_cast<double>(e.value);
        return static_cast<std::size_t>(e.pieces_evaluated);
      },
      t_fx);
  // Coherent queries along rays: plain alpha-beta, and with the previous piece as a hint.
  std::size_t t_ray = 0;
  std::size_t t_hint = 0;
  const double ray_ab = ns_per_call(
      [](std::size_t k, double& sink) {
        const auto e = g_model.evaluate_alpha_beta(g_rays[k]);
        sink += static_cast<double>(e.value);
        return static_cast<std::size_t>(e.pieces_evaluated);
      },
      t_ray);
  static std::uint16_t hint = 0xFFFF;
  const double ray_hint = ns_per_call(
      [](std::size_t k, double& sink) {
        const auto e = g_model.evaluate_alpha_beta(g_rays[k], k % 64 == 0 ? 0xFFFF : hint);
        hint = e.piece;
        sink += static_cast<double>(e.value);
        return static_cast<std::size_t>(e.pieces_evaluated);
      },
      t_hint);
  // Block evaluation (Aln::evaluate_block), kBlock queries per call: random queries and rays;
  // ns per query.
  const auto block_ns = [](const auto& queries) {
    static constexpr std::size_t kB = Model::kBlock;
    std::size_t unused = 0;
    return ns_per_call(
        [&queries](std::size_t k, double& sink) {
          if (k % kB != 0) return std::size_t{0};
          std::array<float, kB> v{};
          std::array<std::uint16_t, kB> p{};
          const std::size_t n = std::min(kB, kQueries - k);
          g_model.evaluate_block(std::span<const Model::Vec>(&queries[k], n), v, p);
          sink += static_cast<double>(v[0]);
          return std::size_t{0};
        },
        unused);
  };
  const double block = block_ns(g_queries);
  const double ray_block = block_ns(g_rays);
  const auto blocks = static_cast<std::int64_t>(g_dtree.block_count());
  const auto dtree_depth = static_cast<std::int64_t>(g_dtree.depth_used());
  const auto dtree_ops = static_cast<std::int64_t>(g_dtree.node_count());
  // DTREE with up to N + 1 = 4 pieces per block (the thesis's) and up to 8: fewer thresholds
  // per query, more pieces.
  const auto dtree_with = [](std::size_t block_pieces, bool& ok, std::size_t& touched) {
    ok = g_dtree.compile(g_model, 10, block_pieces);
    return ns_per_call(
        [](std::size_t k, double& sink) {
          const auto e = g_dtree.evaluate(g_queries[k]);
          sink += static_cast<double>(e.value);
          return static_cast<std::size_t>(e.pieces_evaluated);
        },
        touched);
  };
  bool dtree4_ok = false;
  std::size_t t_dt4 = 0;
  const double dt4 = dtree_with(4, dtree4_ok, t_dt4);
  const auto dtree4_blocks = static_cast<std::int64_t>(g_dtree.block_count());
  bool dtree8_ok = false;
  std::size_t t_dt8 = 0;
  const double dt8 = dtree_with(8, dtree8_ok, t_dt8);
  const auto per = [](std::size_t t) { return static_cast<double>(t) / kQueries; };
  boticelli::bench::JsonLine("aln", "eval")
      .integer("pieces_cap", static_cast<std::int64_t>(cap))
      .integer("pieces", static_cast<std::int64_t>(pieces))
      .integer("depth", static_cast<std::int64_t>(g_model.depth()))
      .num("rms", g_trainer.stats().rms)
      .num("ns_plain", plain)
      .num("ns_alphabeta", ab)
      .num("ns_dtree", dt)
      .num("ns_dtree4", dt4)
      .num("ns_dtree8", dt8)
      .num("ns_fixed", fx)
      .num("ns_alphabeta_rays", ray_ab)
      .num("ns_alphabeta_hint_rays", ray_hint)
      .num("ns_block", block)
      .num("ns_block_rays", ray_block)
      .num("touched_plain", per(t_plain))
      .num("touched_alphabeta", per(t_ab))
      .num("touched_dtree", per(t_dt))
      .num("touched_dtree4", per(t_dt4))
      .num("touched_dtree8", per(t_dt8))
      .num("touched_fixed", per(t_fx))
      .num("touched_alphabeta_rays", per(t_ray))
      .num("touched_alphabeta_hint_rays", per(t_hint))
      .integer("dtree_blocks", blocks)
      .integer("dtree_depth", dtree_depth)
      .integer("dtree_ops", dtree_ops)
      .integer("dtree4_blocks", dtree4_blocks)
      .integer("dtree8_blocks", static_cast<std::int64_t>(g_dtree.block_count()))
      .num("dtree_compile_ms", compile_ms)
      .flag("dtree_ok", dtree_ok && dtree4_ok && dtree8_ok)
      .flag("fixed_ok", fixed_ok)
      .emit();
}

void bench_training(double epsilon, aln::RobustWeighting robust, const char* name) {
  set_ranges(g_model);
  aln::TrainerConfig cfg;
  cfg.epsilon = epsilon;
  cfg.robust = robust;
  g_trainer.configure(cfg);
  constexpr int kRuns = 5;
  std::int64_t best = INT64_MAX;
  for (int r = 0; r < kRuns; ++r) {
    const std::int64_t t0 = cpu_ns();
    g_trainer.train(aln::SampleSet<float, 3>(g_samples, kSamples), g_model);
    const std::int64_t t1 = cpu_ns();
    best = t1 - t0 < best ? t1 - t0 : best;
  }
  const aln::TrainerStats& st = g_trainer.stats();
  boticelli::bench::JsonLine("aln", name)
      .integer("samples", static_cast<std::int64_t>(kSamples))
      .num("epsilon", epsilon)
      .num("cpu_ms", static_cast<double>(best) * 1e-6)
      .integer("pieces", static_cast<std::int64_t>(st.pieces))
      .integer("iterations", static_cast<std::int64_t>(st.iterations))
      .integer("passes", static_cast<std::int64_t>(st.passes))
      .num("rms", st.rms)
      .emit();
}

}  // namespace

BOTICELLI_BENCH_SUITE(aln, "ALN evaluation (plain, alpha-beta, DTREE, Q16.16) and training") {
  make_samples();
  bench_training(0.15, aln::RobustWeighting::kNone, "train_eps0.15");
  bench_training(0.05, aln::RobustWeighting::kNone, "train_eps0.05");
  bench_training(0.15, aln::RobustWeighting::kTukey, "train_eps0.15_tukey");
  for (const std::size_t cap : {std::size_t{8}, std::size_t{32}, std::size_t{128}}) {
    bench_model(cap);
  }
  return 0;
}
