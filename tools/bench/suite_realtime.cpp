// Benchmark suite "realtime": whole missions of the firmware binary on the shipped worlds with
// background slices ended by the host's clock (--host-slices, as on the robot), the executive's
// host timings against the task table's budgets and the slice limit, the mission's longest
// units against half a frame, and frame start latency in a run paced to wall time.
//
// Knobs: BOTICELLI_REALTIME_WORLDS=name,... (default every shipped world), BOTICELLI_REALTIME_SEEDS
// =1,2,... (default 1), BOTICELLI_REALTIME_CYCLES (cycles per mission, default 8),
// BOTICELLI_REALTIME_PACED_S (seconds of the paced run at --speed 1 --realtime, default 20; 0
// skips it), BOTICELLI_REALTIME_FIFO=1 (the missions with --realtime too: SCHED_FIFO where
// permitted, so other processes do not preempt them; they then hold a core each while they
// run), BOTICELLI_REALTIME_TIMEOUT_S (per mission, default 600), BOTICELLI_REALTIME_KEEP
// (keep the outputs), BOTICELLI_REALTIME_FIRMWARE (the firmware binary, default the one built
// next to the bench), BOTICELLI_REALTIME_EMULATOR (a command the firmware is run through, words
// split at spaces, e.g. "qemu-aarch64 -L /usr/aarch64-linux-gnu" for an aarch64 build: every
// line then says "emulated" with the emulator's name, figures of the emulator, not a board).
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "bench.h"
#include "bench_process.h"
#include "bench_worlds.h"
#include "firmware/executive/task_table.h"

namespace boticelli::bench {
namespace {

constexpr const char* kSuite = "realtime";
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The mission's unit kinds, as the firmware's "mission longest_ms" line names them.
constexpr const char* kUnitNames[] = {"view",  "model", "map",      "plan_start",
                                      "value", "step",  "snapshot", "task"};

// "key=value" in a line of space-separated fields; NaN when absent or not a number.
double field(std::string_view line, const char* key) {
  const std::string k = std::string(" ") + key + "=";
  const std::size_t at = line.find(k);
  if (at == std::string_view::npos) return kNaN;
  const std::string value(
      line.substr(at + k.size(), line.find(' ', at + k.size()) - at - k.size()));
  char* end = nullptr;
  const double v = std::strtod(value.c_str(), &end);
  return end != value.c_str() ? v : kNaN;
}

double max_of(double a, double b) {
  if (a != a) return b;  // NaN
  if (b != b) return a;
  return std::max(a, b);
}

// One kind of work's figures from a "host ..." line [µs].
struct Timing {
  double wall_p99_us = kNaN;
  double wall_worst_us = kNaN;
  double cpu_p99_us = kNaN;
  double cpu_worst_us = kNaN;
  double count = 0.0;
  void merge(const Timing& o) {
    wall_p99_us = max_of(wall_p99_us, o.wall_p99_us);
    wall_worst_us = max_of(wall_worst_us, o.wall_worst_us);
    cpu_p99_us = max_of(cpu_p99_us, o.cpu_p99_us);
    cpu_worst_us = max_of(cpu_worst_us, o.cpu_worst_us);
    count += o.count;
  }
};

// What one run of the firmware said.
struct RunOutput {
  std::string result = "none";
  double cycles = kNaN;
  double sim_time_s = kNaN;
  std::vector<std::string> task_names;  // table order
  std::map<std::string, Timing> tasks;
  std::map<std::string, double> budgets_us;
  Timing slice;
  double slice_limit_us = kNaN;
  double slice_over_limit = kNaN;
  double slice_overshoot_us = kNaN;
  double margin_us = kNaN;
  Timing work;
  double latencies = kNaN;
  double latency_p99_us = kNaN;
  double latency_worst_us = kNaN;
  std::map<std::string, double> longest_ms;
  std::string realtime;  // the firmware's "realtime: ..." log line, when it set up the process
};

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::size_t begin = 0;
  while (begin < text.size()) {
    std::size_t end = text.find('\n', begin);
    if (end == std::string::npos) end = text.size();
    std::string line = text.substr(begin, end - begin);
    while (!line.empty() && (line.back() == '\r' || line.back() == '\n')) line.pop_back();
    out.push_back(line);
    begin = end + 1;
  }
  return out;
}

RunOutput parse_run(const std::string& out_path, const std::string& err_path) {
  RunOutput r;
  for (const std::string& line : lines_of(read_file(out_path))) {
    if (line.rfind("MISSION ", 0) == 0) {
      const std::size_t at = line.find("result=");
      if (at != std::string::npos) r.result = line.substr(at + 7, line.find(' ', at) - at - 7);
      r.cycles = field(line, "cycles");
      r.sim_time_s = field(line, "sim_time_s");
    } else if (const std::size_t at = line.find("host task "); at != std::string::npos) {
      std::istringstream words(line.substr(at + 10));
      std::string name;
      words >> name;
      Timing t;
      t.wall_p99_us = field(line, "wall_p99_us");
      t.wall_worst_us = field(line, "wall_worst_us");
      t.cpu_p99_us = field(line, "cpu_p99_us");
      t.cpu_worst_us = field(line, "cpu_worst_us");
      t.count = field(line, "runs");
      r.task_names.push_back(name);
      r.tasks[name] = t;
      r.budgets_us[name] = field(line, "budget_us");
    } else if (line.find("host background ") != std::string::npos) {
      r.slice.wall_p99_us = field(line, "wall_p99_us");
      r.slice.wall_worst_us = field(line, "wall_worst_us");
      r.slice.cpu_p99_us = field(line, "cpu_p99_us");
      r.slice.cpu_worst_us = field(line, "cpu_worst_us");
      r.slice.count = field(line, "slices");
      r.slice_limit_us = field(line, "limit_us");
      r.slice_over_limit = field(line, "over_limit");
      r.slice_overshoot_us = field(line, "overshoot_worst_us");
      r.margin_us = field(line, "margin_us");
    } else if (line.find("host frame ") != std::string::npos) {
      r.work.wall_p99_us = field(line, "work_wall_p99_us");
      r.work.wall_worst_us = field(line, "work_wall_worst_us");
      r.work.cpu_p99_us = field(line, "work_cpu_p99_us");
      r.work.cpu_worst_us = field(line, "work_cpu_worst_us");
      r.work.count = field(line, "frames");
      r.latencies = field(line, "latencies");
      r.latency_p99_us = field(line, "start_latency_p99_us");
      r.latency_worst_us = field(line, "start_latency_worst_us");
    } else if (line.find("mission longest_ms ") != std::string::npos) {
      for (const char* unit : kUnitNames) r.longest_ms[unit] = field(line, unit);
    }
  }
  for (const std::string& line : lines_of(read_file(err_path))) {
    if (const std::size_t at = line.find("realtime: "); at != std::string::npos) {
      r.realtime = line.substr(at);
    }
  }
  return r;
}

// The host's 1-minute load average and, where the kernel reports it, the share of the last
// 60 s in which some task waited for a CPU (/proc/pressure/cpu): how busy the host was.
double load_average() {
  const std::string text = read_file("/proc/loadavg");
  return text.empty() ? kNaN : std::strtod(text.c_str(), nullptr);
}
double cpu_pressure_pct() {
  return field(" " + read_file("/proc/pressure/cpu"), "avg60");
}

// The firmware binary and the emulator it runs under (none: natively).
struct Launch {
  std::string path;
  std::vector<std::string> emulator;  // program and arguments, before the firmware's path
  std::string emulated = "no";        // the emulator program's name, on every output line
  // The command line: the emulator's words, the firmware's path, then `args`.
  std::vector<std::string> command(const std::vector<std::string>& args) const {
    std::vector<std::string> out = emulator;
    out.push_back(path);
    out.insert(out.end(), args.begin(), args.end());
    return out;
  }
};

Launch firmware_launch() {
  Launch f;
  const char* path = std::getenv("BOTICELLI_REALTIME_FIRMWARE");
  f.path = path != nullptr && *path != '\0' ? std::string(path) : own_directory() + "/boticelli";
  if (const char* e = std::getenv("BOTICELLI_REALTIME_EMULATOR"); e != nullptr) {
    std::istringstream words(e);
    std::string word;
    while (words >> word) f.emulator.push_back(word);
  }
  if (!f.emulator.empty()) {
    const std::string& program = f.emulator.front();
    f.emulated = program.substr(program.rfind('/') + 1);
  }
  return f;
}

// Every line of the suite says whether its figures are the emulator's.
JsonLine output_line(const char* name, const Launch& launch) {
  JsonLine line(kSuite, name);
  line.text("emulated", launch.emulated.c_str());
  return line;
}

std::vector<long> seed_list() {
  std::vector<long> seeds;
  const char* v = std::getenv("BOTICELLI_REALTIME_SEEDS");
  if (v != nullptr) {
    std::istringstream in(v);
    std::string item;
    while (std::getline(in, item, ',')) {
      const long s = std::strtol(item.c_str(), nullptr, 10);
      if (s > 0) seeds.push_back(s);
    }
  }
  if (seeds.empty()) seeds.push_back(1);
  return seeds;
}

int run() {
  const Launch launch = firmware_launch();
  if (::access(launch.path.c_str(), X_OK) != 0) {
    std::fprintf(stderr, "realtime: no firmware binary at %s (build the 'boticelli' target)\n",
                 launch.path.c_str());
    return 1;
  }
  const long cycles = env_long("BOTICELLI_REALTIME_CYCLES", 8);
  const double timeout_s = static_cast<double>(env_long("BOTICELLI_REALTIME_TIMEOUT_S", 600));
  const double paced_s = env_double("BOTICELLI_REALTIME_PACED_S", 20.0);
  const bool keep = std::getenv("BOTICELLI_REALTIME_KEEP") != nullptr;
  const bool fifo_missions = env_long("BOTICELLI_REALTIME_FIFO", 0) == 1;
  const double load_start = load_average();
  const double pressure_start = cpu_pressure_pct();
  const std::vector<long> seeds = seed_list();

  char tmp_template[] = "/tmp/boticelli-realtime-XXXXXX";
  const char* tmp = ::mkdtemp(tmp_template);
  if (tmp == nullptr) {
    std::fprintf(stderr, "realtime: cannot create a temporary directory: %s\n",
                 std::strerror(errno));
    return 1;
  }
  const std::string folder = worlds_dir("BOTICELLI_REALTIME_WORLDS_DIR", BOTICELLI_WORLDS_DIR);
  const std::vector<std::string> names = world_names(folder, "BOTICELLI_REALTIME_WORLDS", kSuite);

  std::vector<std::string> task_order;
  std::map<std::string, Timing> tasks;
  std::map<std::string, double> budgets_us;
  Timing slices;
  Timing work;
  double slice_limit_us = kNaN;
  double slice_over_limit = 0.0;
  double slice_overshoot_us = kNaN;
  double margin_us = kNaN;
  std::map<std::string, double> longest_ms;
  std::size_t runs = 0;
  std::size_t parsed = 0;
  std::vector<std::string> dirs;
  const auto dir_for = [&](const std::string& name) {
    std::string dir = std::string(tmp) + "/" + name;  // returned: moved, not copied
    ::mkdir(dir.c_str(), 0755);
    dirs.push_back(dir);
    return dir;
  };

  for (const std::string& name : names) {
    const std::string world_path = std::string(folder).append("/").append(name).append(".sdf");
    for (const long seed : seeds) {
      const std::string dir = dir_for(name + "-" + std::to_string(seed));
      const std::string out = dir + "/console.txt";
      const std::string err = dir + "/stderr.txt";
      // Snapshots on: the picture's units run in the background like every other unit.
      std::vector<std::string> args = {"--world",       world_path,
                                       "--seed",        std::to_string(seed),
                                       "--max-cycles",  std::to_string(cycles),
                                       "--snapshots",   dir + "/snapshots",
                                       "--host-slices", "--console",
                                       "stdio"};
      if (fifo_missions) args.emplace_back("--realtime");
      bool timed_out = false;
      double cpu_s = 0.0;
      const double t0 = wall_s();
      const int exit_code =
          run_firmware(launch.command(args), out, err, timeout_s, timed_out, cpu_s);
      const double wall = wall_s() - t0;
      ++runs;
      const RunOutput r = parse_run(out, err);
      if (r.tasks.empty()) {
        std::fprintf(stderr,
                     "realtime: %s seed %ld: no host timing lines (exit code %d, output in %s)\n",
                     name.c_str(), seed, exit_code, out.c_str());
        continue;
      }
      ++parsed;
      JsonLine line = output_line(name.c_str(), launch);
      line.integer("seed", seed)
          .text("result", r.result.c_str())
          .integer("exit_code", exit_code)
          .flag("timed_out", timed_out)
          .num("cycles", r.cycles)
          .num("sim_time_s", r.sim_time_s)
          .num("wall_time_s", wall)
          .num("process_cpu_s", cpu_s);
      for (const std::string& task : r.task_names) {
        const Timing& t = r.tasks.at(task);
        line.num((task + "_cpu_p99_us").c_str(), t.cpu_p99_us)
            .num((task + "_cpu_worst_us").c_str(), t.cpu_worst_us)
            .num((task + "_wall_worst_us").c_str(), t.wall_worst_us);
        if (tasks.find(task) == tasks.end()) task_order.push_back(task);
        tasks[task].merge(t);
        budgets_us[task] = r.budgets_us.at(task);
      }
      line.num("slices", r.slice.count)
          .num("slice_wall_p99_us", r.slice.wall_p99_us)
          .num("slice_wall_worst_us", r.slice.wall_worst_us)
          .num("slice_cpu_worst_us", r.slice.cpu_worst_us)
          .num("slice_over_limit", r.slice_over_limit)
          .num("slice_overshoot_worst_us", r.slice_overshoot_us);
      for (const auto& [unit, ms] : r.longest_ms) {
        line.num(("longest_" + unit + "_ms").c_str(), ms);
        longest_ms[unit] = max_of(longest_ms.count(unit) != 0U ? longest_ms[unit] : kNaN, ms);
      }
      line.emit();
      slices.merge(r.slice);
      work.merge(r.work);
      slice_limit_us = r.slice_limit_us;
      slice_overshoot_us = max_of(slice_overshoot_us, r.slice_overshoot_us);
      margin_us = r.margin_us;
      if (r.slice_over_limit == r.slice_over_limit) slice_over_limit += r.slice_over_limit;
    }
  }

  // Per task over every run: the worst run and the highest 99th percentile of any run.
  bool tasks_within = parsed > 0;
  bool tasks_within_wall = parsed > 0;
  for (const std::string& task : task_order) {
    const Timing& t = tasks[task];
    const double budget = budgets_us[task];
    const bool within = t.cpu_worst_us <= budget;
    const bool within_wall = t.wall_worst_us <= budget;
    tasks_within = tasks_within && within;
    tasks_within_wall = tasks_within_wall && within_wall;
    output_line("task", launch)
        .text("task", task.c_str())
        .num("budget_us", budget)
        .num("runs", t.count)
        .num("cpu_p99_us", t.cpu_p99_us)
        .num("cpu_worst_us", t.cpu_worst_us)
        .num("wall_p99_us", t.wall_p99_us)
        .num("wall_worst_us", t.wall_worst_us)
        .flag("within_budget_cpu", within)
        .flag("within_budget_wall", within_wall)
        .emit();
  }
  // A slice is within its limit when it ended before it; one that ran past it by less than
  // the margin still ended before the next frame (the margin is there for the unit begun last).
  const bool slices_within = parsed > 0 && slice_over_limit == 0.0;
  const bool slices_within_frame = parsed > 0 && !(slice_overshoot_us > margin_us);
  output_line("background", launch)
      .num("limit_us", slice_limit_us)
      .num("slices", slices.count)
      .num("wall_p99_us", slices.wall_p99_us)
      .num("wall_worst_us", slices.wall_worst_us)
      .num("cpu_p99_us", slices.cpu_p99_us)
      .num("cpu_worst_us", slices.cpu_worst_us)
      .num("over_limit", slice_over_limit)
      .num("overshoot_worst_us", slice_overshoot_us)
      .num("margin_us", margin_us)
      .flag("within_limit", slices_within)
      .flag("within_frame", slices_within_frame)
      .emit();
  output_line("frame", launch)
      .integer("frame_us", firmware::kDefaultMinorFrameUs)
      .num("frames", work.count)
      .num("work_wall_p99_us", work.wall_p99_us)
      .num("work_wall_worst_us", work.wall_worst_us)
      .num("work_cpu_p99_us", work.cpu_p99_us)
      .num("work_cpu_worst_us", work.cpu_worst_us)
      .emit();
  // The longest unit of each kind (thread CPU) against half a frame.
  const double half_frame_ms = firmware::kDefaultMinorFrameUs * 0.5e-3;
  bool units_within = parsed > 0;
  {
    JsonLine line = output_line("units", launch);
    line.num("half_frame_ms", half_frame_ms);
    for (const char* unit : kUnitNames) {
      const double ms = longest_ms.count(unit) != 0U ? longest_ms[unit] : kNaN;
      line.num((std::string("longest_") + unit + "_ms").c_str(), ms);
      // The mission task's body is a task: its budget is judged above, not half a frame.
      if (std::strcmp(unit, "task") != 0) units_within = units_within && ms <= half_frame_ms;
    }
    line.flag("within_half_frame", units_within).emit();
  }

  // Frame start latency at --speed 1 with the robot's process set-up where permitted.
  if (paced_s > 0.0 && !names.empty()) {
    const std::string& name = names.front();
    const std::string world_path = std::string(folder).append("/").append(name).append(".sdf");
    const std::string dir = dir_for("paced");
    const std::string out = dir + "/console.txt";
    const std::string err = dir + "/stderr.txt";
    const std::vector<std::string> args = {
        "--world",   world_path, "--seed",     std::to_string(seeds.front()),
        "--speed",   "1",        "--realtime", "--host-slices",
        "--console", "stdio"};
    bool timed_out = false;
    double cpu_s = 0.0;
    const int exit_code = run_firmware(launch.command(args), out, err, paced_s, timed_out, cpu_s);
    const RunOutput r = parse_run(out, err);
    const bool fifo = r.realtime.find("SCHED_FIFO priority") != std::string::npos;
    const bool locked = r.realtime.find("memory locked") != std::string::npos;
    output_line("jitter", launch)
        .text("world", name.c_str())
        .num("paced_s", paced_s)
        .integer("exit_code", exit_code)
        .num("frames", r.work.count)
        .num("latencies", r.latencies)
        .num("start_latency_p99_us", r.latency_p99_us)
        .num("start_latency_worst_us", r.latency_worst_us)
        .num("slice_wall_worst_us", r.slice.wall_worst_us)
        .flag("sched_fifo", fifo)
        .flag("memory_locked", locked)
        .text("process_setup", r.realtime.empty() ? "not reported" : r.realtime.c_str())
        .emit();
    if (!fifo || !locked) {
      std::fprintf(stderr, "realtime: frame start latency measured WITHOUT %s%s%s: %s\n",
                   fifo ? "" : "SCHED_FIFO", !fifo && !locked ? " and " : "",
                   locked ? "" : "mlockall", r.realtime.c_str());
    }
  }

  output_line("summary", launch)
      .text("firmware", launch.path.c_str())
      .integer("worlds", static_cast<std::int64_t>(names.size()))
      .integer("seeds", static_cast<std::int64_t>(seeds.size()))
      .integer("runs", static_cast<std::int64_t>(runs))
      .integer("max_cycles", cycles)
      .flag("missions_sched_fifo", fifo_missions)
      .num("load_average_start", load_start)
      .num("load_average_end", load_average())
      .num("cpu_pressure_avg60_pct_start", pressure_start)
      .num("cpu_pressure_avg60_pct_end", cpu_pressure_pct())
      .flag("tasks_within_budget_cpu", tasks_within)
      .flag("tasks_within_budget_wall", tasks_within_wall)
      .flag("slices_within_limit", slices_within)
      .flag("slices_within_frame", slices_within_frame)
      .flag("units_within_half_frame", units_within)
      .text("clock", "host CLOCK_MONOTONIC (wall) and CLOCK_THREAD_CPUTIME_ID (cpu)")
      .emit();

  if (!keep) {
    for (const std::string& dir : dirs) remove_tree(dir);
    ::rmdir(tmp);
  } else {
    std::fprintf(stderr, "realtime: outputs kept in %s\n", tmp);
  }
  return parsed == runs ? 0 : 1;
}

[[maybe_unused]] const bool g_registered = register_suite(
    {kSuite,
     "host timings of whole missions: tasks vs budgets, slices vs limit, longest units, jitter",
     &run});

}  // namespace
}  // namespace boticelli::bench
