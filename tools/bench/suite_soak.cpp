// Benchmark suite "soak": two hours of simulated time on the sim board under a seeded random
// plan of faults of every pair, those ridden out and those held and retried
// (boards/sim/harness/fault_scenario.h's rig): allocations after init (counted by replacing the
// global operator new here), statistics, every fault ended safe, the state file loadable at
// every quiet moment. SOAK_SECONDS (default 7200), SOAK_SEED (default 1), SOAK_FAULTS (default
// 250, at most 256), SOAK_TERMINAL (default 1; 0: only the pairs the robot rides out),
// SOAK_PLAN_OUT=FILE (writes the plan in the --faults format).
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <new>
#include <string>

#include "bench.h"
#include "bench_process.h"
#include "fault_scenario.h"
#include "firmware/state/persistence.h"
#include "hal/sim/fault_plan.h"
#include "sim_board.h"

namespace {

std::atomic<bool> g_counting{false};
std::atomic<std::uint64_t> g_allocations{0};

void* counted_alloc(std::size_t size) {
  if (g_counting.load(std::memory_order_relaxed)) {
    g_allocations.fetch_add(1, std::memory_order_relaxed);
  }
  // NOLINTNEXTLINE(cppcoreguidelines-no-malloc): this is the allocator operator new uses
  void* p = std::malloc(size == 0 ? 1 : size);
  if (p == nullptr) throw std::bad_alloc();
  return p;
}

}  // namespace

// The whole bench binary's operator new: counts while g_counting is set (the soak's loop).
// Direct malloc calls are not counted here; test_faults counts those for every pair.
void* operator new(std::size_t size) {
  return counted_alloc(size);
}
void* operator new[](std::size_t size) {
  return counted_alloc(size);
}
// NOLINTBEGIN(cppcoreguidelines-no-malloc): the matching deallocation of counted_alloc
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete[](void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::size_t) noexcept {
  std::free(p);
}
// NOLINTEND(cppcoreguidelines-no-malloc)

namespace boticelli::bench {
namespace {

boards::sim::SimBoard g_board;
boards::sim::FaultSoakResult g_result;
hal::sim::FaultPlan g_plan;

double env_number(const char* name, double fallback) {
  const char* v = std::getenv(name);
  if (v == nullptr || *v == '\0') return fallback;
  char* end = nullptr;
  const double x = std::strtod(v, &end);
  return end != v && *end == '\0' && x > 0.0 ? x : fallback;
}

void start_counting(void*) {
  g_allocations = 0;
  g_counting = true;
}
void stop_counting(void*) {
  g_counting = false;
}

}  // namespace

BOTICELLI_BENCH_SUITE(soak, "2 h of simulated time under random faults: allocations, safety") {
  const double run_s = env_number("SOAK_SECONDS", 7200.0);
  hal::sim::PlanGeneratorConfig plan_config;
  plan_config.seed = static_cast<std::uint64_t>(env_number("SOAK_SEED", 1.0));
  plan_config.run_s = run_s;
  plan_config.warmup_s = 5.0;
  plan_config.count = static_cast<std::size_t>(env_number("SOAK_FAULTS", 250.0));
  // (Not env_number, which takes only positive numbers: "0" is the value that matters here.)
  const char* terminal = std::getenv("SOAK_TERMINAL");
  plan_config.include_terminal = terminal == nullptr || std::strcmp(terminal, "0") != 0;
  hal::sim::generate_fault_plan(plan_config, g_plan);
  if (const char* plan_out = std::getenv("SOAK_PLAN_OUT"); plan_out != nullptr) {
    // The plan in the --faults file format, to replay a soak's faults on the firmware.
    static char text[hal::sim::FaultPlan::kMaxFileBytes];
    const std::size_t n = hal::sim::format_fault_plan(g_plan, text, sizeof text);
    std::FILE* f = std::fopen(plan_out, "w");
    if (f == nullptr || n == 0 || std::fwrite(text, 1, n, f) != n) {
      std::fprintf(stderr, "soak: cannot write the plan to %s\n", plan_out);
    }
    if (f != nullptr) std::fclose(f);
  }
  char dir_template[] = "/tmp/boticelli-soak-XXXXXX";
  const char* dir = ::mkdtemp(dir_template);
  const std::string world = std::string(BOTICELLI_WORLDS_DIR) + "/thesis_room.sdf";
  boards::sim::FaultScenarioConfig config;
  config.world_file = world.c_str();
  config.state_dir = dir;
  config.seed = plan_config.seed;
  config.camera_fps = 1.0F;  // frames are what costs: one a second keeps the camera healthy
  config.loop_started = start_counting;
  config.loop_ended = stop_counting;
  const double wall0 = wall_s();
  const bool ran = boards::sim::run_fault_soak(g_board, g_plan, run_s, config, g_result);
  const double wall = wall_s() - wall0;
  if (dir != nullptr) {
    for (const char* name : firmware::StateStore::kCopyNames) {
      ::unlink((std::string(dir) + "/" + name).c_str());
    }
    ::rmdir(dir);
  }
  if (!ran) {
    std::fprintf(stderr, "soak: %s\n", g_result.error);
    return 1;
  }
  const boards::sim::FaultSoakResult& r = g_result;
  const bool ok = g_allocations == 0 && r.ended_unsafe == 0 && r.stop_violations == 0 &&
                  r.collisions == 0 && r.state_loads_failed == 0 && r.state_not_current == 0 &&
                  r.corruptions > 0 && r.corruptions_recovered == r.corruptions &&
                  r.faults_ended > 0;
  JsonLine("soak", "run")
      .integer("seed", static_cast<std::int64_t>(plan_config.seed))
      .num("sim_s", r.sim_s)
      .num("wall_s", wall)
      .integer("frames", static_cast<std::int64_t>(r.frames))
      .integer("planned_faults", static_cast<std::int64_t>(g_plan.size()))
      .integer("faults_started", r.faults_started)
      .integer("faults_ended", r.faults_ended)
      .integer("quiet_checks", r.quiet_checks)
      .num("worst_recovery_s", r.worst_recovery_s)
      .flag("held_and_retried_faults", plan_config.include_terminal)
      .integer("ended_safe", r.ended_safe)
      .integer("ended_unsafe", r.ended_unsafe)
      .text("first_unsafe", r.first_unsafe)
      .integer("stop_violations", static_cast<std::int64_t>(r.stop_violations))
      .text("first_stop_violation", r.first_stop_violation)
      .integer("operator_resets", r.operator_resets)
      .integer("collisions", r.collisions)
      .integer("allocations_after_init", static_cast<std::int64_t>(g_allocations.load()))
      .integer("saves", static_cast<std::int64_t>(r.saves))
      .integer("save_failures", static_cast<std::int64_t>(r.save_failures))
      .integer("state_loads_failed", r.state_loads_failed)
      .integer("state_not_current", r.state_not_current)
      .integer("corruptions", r.corruptions)
      .integer("corruptions_recovered", r.corruptions_recovered)
      .integer("frame_overruns", static_cast<std::int64_t>(r.frame_overruns))
      .integer("missed_frames", static_cast<std::int64_t>(r.missed_frames))
      .integer("worst_jitter_us", r.worst_jitter_us)
      .integer("worst_task_us", r.worst_task_us)
      .integer("console_dropped_bytes", static_cast<std::int64_t>(r.console_dropped_bytes))
      .integer("watchdog_expirations", r.watchdog_expirations)
      .flag("passed", ok)
      .emit();
  return ok ? 0 : 1;
}

}  // namespace boticelli::bench
