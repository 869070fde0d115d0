// Localization end to end on the sim board with a realistic base ([sim] realism): the trace's
// estimate columns are the firmware's pose, and registering every look keeps that pose near
// the truth while the raw odometry drifts.
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "algo/core/angles.h"
#include "algo/core/geometry.h"
#include "firmware/app/firmware_main.h"
#include "mission_runner.h"
#include "sim_board.h"

#include "CppUTest/TestHarness.h"
// (after TestHarness.h, which it needs)
#include "CppUTest/MemoryLeakWarningPlugin.h"

using boticelli::core::Pose2;

using boticelli::test::slurp;

namespace {

boticelli::boards::sim::SimBoard g_board;

struct Row {
  double t_s = 0.0;
  Pose2 truth;  // world frame
  Pose2 odo;    // mission frame
  Pose2 est;    // mission frame
};

struct Run {
  std::string output;  // the console's stdout (TLM lines, the MISSION line)
  std::vector<Row> rows;
};

// The firmware on `world` with `seed` and a configuration file holding `sim_table`, for
// `cycles` cycles: the console's output and the trace.
Run run_mission(const char* world, const char* seed, const char* sim_table, const char* cycles) {
  char dir_template[] = "/tmp/boticelli-localization-XXXXXX";
  const std::string dir = mkdtemp(dir_template);
  const std::string trace = dir + "/trace.csv";
  const std::string out = dir + "/stdout.txt";
  const std::string conf = dir + "/sim.conf";
  {
    std::ofstream f(conf);
    f << sim_table;
  }
  const std::string path = std::string(BOTICELLI_WORLDS_DIR) + "/" + world + ".sdf";
  g_board.settings() = boticelli::boards::sim::make_settings(g_board.config(), 1);
  std::vector<const char*> argv = {"boticelli",  "--world",      path.c_str(), "--seed", seed,
                                   "--trace",    trace.c_str(),  "--console",  "stdio",  "--config",
                                   conf.c_str(), "--max-cycles", cycles};
  (void)boticelli::test::run_captured(g_board, argv, out);
  Run run;
  run.output = slurp(out);
  std::stringstream lines(slurp(trace));
  std::string line;
  std::getline(lines, line);
  CHECK_TEXT(
      line.find(",odo_x_m,odo_y_m,odo_yaw_rad,est_x_m,est_y_m,est_yaw_rad") != std::string::npos,
      line.c_str());
  while (std::getline(lines, line)) {
    std::vector<double> v;
    std::stringstream fields(line);
    std::string field;
    while (std::getline(fields, field, ',')) v.push_back(std::atof(field.c_str()));
    if (v.size() < 13) continue;
    const auto pose = [&v](std::size_t i) {
      return Pose2{static_cast<float>(v[i]), static_cast<float>(v[i + 1]),
                   static_cast<float>(v[i + 2])};
    };
    run.rows.push_back({v[0], pose(1), pose(7), pose(10)});
  }
  std::remove(out.c_str());
  std::remove(trace.c_str());
  std::remove(conf.c_str());
  rmdir(dir.c_str());
  return run;
}

// How far a mission-frame pose lies from the truth: position [m] and heading [rad].
struct Error {
  double m = 0.0;
  double rad = 0.0;
};
Error error_of(const Row& start, const Pose2& mission, const Pose2& truth) {
  const Pose2 w = boticelli::core::compose(start.truth, mission);
  return {
      std::hypot(static_cast<double>(w.x_m - truth.x_m), static_cast<double>(w.y_m - truth.y_m)),
      std::fabs(static_cast<double>(boticelli::core::wrap_pi(w.yaw_rad - truth.yaw_rad)))};
}

// The realistic base with the camera and rig as configured: these tests are of the pose
// estimate against the base's errors (the realistic optics' range errors are the look bench's).
constexpr const char* kRealistic =
    "[sim]\nrealism = \"realistic\"\nlens_k1_error = 0\nlens_k2_error = 0\n"
    "lens_p1_error = 0\nlens_p2_error = 0\nfocal_scale = 1\nprincipal_error_px = 0\n"
    "lever_error_m = 0\nptu_backlash_rad = 0\nchroma_noise = 0\nexposure_jitter = 0\n"
    "[mission]\nregister_looks = true\n";

}  // namespace

// The board allocates its world and textures at init and keeps them (static storage).
TEST_GROUP(MissionLocalization){
    void setup() override{MemoryLeakWarningPlugin::saveAndDisableNewDeleteOverloads();
}
void teardown() override {
  MemoryLeakWarningPlugin::restoreNewDeleteOverloads();
}
}
;

TEST(MissionLocalization, TheTracesEstimateColumnsAreTheFirmwaresPose) {
  const Run r = run_mission("thesis_room", "1", kRealistic, "6");
  CHECK(r.rows.size() > 100);
  // Every TLM line's pose (the console's view of the mission's pose) is in the est_ columns
  // of a trace row; and somewhere the odometry is not the estimate (a look was registered).
  std::stringstream lines(r.output);
  std::string line;
  int tlm = 0;
  double most_apart_m = 0.0;
  while (std::getline(lines, line)) {
    if (line.rfind("TLM ", 0) != 0) continue;
    const auto value = [&line](const char* key) {
      const std::size_t at = line.find(std::string(" ") + key + "=");
      return std::atof(line.c_str() + at + std::strlen(key) + 2);
    };
    const double x = value("x_m");
    const double y = value("y_m");
    const double yaw = value("yaw_rad");
    bool seen = false;
    for (const Row& row : r.rows) {
      const auto near = [](float column, double expected) {
        return std::fabs(static_cast<double>(column) - expected) < 0.0015;
      };
      seen = seen || (near(row.est.x_m, x) && near(row.est.y_m, y) && near(row.est.yaw_rad, yaw));
    }
    CHECK_TEXT(seen, line.c_str());
    ++tlm;
  }
  for (const Row& row : r.rows) {
    most_apart_m = std::max(
        most_apart_m,
        static_cast<double>(std::hypot(row.est.x_m - row.odo.x_m, row.est.y_m - row.odo.y_m)));
  }
  CHECK(tlm > 10);
  CHECK_TEXT(most_apart_m > 0.005, "the estimate left the odometry");
}

TEST(MissionLocalization, WithARealisticBaseTheEstimateStaysNearTheTruthWhileOdometryDrifts) {
  const Run r = run_mission("thesis_room", "1", kRealistic, "45");
  CHECK(r.rows.size() > 100);
  const Row& start = r.rows.front();
  Error est_worst;
  Error odo_final;
  Error est_final;
  for (const Row& row : r.rows) {
    const Error e = error_of(start, row.est, row.truth);
    est_worst.m = std::max(est_worst.m, e.m);
    est_worst.rad = std::max(est_worst.rad, e.rad);
    est_final = e;
    odo_final = error_of(start, row.odo, row.truth);
  }
  char why[256];
  std::snprintf(why, sizeof why,
                "estimate final %.3f m %.2f deg, worst %.3f m %.2f deg; odometry final %.3f m "
                "%.2f deg",
                est_final.m, est_final.rad * 57.3, est_worst.m, est_worst.rad * 57.3, odo_final.m,
                odo_final.rad * 57.3);
  // Measured (docs/benchmarks.md, "localization"): the estimate ends 0.19 m and 4.6° from the
  // truth (worst 0.19 m, 8.8°), the odometry 0.78 m and 11.4°. The bounds guard that; the
  // issue's target (0.05 m, 2°) is not reached yet.
  STRCMP_CONTAINS("MISSION result=found", r.output.c_str());
  CHECK_TEXT(est_final.m < 0.25 && est_final.rad < 0.1, why);
  CHECK_TEXT(est_worst.m < 0.3 && est_worst.rad < 0.17, why);
  CHECK_TEXT(odo_final.m > 3.0 * est_final.m, why);
  // The registrations calibrate the base: the realistic base's track is 1.01 of the
  // configured one and its right wheel 0.9975/1.0025 of its left (boards/sim/board_config.h).
  const std::size_t at = r.output.find("mission base_calibration valid=1 ");
  CHECK_TEXT(at != std::string::npos, "the end of the run logs a valid base calibration");
  const std::string line = r.output.substr(at, r.output.find('\n', at) - at);
  double scale = 0.0;
  double scale_sd = 0.0;
  double ratio = 0.0;
  double ratio_sd = 0.0;
  CHECK_TEXT(std::sscanf(line.c_str() + line.find("odometry_track_scale="),
                         "odometry_track_scale=%lf sd=%lf odometry_diameter_ratio=%lf sd=%lf",
                         &scale, &scale_sd, &ratio, &ratio_sd) == 4,
             line.c_str());
  CHECK_TEXT(scale_sd > 0.0 && scale_sd < 0.01 && ratio_sd > 0.0 && ratio_sd < 0.01, line.c_str());
  // Measured: 1.0108 ± 0.0036 and 0.9983 ± 0.0037. One run tells the track's 1 % (three of
  // its standard errors), not the wheels' 0.5 % (docs/benchmarks.md pools several runs).
  CHECK_TEXT(std::fabs(scale - 1.01) < 3.0 * scale_sd, line.c_str());
  CHECK_TEXT(scale - 1.0 > 2.0 * scale_sd, line.c_str());
  CHECK_TEXT(std::fabs(ratio - 0.9975 / 1.0025) < 3.0 * ratio_sd, line.c_str());
}
