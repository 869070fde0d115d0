// Benchmark suites "mission" and "localization": the firmware binary run on every shipped and
// test world, per seed and planner, checked against each world's geometry; "localization" runs
// the simulator's realistic setting with every look registered and reports the pose estimate.
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
#include <thread>
#include <atomic>
#include <vector>

#include "algo/aln/text_format.h"
#include "algo/mapping/local_model_builder.h"
#include "bench.h"
#include "bench_process.h"
#include "bench_worlds.h"
#include "board_config.h"
#include "firmware/state/mission_state.h"
#include "firmware/state/persistence.h"
#include "algo/core/geometry.h"
#include "hal/sim/world.h"
#include "hal/sim/world_geometry.h"

namespace boticelli::bench {
namespace {

constexpr const char* kMissionSuite = "mission";
constexpr const char* kLocalizationSuite = "localization";
const char* g_suite = kMissionSuite;   // the suite running (its rows' and messages' name)
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
  double register_s = std::numeric_limits<double>::quiet_NaN();
  double registered = std::numeric_limits<double>::quiet_NaN();  // looks registered
  std::string calibration_line;  // "LOG info mission base_calibration valid=… …"
  std::string longest_line;      // "LOG info mission longest_ms view=… task=…"
  std::string map_line;          // "LOG info mission map planner=… grid_bytes=… …"
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
    } else if (line.find("LOG info mission map ") != std::string::npos) {
      m.map_line = line;
    } else if (line.find("LOG info mission longest_ms ") != std::string::npos) {
      m.longest_line = line;
    } else if (line.find("LOG info mission cpu ") != std::string::npos) {
      m.found_cpu = true;
      m.look_s = field(line, "look_s");
      m.think_s = field(line, "think_s");
      m.plan_s = field(line, "plan_s");
      m.register_s = field(line, "register_s");
      m.registered = field(line, "registered");
    } else if (line.find("LOG info mission base_calibration ") != std::string::npos) {
      m.calibration_line = line;
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
    std::fprintf(stderr, "%s: %s: %s\n", g_suite, state_dir.c_str(), why);
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

constexpr double kObstacleOffM = 0.3;  // an occupied cell farther than this from a surface

// The mission frame in the world: the first trace row's true pose composed with the inverse
// of its odometry pose (the odo_* columns; the frame is the odometry's at the base's start).
bool mission_frame(const std::vector<hal::sim::TraceRow>& rows, core::Pose2& origin) {
  if (rows.empty() || !rows.front().has_pose_columns) return false;
  const hal::sim::TraceRow& r = rows.front();
  const core::Pose2 truth{static_cast<float>(r.x_m), static_cast<float>(r.y_m),
                          static_cast<float>(r.yaw_rad)};
  const core::Pose2 odo{static_cast<float>(r.odo[0]), static_cast<float>(r.odo[1]),
                        static_cast<float>(r.odo[2])};
  origin = core::compose(truth, core::inverse(odo));
  return true;
}

// How far the firmware's estimate (est_*) and the raw odometry (odo_*), both in the mission
// frame, are from the true pose: at the end and at worst over the run [m, deg], and the path
// the robot truly drove [m].
struct PoseErrors {
  bool ok = false;
  double path_m = 0.0;
  double final_m[2] = {0.0, 0.0};  // [estimate, odometry]
  double final_deg[2] = {0.0, 0.0};
  double worst_m[2] = {0.0, 0.0};
  double worst_deg[2] = {0.0, 0.0};
};

PoseErrors pose_errors(const std::vector<hal::sim::TraceRow>& rows) {
  PoseErrors e;
  core::Pose2 origin{};
  if (!mission_frame(rows, origin)) return e;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const hal::sim::TraceRow& r = rows[i];
    if (i > 0) e.path_m += std::hypot(r.x_m - rows[i - 1].x_m, r.y_m - rows[i - 1].y_m);
    for (int k = 0; k < 2; ++k) {
      const double* p = k == 0 ? r.est : r.odo;
      const core::Pose2 w = core::compose(
          origin, {static_cast<float>(p[0]), static_cast<float>(p[1]), static_cast<float>(p[2])});
      e.final_m[k] =
          std::hypot(static_cast<double>(w.x_m) - r.x_m, static_cast<double>(w.y_m) - r.y_m);
      e.final_deg[k] = std::fabs(std::remainder(static_cast<double>(w.yaw_rad) - r.yaw_rad,
                                                2.0 * 3.14159265358979323846)) *
                       180.0 / 3.14159265358979323846;
      e.worst_m[k] = std::max(e.worst_m[k], e.final_m[k]);
      e.worst_deg[k] = std::max(e.worst_deg[k], e.final_deg[k]);
    }
  }
  e.ok = true;
  return e;
}

// The median of `v` (NaN when empty).
double median(std::vector<double> v) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// A configuration text with `key = value` in [table]: the user's own setting of it stays;
// otherwise it goes into the user's [table] (TOML defines a table once) or a new one.
std::string with_key(std::string text, const char* table, const char* key, const char* value) {
  const std::string head = std::string("[") + table + "]\n";
  std::size_t at = text.find(head);
  while (at != std::string::npos && at != 0 && text[at - 1] != '\n') at = text.find(head, at + 1);
  const std::string line = std::string(key) + " = " + value + "\n";
  if (at == std::string::npos) return text + head + line;
  const std::size_t body = at + head.size();
  std::size_t end = text.find("\n[", body - 1);
  end = end == std::string::npos ? text.size() : end + 1;
  for (std::size_t l = body; l < end;) {
    const std::size_t eol = std::min(text.find('\n', l), end);
    const std::string k = text.substr(l, eol - l);
    const std::size_t eq = k.find('=');
    std::string name = k.substr(0, eq == std::string::npos ? 0 : eq);
    while (!name.empty() && (name.back() == ' ' || name.back() == '\t')) name.pop_back();
    if (name == key) return text;
    l = eol + 1;
  }
  text.insert(body, line);
  return text;
}

// The map the firmware wrote (--map PREFIX: PGM + map_server YAML) against the world: occupied
// cells, and how many lie more than kObstacleOffM from any true surface in the robot's height.
struct MapCheck {
  bool ok = false;
  std::size_t occupied = 0;
  std::size_t off = 0;
};

MapCheck check_map(const std::string& prefix, const core::Pose2& origin, float height_m) {
  MapCheck out;
  const std::string yaml = read_file(prefix + ".yaml");
  const std::string pgm = read_file(prefix + ".pgm");
  double cell = 0, ox = 0, oy = 0;
  const std::size_t r = yaml.find("resolution: ");
  const std::size_t o = yaml.find("origin: [");
  if (r == std::string::npos || o == std::string::npos ||
      std::sscanf(yaml.c_str() + r, "resolution: %lf", &cell) != 1 ||
      std::sscanf(yaml.c_str() + o, "origin: [%lf, %lf", &ox, &oy) != 2 || cell <= 0) {
    return out;
  }
  int width = 0, height = 0, maxval = 0, header = 0;
  if (std::sscanf(pgm.c_str(), "P5\n%d %d\n%d\n%n", &width, &height, &maxval, &header) != 3 ||
      width <= 0 || height <= 0 ||
      pgm.size() != static_cast<std::size_t>(header) + static_cast<std::size_t>(width * height)) {
    return out;
  }
  for (int row = 0; row < height; ++row) {
    for (int col = 0; col < width; ++col) {
      if (static_cast<unsigned char>(pgm[static_cast<std::size_t>(header + row * width + col)]) !=
          0) {
        continue;
      }
      ++out.occupied;
      const core::Point2 p{static_cast<float>(ox + (col + 0.5) * cell),
                           static_cast<float>(oy + (height - 1 - row + 0.5) * cell)};
      const core::Point2 w = core::to_world(origin, p);
      out.off += disc_clearance_m(g_world, w.x_m, w.y_m, 0.0F, height_m) >
                         static_cast<float>(kObstacleOffM)
                     ? 1U
                     : 0U;
    }
  }
  out.ok = true;
  return out;
}

// One firmware run: a world of a set, a seed and a planner.
struct Run {
  std::string set;    // "shipped" or "tests"
  std::string world;  // its path in the repository
  std::string name;   // its file name without .sdf
  std::string path;   // where it is read from
  long seed = 1;
  std::string planner;  // "thesis" or "frontier"
  std::string dir;      // the run's outputs
  int exit_code = -1;
  bool timed_out = false;
  double cpu_s = 0.0;
  double wall_s = 0.0;
};

// Per set and planner, over its runs.
struct Tally {
  std::size_t runs = 0;
  std::size_t found = 0;
  std::size_t contacts = 0;
  double spl_sum = 0.0;
  double found_sim_s = 0.0;
  std::vector<double> est_final_m, est_final_deg, odo_final_m, odo_final_deg, register_ms;
  std::size_t within_target = 0;  // estimate within 0.05 m and 2 deg of the truth at the end
};

std::vector<long> seed_list() {
  std::vector<long> seeds;
  const char* list = std::getenv("BOTICELLI_MISSION_SEEDS");
  if (list == nullptr || *list == '\0') {
    const long one = env_long("BOTICELLI_MISSION_SEED", 0);
    if (one > 0) return {one};
    return {1, 2, 3};
  }
  const char* p = list;
  while (*p != '\0') {
    char* end = nullptr;
    const long v = std::strtol(p, &end, 10);
    if (end == p) break;
    if (v > 0) seeds.push_back(v);
    p = *end == ',' ? end + 1 : end;
  }
  return seeds.empty() ? std::vector<long>{1} : seeds;
}

// `localization`: the simulator's realistic setting and every look registered, unless the
// user's configuration (BOTICELLI_MISSION_CONFIG) sets either.
int run(bool localization) {
  g_suite = localization ? kLocalizationSuite : kMissionSuite;
  const std::string bin_dir = own_directory();
  const std::string firmware_bin = bin_dir + "/boticelli";
  if (::access(firmware_bin.c_str(), X_OK) != 0) {
    std::fprintf(stderr, "%s: no firmware binary at %s (build the 'boticelli' target)\n", g_suite,
                 firmware_bin.c_str());
    return 1;
  }
  const long max_cycles = env_long("BOTICELLI_MISSION_CYCLES", 60);
  const std::vector<long> seeds = seed_list();
  const double timeout_s = static_cast<double>(env_long("BOTICELLI_MISSION_TIMEOUT_S", 900));
  const long jobs = env_long("BOTICELLI_MISSION_JOBS",
                             std::max(1L, static_cast<long>(std::thread::hardware_concurrency())));
  const bool keep = std::getenv("BOTICELLI_MISSION_KEEP") != nullptr;
  const firmware::BoardConfig config = boards::sim::make_config();
  const std::string default_planner = config.thesis_planner ? "thesis" : "frontier";
  std::vector<std::string> planners;
  {
    const char* list = std::getenv("BOTICELLI_MISSION_PLANNERS");
    for (const char* p : {"thesis", "frontier"}) {
      if ((list == nullptr || *list == '\0') ? default_planner == p : listed(list, p)) {
        planners.emplace_back(p);
      }
    }
    if (planners.empty()) {
      std::fprintf(stderr, "%s: BOTICELLI_MISSION_PLANNERS lists neither thesis nor frontier\n",
                   g_suite);
      return 1;
    }
  }

  char tmp_template[] = "/tmp/boticelli-mission-XXXXXX";
  const char* tmp = ::mkdtemp(tmp_template);
  if (tmp == nullptr) {
    std::fprintf(stderr, "%s: cannot create a temporary directory: %s\n", g_suite,
                 std::strerror(errno));
    return 1;
  }
  // BOTICELLI_MISSION_CONFIG: a configuration file of the user's, whose keys every run takes
  // too (without `thesis_planner`: the planner knob decides that).
  std::string extra;
  if (const char* path = std::getenv("BOTICELLI_MISSION_CONFIG"); path != nullptr && *path) {
    FILE* in = std::fopen(path, "r");
    if (in == nullptr) {
      std::fprintf(stderr, "%s: cannot read BOTICELLI_MISSION_CONFIG %s: %s\n", g_suite, path,
                   std::strerror(errno));
      return 1;
    }
    char chunk[4096];
    for (std::size_t n = 0; (n = std::fread(chunk, 1, sizeof chunk, in)) > 0;)
      extra.append(chunk, n);
    std::fclose(in);
    if (!extra.empty() && extra.back() != '\n') extra += '\n';
  }
  for (const std::string& planner : planners) {
    const std::string conf = std::string(tmp) + "/" + planner + ".conf";
    FILE* f = std::fopen(conf.c_str(), "w");
    if (f == nullptr) {
      std::fprintf(stderr, "%s: cannot write %s\n", g_suite, conf.c_str());
      return 1;
    }
    // The planner knob decides the planner, whatever the user's file says.
    std::string text = extra;
    for (std::size_t at = text.find("thesis_planner"); at != std::string::npos;
         at = text.find("thesis_planner", at + 1)) {
      if (at == 0 || text[at - 1] == '\n') text.insert(at, "# ");
    }
    text = with_key(text, "mission", "thesis_planner", planner == "thesis" ? "true" : "false");
    if (localization) {
      text = with_key(text, "sim", "realism", "\"realistic\"");
      text = with_key(text, "mission", "register_looks", "true");
    }
    std::fputs(text.c_str(), f);
    std::fclose(f);
  }

  // The worlds: both sets, or the one folder BOTICELLI_MISSION_WORLDS_DIR names.
  struct Set {
    const char* name;
    std::string dir;
    std::string prefix;  // the folder's path in the repository
  };
  std::vector<Set> sets;
  if (const char* d = std::getenv("BOTICELLI_MISSION_WORLDS_DIR"); d != nullptr && *d != '\0') {
    sets.push_back({"custom", d, d});
  } else {
    sets.push_back({"shipped", BOTICELLI_WORLDS_DIR, "boards/sim/worlds"});
    sets.push_back({"tests", BOTICELLI_TEST_WORLDS_DIR, "tests/worlds"});
  }
  std::vector<Run> runs;
  std::vector<std::string> listed_anywhere;  // what the filter found in some set
  for (const Set& set : sets) {
    for (const std::string& name :
         world_names(set.dir, "BOTICELLI_MISSION_WORLDS", g_suite, false)) {
      listed_anywhere.push_back(name);
      const std::string path = set.dir + "/" + name + ".sdf";
      char error[256] = "";
      if (!hal::sim::load_world(path.c_str(), g_world, error, sizeof error)) {
        std::fprintf(stderr, "%s: %s\n", g_suite, error);
        continue;
      }
      bool has_target = false;
      for (std::size_t i = 0; i < g_world.surface_count; ++i) {
        has_target = has_target || g_world.surfaces[i].target_face != hal::sim::kNoFace;
      }
      if (!has_target) {
        JsonLine(g_suite, name.c_str())
            .text("world", path.c_str())
            .text("skipped", "no target")
            .emit();
        continue;
      }
      for (const std::string& planner : planners) {
        for (const long seed : seeds) {
          Run r;
          r.set = set.name;
          r.world = set.prefix + "/" + name + ".sdf";
          r.name = name;
          r.path = path;
          r.seed = seed;
          r.planner = planner;
          r.dir = std::string(tmp) + "/" + set.name + "-" + name + "-" + planner + "-" +
                  std::to_string(seed);
          runs.push_back(r);
        }
      }
    }
  }

  // A listed world in no set is a typing error worth a word (one set lacking it is not).
  if (const char* only = std::getenv("BOTICELLI_MISSION_WORLDS");
      only != nullptr && *only != '\0') {
    std::string list = only;
    std::size_t at = 0;
    while (at <= list.size()) {
      const std::size_t comma = std::min(list.find(',', at), list.size());
      std::string item = list.substr(at, comma - at);
      if (item.size() > 4 && item.compare(item.size() - 4, 4, ".sdf") == 0)
        item.resize(item.size() - 4);
      if (!item.empty() && std::find(listed_anywhere.begin(), listed_anywhere.end(), item) ==
                               listed_anywhere.end()) {
        std::fprintf(stderr, "%s: no world '%s' in any set\n", g_suite, item.c_str());
      }
      at = comma + 1;
    }
  }

  // The runs, `jobs` at a time (each a process; the host's cores are the limit).
  std::atomic<std::size_t> next{0};
  const auto worker = [&]() {
    for (std::size_t i = next++; i < runs.size(); i = next++) {
      Run& r = runs[i];
      ::mkdir(r.dir.c_str(), 0755);
      const std::vector<std::string> args = {firmware_bin,
                                             "--world",
                                             r.path,
                                             "--seed",
                                             std::to_string(r.seed),
                                             "--max-cycles",
                                             std::to_string(max_cycles),
                                             "--config",
                                             std::string(tmp) + "/" + r.planner + ".conf",
                                             "--trace",
                                             r.dir + "/trace.csv",
                                             "--map",
                                             r.dir + "/map",
                                             "--console",
                                             "stdio",
                                             "--state",
                                             r.dir + "/state"};
      const double t0 = wall_s();
      r.exit_code = run_firmware(args, r.dir + "/console.txt", r.dir + "/stderr.txt", timeout_s,
                                 r.timed_out, r.cpu_s);
      r.wall_s = wall_s() - t0;
    }
  };
  {
    std::vector<std::thread> threads;
    for (long j = 0; j < std::min<long>(jobs, static_cast<long>(runs.size())); ++j) {
      threads.emplace_back(worker);
    }
    for (std::thread& t : threads) t.join();
  }

  std::vector<std::pair<std::string, Tally>> tallies;  // "set planner" → tally
  for (const Run& r : runs) {
    char error[256] = "";
    if (!hal::sim::load_world(r.path.c_str(), g_world, error, sizeof error)) continue;
    const MissionLine m = parse_output(r.dir + "/console.txt");

    // The trace against the world's geometry (true poses; the robot's cylinder).
    std::vector<hal::sim::TraceRow> rows;
    std::string trace_error;
    hal::sim::TraceCheck check{};
    const bool trace_ok = hal::sim::read_trace((r.dir + "/trace.csv").c_str(), rows, trace_error);
    if (trace_ok) {
      check = hal::sim::check_trace(g_world, rows, config.robot_radius_m, config.robot_height_m);
    } else {
      std::fprintf(stderr, "%s: %s: %s\n", g_suite, r.world.c_str(), trace_error.c_str());
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
    const double compute_s = m.look_s + m.think_s + m.plan_s;
    const ModelSize size = model_size(r.dir + "/state");
    core::Pose2 origin{};
    MapCheck map_check{};
    if (trace_ok && mission_frame(rows, origin)) {
      map_check = check_map(r.dir + "/map", origin, config.robot_height_m);
    }
    const PoseErrors pose = trace_ok ? pose_errors(rows) : PoseErrors{};
    const double register_ms = m.registered > 0.0 ? 1e3 * m.register_s / m.registered
                                                  : std::numeric_limits<double>::quiet_NaN();
    const double free_m2 = field(m.map_line, "free_m2");

    const std::string key = r.set + " " + r.planner;
    auto it =
        std::find_if(tallies.begin(), tallies.end(), [&](const auto& t) { return t.first == key; });
    if (it == tallies.end()) {
      tallies.emplace_back(key, Tally{});
      it = tallies.end() - 1;
    }
    Tally& t = it->second;
    ++t.runs;
    t.found += success ? 1U : 0U;
    t.contacts += trace_ok ? check.collisions : 1U;
    t.spl_sum += spl;
    t.found_sim_s += success ? m.sim_time_s : 0.0;
    if (pose.ok) {
      t.est_final_m.push_back(pose.final_m[0]);
      t.est_final_deg.push_back(pose.final_deg[0]);
      t.odo_final_m.push_back(pose.final_m[1]);
      t.odo_final_deg.push_back(pose.final_deg[1]);
      t.within_target += pose.final_m[0] <= 0.05 && pose.final_deg[0] <= 2.0 ? 1U : 0U;
    }
    if (std::isfinite(register_ms)) t.register_ms.push_back(register_ms);

    JsonLine line(g_suite, r.name.c_str());
    line.text("world", r.world.c_str())
        .text("set", r.set.c_str())
        .integer("seed", r.seed)
        .text("planner", r.planner.c_str())
        .flag("default", r.planner == default_planner)
        .text("result", m.result.c_str())
        .text("end_reason", m.end_reason.c_str())
        .integer("exit_code", r.exit_code)
        .flag("timed_out", r.timed_out)
        .integer("cycles", m.cycles)
        .num("path_length_m", path)
        .num("shortest_m", shortest)
        .num("spl", spl)
        .num("sim_time_s", m.sim_time_s)
        .num("wall_time_s", r.wall_s)
        .num("firmware_wall_time_s", m.wall_time_s)
        .num("process_cpu_s", r.cpu_s)
        .integer("collisions", trace_ok ? static_cast<std::int64_t>(check.collisions) : -1)
        .integer("firmware_collisions", m.collisions)
        .num("min_clearance_m",
             trace_ok ? check.min_clearance_m : std::numeric_limits<double>::quiet_NaN())
        .num("max_trace_gap_s",
             trace_ok ? check.max_gap_s : std::numeric_limits<double>::quiet_NaN())
        .integer("trace_rows", static_cast<std::int64_t>(check.rows))
        .integer("reversals",
                 trace_ok ? static_cast<std::int64_t>(hal::sim::count_reversals(rows)) : -1)
        .num("target_error_m", m.target_error_m)
        .num("map_bytes", field(m.map_line, "grid_bytes"))
        .num("map_free_m2", free_m2)
        .num("path_per_m2_seen",
             free_m2 > 0.0 ? path / free_m2 : std::numeric_limits<double>::quiet_NaN())
        .integer("map_occupied_cells",
                 map_check.ok ? static_cast<std::int64_t>(map_check.occupied) : -1)
        .num("map_obstacles_off_share",
             map_check.ok && map_check.occupied > 0
                 ? static_cast<double>(map_check.off) / static_cast<double>(map_check.occupied)
                 : std::numeric_limits<double>::quiet_NaN())
        .num("blacklisted", field(m.map_line, "blacklisted"))
        .num("look_cpu_s", m.look_s)
        .num("think_cpu_s", m.think_s)
        .num("plan_cpu_s", m.plan_s)
        .num("compute_share_of_sim_time", m.sim_time_s > 0.0
                                              ? compute_s / m.sim_time_s
                                              : std::numeric_limits<double>::quiet_NaN())
        .num("wall_per_sim_s", m.sim_time_s > 0.0 ? r.wall_s / m.sim_time_s
                                                  : std::numeric_limits<double>::quiet_NaN());
    if (size.ok) {
      line.integer("model_pieces", static_cast<std::int64_t>(size.pieces))
          .integer("model_bytes", static_cast<std::int64_t>(size.binary_bytes))
          .integer("model_text_bytes", static_cast<std::int64_t>(size.text_bytes))
          .integer("map_points", static_cast<std::int64_t>(size.points))
          .integer("map_points_bytes", static_cast<std::int64_t>(size.points_bytes));
    }
    line.integer("grid_0_1m_bytes", static_cast<std::int64_t>(grid_bytes(g_world)));
    // The pose: the estimate's and the odometry's error against the truth, at the end and at
    // worst, per metre driven; registration CPU per registered look; the base's calibration.
    if (pose.ok) {
      const char* kinds[2] = {"est", "odo"};
      for (int k = 0; k < 2; ++k) {
        const std::string kind = kinds[k];
        line.num((kind + "_final_m").c_str(), pose.final_m[k])
            .num((kind + "_final_deg").c_str(), pose.final_deg[k])
            .num((kind + "_worst_m").c_str(), pose.worst_m[k])
            .num((kind + "_worst_deg").c_str(), pose.worst_deg[k])
            .num((kind + "_final_m_per_m").c_str(),
                 pose.path_m > 0.0 ? pose.final_m[k] / pose.path_m : 0.0)
            .num((kind + "_final_deg_per_m").c_str(),
                 pose.path_m > 0.0 ? pose.final_deg[k] / pose.path_m : 0.0);
      }
      line.num("true_path_m", pose.path_m);
    }
    line.num("registered_looks", m.registered).num("register_ms_per_look", register_ms);
    if (field(m.calibration_line, "valid") == 1.0) {
      // "odometry_track_scale=A sd=B odometry_diameter_ratio=C sd=D"
      const std::size_t ratio = m.calibration_line.find(" odometry_diameter_ratio=");
      line.num("calibrated_track_scale", field(m.calibration_line, "odometry_track_scale"))
          .num("calibrated_track_scale_sd", field(m.calibration_line.substr(0, ratio), "sd"))
          .num("calibrated_diameter_ratio", field(m.calibration_line, "odometry_diameter_ratio"))
          .num("calibrated_diameter_ratio_sd", ratio == std::string::npos
                                                   ? std::numeric_limits<double>::quiet_NaN()
                                                   : field(m.calibration_line.substr(ratio), "sd"));
    }
    for (const char* unit : kUnitNames) {
      line.num((std::string("longest_") + unit + "_ms").c_str(), field(m.longest_line, unit));
    }
    line.emit();
    if (!m.found_line || !m.found_cpu || m.map_line.empty()) {
      std::fprintf(stderr, "%s: %s seed %ld %s: %s%s%s (console output in %s)\n", g_suite,
                   r.world.c_str(), r.seed, r.planner.c_str(),
                   m.found_line ? "" : "no MISSION line ", m.found_cpu ? "" : "no cpu line ",
                   m.map_line.empty() ? "no map line" : "", (r.dir + "/console.txt").c_str());
    }
    if (!keep) remove_tree(r.dir);
  }
  if (!keep) {
    for (const std::string& planner : planners) {
      ::unlink((std::string(tmp) + "/" + planner + ".conf").c_str());
    }
    ::rmdir(tmp);
  } else {
    std::fprintf(stderr, "%s: outputs kept in %s\n", g_suite, tmp);
  }
  std::string seed_text;
  for (const long s : seeds) seed_text += (seed_text.empty() ? "" : ",") + std::to_string(s);
  for (const auto& [key, t] : tallies) {
    const std::size_t space = key.find(' ');
    const std::string set = key.substr(0, space);
    const std::string planner = key.substr(space + 1);
    JsonLine(g_suite, "summary")
        .text("set", set.c_str())
        .text("planner", planner.c_str())
        .flag("default", planner == default_planner)
        .text("seeds", seed_text.c_str())
        .integer("runs", static_cast<std::int64_t>(t.runs))
        .integer("found", static_cast<std::int64_t>(t.found))
        .integer("contacts", static_cast<std::int64_t>(t.contacts))
        .num("mean_spl", t.runs > 0 ? t.spl_sum / static_cast<double>(t.runs) : 0.0)
        .num("mean_sim_time_to_find_s", t.found > 0 ? t.found_sim_s / static_cast<double>(t.found)
                                                    : std::numeric_limits<double>::quiet_NaN())
        .integer("max_cycles", max_cycles)
        .integer("est_within_5cm_2deg", static_cast<std::int64_t>(t.within_target))
        .num("est_final_m_median", median(t.est_final_m))
        .num("est_final_deg_median", median(t.est_final_deg))
        .num("est_final_m_max", t.est_final_m.empty()
                                    ? std::numeric_limits<double>::quiet_NaN()
                                    : *std::max_element(t.est_final_m.begin(), t.est_final_m.end()))
        .num("odo_final_m_median", median(t.odo_final_m))
        .num("odo_final_deg_median", median(t.odo_final_deg))
        .num("register_ms_per_look_max",
             t.register_ms.empty() ? std::numeric_limits<double>::quiet_NaN()
                                   : *std::max_element(t.register_ms.begin(), t.register_ms.end()))
        .emit();
  }
  return 0;
}

int run_mission() {
  return run(false);
}
int run_localization() {
  return run(true);
}

[[maybe_unused]] const bool g_registered = register_suite(
    {kMissionSuite, "firmware binary on every shipped and test world, per seed and planner",
     &run_mission});
[[maybe_unused]] const bool g_registered_localization = register_suite(
    {kLocalizationSuite,
     "the mission suite with the realistic sim and every look registered: the pose estimate "
     "and the raw odometry against the truth",
     &run_localization});

}  // namespace
}  // namespace boticelli::bench
