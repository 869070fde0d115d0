// Benchmark suite "mission": the firmware binary run on every shipped world, checked against it.
#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "algo/aln/text_format.h"
#include "algo/mapping/local_model_builder.h"
#include "bench.h"
#include "bench_process.h"
#include "bench_worlds.h"
#include "board_config.h"
#include "firmware/state/mission_state.h"
#include "firmware/state/persistence.h"
#include "hal/sim/world.h"
#include "hal/sim/world_geometry.h"

namespace boticelli::bench {
namespace {

constexpr const char* kSuite = "mission";
constexpr double kGridCellM = 0.1;     // the grid the model's size is compared with [m]
constexpr double kGridCeilingM = 2.5;  // its height: BoardConfig::ceiling_height_m [m]

// What the firmware's last line and console said.
struct MissionLine {
  bool found_line = false;
  std::string result = "none";
  long long cycles = -1;
  long long collisions = -1;
  double sim_time_s = std::numeric_limits<double>::quiet_NaN();
  double wall_time_s = std::numeric_limits<double>::quiet_NaN();
  double target_error_m = std::numeric_limits<double>::quiet_NaN();
  std::string end_reason;  // "LOG info stopping: WHY"
  bool found_cpu = false;
  double look_s = std::numeric_limits<double>::quiet_NaN();
  double think_s = std::numeric_limits<double>::quiet_NaN();
  double plan_s = std::numeric_limits<double>::quiet_NaN();
  std::string longest_line;  // "LOG info mission longest_ms view=… task=…"
};

// The longest unit of each kind, as the firmware names them (mission::unit_name).
constexpr const char* kUnitNames[] = {"view",  "model", "map",      "plan_start",
                                      "value", "step",  "snapshot", "task"};

// "key=value" in a line of space-separated fields; NaN when absent or not a number.
double field(std::string_view line, const char* key) {
  const std::string k = std::string(" ") + key + "=";
  const std::size_t at = line.find(k);
  if (at == std::string_view::npos) return std::numeric_limits<double>::quiet_NaN();
  const std::string value(
      line.substr(at + k.size(), line.find(' ', at + k.size()) - at - k.size()));
  char* end = nullptr;
  const double v = std::strtod(value.c_str(), &end);
  return end != value.c_str() ? v : std::numeric_limits<double>::quiet_NaN();
}

// The console output (stdout of --console stdio): the LAST "MISSION ..." line and the last
// "LOG info mission cpu ..." line. Console lines end in "\r\n".
MissionLine parse_output(const std::string& path) {
  MissionLine m;
  const std::string text = read_file(path);
  std::size_t begin = 0;
  while (begin < text.size()) {
    std::size_t end = text.find('\n', begin);
    if (end == std::string::npos) end = text.size();
    std::string line = text.substr(begin, end - begin);
    begin = end + 1;
    while (!line.empty() && (line.back() == '\r' || line.back() == '\n')) line.pop_back();
    if (line.rfind("MISSION ", 0) == 0) {
      m.found_line = true;
      const std::size_t at = line.find("result=");
      m.result = at == std::string::npos ? "?" : line.substr(at + 7, line.find(' ', at) - at - 7);
      m.cycles = static_cast<long long>(field(line, "cycles"));
      m.collisions = static_cast<long long>(field(line, "collisions"));
      m.sim_time_s = field(line, "sim_time_s");
      m.wall_time_s = field(line, "wall_time_s");
      m.target_error_m = field(line, "target_error_m");
    } else if (const std::size_t at = line.find("LOG info stopping: "); at != std::string::npos) {
      m.end_reason = line.substr(at + 19);
      std::replace(m.end_reason.begin(), m.end_reason.end(), '"', '\'');
    } else if (line.find("LOG info mission longest_ms ") != std::string::npos) {
      m.longest_line = line;
    } else if (line.find("LOG info mission cpu ") != std::string::npos) {
      m.found_cpu = true;
      m.look_s = field(line, "look_s");
      m.think_s = field(line, "think_s");
      m.plan_s = field(line, "plan_s");
    }
  }
  return m;
}

// Size of the last local model as the firmware keeps it, from the state file: the ALN's
// pieces and nodes in binary plus the global map's points (two floats each).
struct ModelSize {
  bool ok = false;
  std::size_t text_bytes = 0;
  std::size_t pieces = 0;
  std::size_t binary_bytes = 0;
  std::size_t points = 0;
  std::size_t points_bytes = 0;
};

firmware::MissionState g_state;  // large: static
mapping::OccupancyModel g_model;

firmware::StateStore g_store;

ModelSize model_size(const std::string& state_dir) {
  ModelSize s;
  char why[512] = "";
  if (!g_store.open(state_dir.c_str(), why, sizeof why) ||
      g_store.load(g_state, why, sizeof why) != firmware::LoadResult::kLoaded) {
    std::fprintf(stderr, "mission: %s: %s\n", state_dir.c_str(), why);
    return s;
  }
  s.text_bytes = g_state.model_bytes;
  s.points = g_state.obstacles.size() + g_state.exploration.size();
  s.points_bytes = s.points * sizeof(core::Point2);
  aln::TextError error{};
  if (g_state.model_bytes > 0 &&
      aln::read_text(g_state.model.data(), g_state.model_bytes, g_model, error)) {
    s.pieces = g_model.piece_count();
    s.binary_bytes = g_model.piece_count() * sizeof(mapping::OccupancyModel::PieceType) +
                     g_model.node_count() * sizeof(mapping::OccupancyModel::Node);
  }
  s.ok = true;
  return s;
}

// A 0.1 m occupancy grid (one byte a cell) over the colliders' floor bounding box, from the
// floor to the readings' ceiling: what a grid map of the same room would hold.
std::size_t grid_bytes(const hal::sim::World& w) {
  double x0 = 1e9, y0 = 1e9, x1 = -1e9, y1 = -1e9;
  for (std::size_t i = 0; i < w.collider_count; ++i) {
    const hal::sim::Collider& c = w.colliders[i];
    if (c.circle) {
      x0 = std::min<double>(x0, c.centre_x_m - c.radius_m);
      x1 = std::max<double>(x1, c.centre_x_m + c.radius_m);
      y0 = std::min<double>(y0, c.centre_y_m - c.radius_m);
      y1 = std::max<double>(y1, c.centre_y_m + c.radius_m);
    } else {
      for (std::size_t k = 0; k < c.hull_size; ++k) {
        x0 = std::min<double>(x0, c.hull[k].x_m);
        x1 = std::max<double>(x1, c.hull[k].x_m);
        y0 = std::min<double>(y0, c.hull[k].y_m);
        y1 = std::max<double>(y1, c.hull[k].y_m);
      }
    }
  }
  if (x1 < x0) return 0;
  const auto cells = [](double a, double b) {
    return static_cast<std::size_t>(std::ceil((b - a) / kGridCellM - 1e-9));
  };
  return cells(x0, x1) * cells(y0, y1) * cells(0.0, kGridCeilingM);
}

hal::sim::World g_world;

int run() {
  const std::string bin_dir = own_directory();
  const std::string firmware_bin = bin_dir + "/boticelli";
  if (::access(firmware_bin.c_str(), X_OK) != 0) {
    std::fprintf(stderr, "mission: no firmware binary at %s (build the 'boticelli' target)\n",
                 firmware_bin.c_str());
    return 1;
  }
  const long max_cycles = env_long("BOTICELLI_MISSION_CYCLES", 60);
  const long seed = env_long("BOTICELLI_MISSION_SEED", 1);
  const double timeout_s = static_cast<double>(env_long("BOTICELLI_MISSION_TIMEOUT_S", 900));
  const bool keep = std::getenv("BOTICELLI_MISSION_KEEP") != nullptr;
  const firmware::BoardConfig config = boards::sim::make_config();

  char tmp_template[] = "/tmp/boticelli-mission-XXXXXX";
  const char* tmp = ::mkdtemp(tmp_template);
  if (tmp == nullptr) {
    std::fprintf(stderr, "mission: cannot create a temporary directory: %s\n",
                 std::strerror(errno));
    return 1;
  }

  const std::string folder = worlds_dir("BOTICELLI_MISSION_WORLDS_DIR", BOTICELLI_WORLDS_DIR);
  const std::vector<std::string> names = world_names(folder, "BOTICELLI_MISSION_WORLDS", kSuite);
  std::size_t worlds = 0;
  std::size_t with_target = 0;
  std::size_t successes = 0;
  double spl_sum = 0.0;
  for (const std::string& name : names) {
    const std::string world_path = std::string(folder).append("/").append(name).append(".sdf");
    char error[256] = "";
    if (!hal::sim::load_world(world_path.c_str(), g_world, error, sizeof error)) {
      std::fprintf(stderr, "mission: %s\n", error);
      continue;
    }
    ++worlds;
    bool has_target = false;
    for (std::size_t i = 0; i < g_world.surface_count; ++i) {
      has_target = has_target || g_world.surfaces[i].target_face != hal::sim::kNoFace;
    }
    if (!has_target) {
      JsonLine(kSuite, name.c_str()).text("skipped", "no target").emit();
      continue;
    }
    ++with_target;
    const std::string dir = std::string(tmp) + "/" + name;
    ::mkdir(dir.c_str(), 0755);
    const std::string trace = dir + "/trace.csv";
    const std::string out = dir + "/console.txt";
    const std::string err = dir + "/stderr.txt";
    const std::string state_dir = dir + "/state";
    const std::vector<std::string> args = {firmware_bin,
                                           "--world",
                                           world_path,
                                           "--seed",
                                           std::to_string(seed),
                                           "--max-cycles",
                                           std::to_string(max_cycles),
                                           "--trace",
                                           trace,
                                           "--console",
                                           "stdio",
                                           "--state",
                                           state_dir};
    bool timed_out = false;
    double cpu_s = 0.0;
    const double t0 = wall_s();
    const int exit_code = run_firmware(args, out, err, timeout_s, timed_out, cpu_s);
    const double wall = wall_s() - t0;
    const MissionLine m = parse_output(out);

    // The trace against the world's geometry (true poses; the robot's cylinder).
    std::vector<hal::sim::TraceRow> rows;
    std::string trace_error;
    hal::sim::TraceCheck check{};
    const bool trace_ok = hal::sim::read_trace(trace.c_str(), rows, trace_error);
    if (trace_ok) {
      check = hal::sim::check_trace(g_world, rows, config.robot_radius_m, config.robot_height_m);
    } else {
      std::fprintf(stderr, "mission: %s: %s\n", name.c_str(), trace_error.c_str());
    }
    const core::Point2 start{g_world.start.x_m, g_world.start.y_m};
    const core::Point2 goal{g_world.target_point_m.x(), g_world.target_point_m.y()};
    const double shortest = hal::sim::shortest_path_m(g_world, start, goal, config.goal_standoff_m,
                                                      config.robot_radius_m, config.robot_height_m);
    const bool success = m.result == "found";
    const double path = trace_ok ? check.path_length_m : std::numeric_limits<double>::quiet_NaN();
    double spl = 0.0;
    if (success && std::isfinite(shortest) && std::isfinite(path)) {
      spl = std::max(path, shortest) > 0.0 ? shortest / std::max(path, shortest) : 1.0;
    }
    successes += success ? 1U : 0U;
    spl_sum += spl;
    const double compute_s = m.look_s + m.think_s + m.plan_s;
    const ModelSize size = model_size(state_dir);

    JsonLine line(kSuite, name.c_str());
    line.text("result", m.result.c_str())
        .text("end_reason", m.end_reason.c_str())
        .integer("exit_code", exit_code)
        .flag("timed_out", timed_out)
        .integer("cycles", m.cycles)
        .num("path_length_m", path)
        .num("shortest_m", shortest)
        .num("spl", spl)
        .num("sim_time_s", m.sim_time_s)
        .num("wall_time_s", wall)
        .num("firmware_wall_time_s", m.wall_time_s)
        .num("process_cpu_s", cpu_s)
        .integer("collisions", trace_ok ? static_cast<std::int64_t>(check.collisions) : -1)
        .integer("firmware_collisions", m.collisions)
        .num("min_clearance_m",
             trace_ok ? check.min_clearance_m : std::numeric_limits<double>::quiet_NaN())
        .num("max_trace_gap_s",
             trace_ok ? check.max_gap_s : std::numeric_limits<double>::quiet_NaN())
        .integer("trace_rows", static_cast<std::int64_t>(check.rows))
        .num("target_error_m", m.target_error_m)
        .num("look_cpu_s", m.look_s)
        .num("think_cpu_s", m.think_s)
        .num("plan_cpu_s", m.plan_s)
        .num("compute_share_of_sim_time", m.sim_time_s > 0.0
                                              ? compute_s / m.sim_time_s
                                              : std::numeric_limits<double>::quiet_NaN())
        .num("wall_per_sim_s",
             m.sim_time_s > 0.0 ? wall / m.sim_time_s : std::numeric_limits<double>::quiet_NaN());
    if (size.ok) {
      line.integer("model_pieces", static_cast<std::int64_t>(size.pieces))
          .integer("model_bytes", static_cast<std::int64_t>(size.binary_bytes))
          .integer("model_text_bytes", static_cast<std::int64_t>(size.text_bytes))
          .integer("map_points", static_cast<std::int64_t>(size.points))
          .integer("map_points_bytes", static_cast<std::int64_t>(size.points_bytes));
    }
    line.integer("grid_0_1m_bytes", static_cast<std::int64_t>(grid_bytes(g_world)));
    for (const char* unit : kUnitNames) {
      line.num((std::string("longest_") + unit + "_ms").c_str(), field(m.longest_line, unit));
    }
    line.emit();
    if (!m.found_line || !m.found_cpu) {
      std::fprintf(stderr, "mission: %s: %s%s (console output in %s)\n", name.c_str(),
                   m.found_line ? "" : "no MISSION line ", m.found_cpu ? "" : "no cpu line",
                   out.c_str());
    }
    if (!keep) remove_tree(dir);
  }
  if (!keep) {
    ::rmdir(tmp);
  } else {
    std::fprintf(stderr, "mission: outputs kept in %s\n", tmp);
  }
  JsonLine(kSuite, "summary")
      .integer("worlds", static_cast<std::int64_t>(worlds))
      .integer("with_target", static_cast<std::int64_t>(with_target))
      .integer("found", static_cast<std::int64_t>(successes))
      .num("mean_spl", with_target > 0 ? spl_sum / static_cast<double>(with_target) : 0.0)
      .integer("max_cycles", max_cycles)
      .integer("seed", seed)
      .emit();
  return 0;
}

[[maybe_unused]] const bool g_registered = register_suite(
    {kSuite, "firmware binary on every shipped world: SPL, collisions, CPU split", &run});

}  // namespace
}  // namespace boticelli::bench
