// Tests of the mission state file: round trip, strict rejection of corrupt files, atomic saves
// under SIGKILL, resume.
#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <chrono>
#include <cerrno>
#include <condition_variable>
#include <cstdint>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <thread>
#include <tuple>

#include "firmware/state/mission_state.h"
#include "firmware/state/persistence.h"
#include "firmware/state/state_saver.h"

#include "child_process.h"
#include "test_files.h"
#include "CppUTest/TestHarness.h"

using namespace boticelli::firmware;
using boticelli::core::Point2;

namespace {

using boticelli::test::read_file;
using boticelli::test::temp_dir;
using boticelli::test::write_file;

// Large buffers live in static storage, not on the stack.
MissionState g_a;
MissionState g_b;
StateStore g_store;
char g_file[kMaxStateFileBytes];

// The state a mission would have after `cycle` cycles: every field derived from the cycle,
// so a loaded state can be checked against the cycle it claims.
void make_state(std::uint64_t cycle, MissionState& s) {
  s.clear();
  s.cycle = cycle;
  s.seed = 42;
  s.pose = {0.1F * static_cast<float>(cycle), -0.37F, 0.001F * static_cast<float>(cycle)};
  s.pose_time_ms = cycle % 4 == 0 ? 0 : 1700000000000LL + static_cast<std::int64_t>(cycle);
  s.grid_cell_m = 0.05F;
  for (std::size_t i = 0; i < cycle % 9; ++i) {
    boticelli::worldmap::SavedTile t;
    t.tx = static_cast<std::int16_t>(i * 7 % 64);
    t.ty = static_cast<std::int16_t>(63 - i);
    for (std::size_t k = 0; k < t.cells.size(); ++k) {
      t.cells[k] = static_cast<std::int8_t>(static_cast<int>((k * 13 + cycle) % 121) - 60);
    }
    (void)s.grid.push_back(t);
  }
  s.wheels_known = cycle % 2 == 1;
  s.wheel_left_m = 1234.5678901234567 + 0.1 * static_cast<double>(cycle);
  s.wheel_right_m = -0.1 / 3.0 * static_cast<double>(cycle);
  s.stereo_bias_per_m = 0.0473F - 0.001F * static_cast<float>(cycle % 97);
  s.has_goal = cycle % 3 == 0;
  s.goal = {1.0F / 3.0F, 2.5e-7F * static_cast<float>(cycle)};
  s.goal_height_m = 0.01F * static_cast<float>(cycle % 40);
  const std::size_t n_obs = (cycle * 37) % MissionState::kMaxObstaclePoints;
  for (std::size_t i = 0; i < n_obs; ++i) {
    (void)s.obstacles.push_back({static_cast<float>(i) * 0.01F + 0.001F * static_cast<float>(cycle),
                                 -static_cast<float>(i) / 7.0F});
  }
  for (std::size_t i = 0; i < cycle % 50; ++i) {
    (void)s.exploration.push_back({static_cast<float>(i), static_cast<float>(cycle)});
  }
  std::string model = "VARIABLES 3\nOUTPUT 2\nLINEARFORMS " + std::to_string(cycle) + "\n";
  while (model.size() < 2000 + (cycle % 7) * 1000) model += "0.125 -0.5 1 0.25\n";
  model += "BLOCKS\nMIN 0 1\n";
  CHECK(s.set_model(model));
  for (std::uint64_t c = 1; c <= cycle && c <= 200; ++c) {
    s.add_log(c, "cycle " + std::to_string(c) + " done");
  }
  if (cycle % 5 == 0) s.set_end(MissionEnd::kNotFound, "nothing left to explore");
}

void remove_dir(const std::string& dir) {
  for (const char* name :
       {"/mission.state", "/mission.state.tmp", "/mission.state.a", "/mission.state.a.tmp",
        "/mission.state.b", "/mission.state.b.tmp", "/mission.state.1", "/mission.state.2",
        "/parameters.conf", "/parameters.conf.tmp"}) {
    unlink((dir + name).c_str());
  }
  rmdir(dir.c_str());
}

// A file body with its checksum line appended: a file that passes the CRC, so the body
// parser is what accepts or rejects it.
std::string with_crc(const std::string& body) {
  char line[32];
  std::snprintf(line, sizeof line, "crc32 %08x\n", crc32(body.data(), body.size()));
  return body + line;
}

}  // namespace

namespace {
// Polls `busy` every 10 ms for up to 5 s (the writer thread's work, which a test then checks).
template <typename Busy>
void wait_while(Busy busy) {
  for (int i = 0; i < 500 && busy(); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
}
}  // namespace

TEST_GROUP(Persistence) {
  std::string dir;
  char error[256] = "";
  void setup() override {
    dir = temp_dir("state");
  }
  void teardown() override {
    set_storage_fault_hook(nullptr, nullptr);  // a failed test may have left one
    remove_dir(dir);
  }
};

TEST_GROUP(MissionState){};

namespace {
// Copies g_a into g_b, changes one field of g_b and tells whether the two still compare
// equal, either way round.
template <typename Change>
bool equal_after(Change change) {
  g_b = g_a;
  change(g_b);
  const bool ab = g_a == g_b;
  CHECK_EQUAL(ab, g_b == g_a);
  return ab;
}
}  // namespace

TEST(MissionState, TwoStatesThatDifferInAnyOneFieldAreNotEqual) {
  make_state(15, g_a);  // a goal, obstacles, exploration points, a model, a log and an end
  CHECK(g_a.has_goal && g_a.obstacles.size() > 1 && g_a.exploration.size() > 1);
  CHECK(equal_after([](MissionState&) {}));
  CHECK_FALSE(equal_after([](MissionState& s) { s.end = MissionEnd::kFound; }));
  CHECK_FALSE(equal_after([](MissionState& s) { s.set_end(s.end, "another reason"); }));
  CHECK_FALSE(equal_after([](MissionState& s) { ++s.cycle; }));
  CHECK_FALSE(equal_after([](MissionState& s) { ++s.seed; }));
  CHECK_FALSE(equal_after([](MissionState& s) { s.pose.x_m += 0.5F; }));
  CHECK_FALSE(equal_after([](MissionState& s) { s.pose.y_m += 0.5F; }));
  CHECK_FALSE(equal_after([](MissionState& s) { s.pose.yaw_rad += 0.5F; }));
  CHECK_FALSE(equal_after([](MissionState& s) { ++s.pose_time_ms; }));
  CHECK_FALSE(equal_after([](MissionState& s) { s.has_goal = false; }));
  CHECK_FALSE(equal_after([](MissionState& s) { s.goal.x_m += 0.5F; }));
  CHECK_FALSE(equal_after([](MissionState& s) { s.goal.y_m += 0.5F; }));
  CHECK_FALSE(equal_after([](MissionState& s) { s.goal_height_m += 0.5F; }));
  CHECK_FALSE(equal_after([](MissionState& s) { s.obstacles.pop_back(); }));
  CHECK_FALSE(equal_after([](MissionState& s) { s.obstacles[1].x_m += 0.5F; }));
  CHECK_FALSE(equal_after([](MissionState& s) { s.obstacles[1].y_m += 0.5F; }));
  CHECK_FALSE(equal_after([](MissionState& s) { s.exploration.pop_back(); }));
  CHECK_FALSE(equal_after([](MissionState& s) { s.exploration[1].x_m += 0.5F; }));
  CHECK_FALSE(equal_after([](MissionState& s) { s.exploration[1].y_m += 0.5F; }));
  CHECK_FALSE(equal_after([](MissionState& s) { CHECK(s.set_model("VARIABLES 3\n")); }));
  CHECK_FALSE(equal_after([](MissionState& s) { s.log.pop_back(); }));
  CHECK_FALSE(equal_after([](MissionState& s) { ++s.log[2].cycle; }));
  CHECK_FALSE(equal_after([](MissionState& s) { s.log[2].text[0] = '#'; }));
  CHECK(g_a.wheels_known && g_a.grid.size() > 1);
  CHECK_FALSE(equal_after([](MissionState& s) { s.wheels_known = false; }));
  CHECK_FALSE(equal_after([](MissionState& s) { s.wheel_left_m += 0.5; }));
  CHECK_FALSE(equal_after([](MissionState& s) { s.wheel_right_m += 0.5; }));
  CHECK_FALSE(equal_after([](MissionState& s) { s.grid_cell_m = 0.1F; }));
  CHECK_FALSE(equal_after([](MissionState& s) { s.grid.pop_back(); }));
  CHECK_FALSE(equal_after([](MissionState& s) { ++s.grid[1].tx; }));
  CHECK_FALSE(equal_after([](MissionState& s) { ++s.grid[1].ty; }));
  CHECK_FALSE(equal_after([](MissionState& s) { ++s.grid[1].cells[200]; }));
  // Without a goal, where the goal would be does not count.
  g_a.has_goal = false;
  CHECK(equal_after([](MissionState& s) {
    s.goal.x_m += 0.5F;
    s.goal_height_m += 0.5F;
  }));
  // Without the wheel counters, what they would read does not count either.
  g_a.wheels_known = false;
  CHECK(equal_after([](MissionState& s) { s.wheel_left_m += 0.5; }));
}

TEST(MissionState, ClearingGivesTheStateOfANewMission) {
  make_state(15, g_a);
  for (std::size_t i = 0; i < MissionState::kMaxLogEntries; ++i) g_a.add_log(99, "more");
  CHECK(g_a.log_dropped > 0U);
  g_a.clear();
  static const MissionState fresh;
  CHECK(g_a == fresh);
  CHECK_EQUAL(0U, g_a.log_dropped);
  CHECK_EQUAL(0U, g_a.obstacles.size());
  STRCMP_EQUAL("", g_a.end_reason.data());
  CHECK_EQUAL(0, g_a.pose_time_ms);
}

TEST(MissionState, AFullLogDropsItsOldestLinesAndCountsThem) {
  g_a.clear();
  const std::size_t n = MissionState::kMaxLogEntries;
  for (std::size_t c = 1; c <= n + 2; ++c) g_a.add_log(c, "cycle " + std::to_string(c));
  CHECK_EQUAL(n, g_a.log.size());
  CHECK_EQUAL(2U, g_a.log_dropped);
  CHECK_EQUAL(3U, g_a.log[0].cycle);
  STRCMP_EQUAL("cycle 3", g_a.log[0].text.data());
  CHECK_EQUAL(n + 2, g_a.log[n - 1].cycle);
}

TEST(MissionState, TextIsCutToItsCapacityAndOnlyPrintableAsciiIsKept) {
  g_a.clear();
  const std::string longest(MissionLogEntry::kMaxTextBytes + 7, 'x');
  g_a.add_log(1, longest);
  CHECK_EQUAL(MissionLogEntry::kMaxTextBytes, g_a.log[0].view().size());
  const std::string one_short(MissionLogEntry::kMaxTextBytes - 1, 'y');
  g_a.add_log(1, one_short);
  STRCMP_EQUAL(one_short.c_str(), g_a.log[1].text.data());
  g_a.log.pop_back();
  // Space and tilde are the ends of printable ASCII; the unit separator and DEL lie outside.
  g_a.add_log(2, "\x1f \x7e\x7f");
  STRCMP_EQUAL("? ~?", g_a.log[1].text.data());
  g_a.set_end(MissionEnd::kAborted, longest);
  CHECK_EQUAL(MissionLogEntry::kMaxTextBytes, g_a.end_reason_text().size());
  g_a.set_end(MissionEnd::kAborted, "a\tb");
  STRCMP_EQUAL("a?b", g_a.end_reason.data());
}

// At the capacity's edges: a text of exactly the capacity is kept whole, one byte more is cut
// to the capacity, in the log and in the end's reason alike.
TEST(MissionState, ATextOfExactlyItsCapacityIsKeptWholeAndOneByteMoreIsCutToIt) {
  g_a.clear();
  const std::string exact(MissionLogEntry::kMaxTextBytes, 'e');
  const std::string one_more(MissionLogEntry::kMaxTextBytes + 1, 'm');
  g_a.add_log(1, one_more);
  g_a.add_log(2, exact);
  CHECK_EQUAL(std::string(MissionLogEntry::kMaxTextBytes, 'm'), std::string(g_a.log[0].view()));
  CHECK_EQUAL(exact, std::string(g_a.log[1].view()));
  g_a.set_end(MissionEnd::kAborted, one_more);
  CHECK_EQUAL(std::string(MissionLogEntry::kMaxTextBytes, 'm'), std::string(g_a.end_reason_text()));
  g_a.set_end(MissionEnd::kAborted, exact);
  CHECK_EQUAL(exact, std::string(g_a.end_reason_text()));
}

TEST(Persistence, ComputesTheStandardCrc32) {
  CHECK_EQUAL(0xCBF43926U, crc32("123456789", 9));
  CHECK_EQUAL(0U, crc32("", 0));
}

TEST(Persistence, EncodesAndDecodesEveryFieldExactly) {
  make_state(123, g_a);
  const std::size_t n = encode_state(g_a, g_file, sizeof g_file);
  CHECK(n > 0);
  const char* why = "";
  CHECK_TRUE_TEXT(decode_state({g_file, n}, g_b, &why), why);
  CHECK(g_a == g_b);
  CHECK(g_b.has_goal);
  CHECK_EQUAL(123U, g_b.log.size());
}

TEST(Persistence, HoldsAStateFilledToEveryCapacity) {
  g_a.clear();
  g_a.cycle = UINT64_MAX;
  g_a.pose = {-1e30F, 1e-30F, -3.14159274F};
  while (g_a.obstacles.push_back({-123456.789F, 1e-40F})) {  // a subnormal y
  }
  while (g_a.exploration.push_back({3.40282347e38F, -0.0F})) {
  }
  g_a.set_end(MissionEnd::kAborted, std::string(MissionLogEntry::kMaxTextBytes, '~'));
  CHECK(g_a.set_model(std::string(MissionState::kMaxModelBytes, 'M')));
  // One byte more, or a NUL inside, is refused and leaves the model as it was.
  CHECK_FALSE(g_a.set_model(std::string(MissionState::kMaxModelBytes + 1, 'X')));
  CHECK_FALSE(g_a.set_model(std::string_view("ab\0cd", 5)));
  CHECK_EQUAL(MissionState::kMaxModelBytes, g_a.model_text().size());
  CHECK_EQUAL('M', g_a.model_text().front());
  g_a.grid_cell_m = 0.05F;
  while (g_a.grid.size() < g_a.grid.capacity()) {
    boticelli::worldmap::SavedTile t;
    t.tx = static_cast<std::int16_t>(g_a.grid.size() % 64);
    t.ty = static_cast<std::int16_t>(g_a.grid.size() / 64);
    t.cells.fill(-60);  // the longest hex: every byte "c4"
    (void)g_a.grid.push_back(t);
  }
  g_a.wheels_known = true;
  g_a.wheel_left_m = -1.2345678901234567e300;
  g_a.wheel_right_m = 2.2250738585072014e-308;
  for (int i = 0; i < 500; ++i) g_a.add_log(static_cast<std::uint64_t>(i), std::string(200, '~'));
  CHECK_EQUAL(MissionState::kMaxLogEntries, g_a.log.size());
  CHECK_EQUAL(499U, g_a.log.back().cycle);
  const std::size_t n = encode_state(g_a, g_file, sizeof g_file);
  CHECK(n > 0);
  const char* why = "";
  CHECK_TRUE_TEXT(decode_state({g_file, n}, g_b, &why), why);
  CHECK(g_a == g_b);
}

// The encoder writes each line with its terminating NUL: a buffer of exactly the file's size
// is too small (nothing is returned), one byte more holds the same file.
TEST(Persistence, AStateIsEncodedOnlyIntoABufferLongerThanItsFile) {
  make_state(7, g_a);
  const std::size_t n = encode_state(g_a, g_file, sizeof g_file, 5);
  CHECK(n > 0);
  const std::string file(g_file, n);
  static char again[kMaxStateFileBytes];
  CHECK_EQUAL(0U, encode_state(g_a, again, n, 5));
  CHECK_EQUAL(n, encode_state(g_a, again, n + 1, 5));
  CHECK(file == std::string(again, n));
}

TEST(Persistence, RejectsEveryTruncationOfAFile) {
  make_state(5, g_a);
  const std::size_t n = encode_state(g_a, g_file, sizeof g_file);
  const char* why = "";
  for (std::size_t len = 0; len < n; len += (len < 200 || n - len < 200) ? 1 : 97) {
    CHECK_FALSE(decode_state({g_file, len}, g_b, &why));
    CHECK_EQUAL(0U, g_b.cycle);  // nothing half-loaded
    CHECK_EQUAL(0U, g_b.obstacles.size());
  }
}

TEST(Persistence, RejectsAnyFlippedByte) {
  make_state(9, g_a);
  const std::size_t n = encode_state(g_a, g_file, sizeof g_file);
  const char* why = "";
  std::uint32_t x = 7;
  for (int trial = 0; trial < 500; ++trial) {
    x = x * 1664525U + 1013904223U;
    const std::size_t at = x % n;
    const char saved = g_file[at];
    g_file[at] = static_cast<char>(saved ^ static_cast<char>(1 + (x >> 29)));
    CHECK_FALSE(decode_state({g_file, n}, g_b, &why));
    g_file[at] = saved;
  }
  CHECK(decode_state({g_file, n}, g_b, &why));
}

TEST(Persistence, RejectsAWellChecksummedFileThatBreaksTheFormat) {
  // A file whose CRC is right but whose content is not valid (as from a buggy writer).
  const char* why = "";
  const std::string head = "BOTICELLI-STATE 1\ncycle 3\nseed 1\npose 0 0 0\ngoal none\n";
  const std::string tail = "exploration 0\nmodel 0\n\nlog 0\nend\n";
  std::string f = with_crc(head + "obstacles 1\n1 2\n" + tail);
  CHECK_TRUE_TEXT(decode_state(f, g_b, &why), why);
  for (const std::string& body :
       {head + "obstacles 3000\n" + tail, head + "obstacles 1\n1 nan\n" + tail,
        head + "obstacles 1\n1 2 3\n" + tail, head + "obstacles 2\n1 2\n" + tail,
        head + "obstacles 1\n1 1e39\n" + tail,   // beyond a float: infinite
        head + "obstacles 1\n1 1.5.2\n" + tail,  // not all of it a number
        head + "obstacles 1\n1 -\n" + tail, head + "obstacles -1\n" + tail,
        std::string("BOTICELLI-STATE 2\n") + "cycle 3\n",
        "BOTICELLI-STATE 4" + head.substr(17) + "obstacles 0\n" + tail,
        // Version 3 has a sequence number and the mission's result.
        "BOTICELLI-STATE 3" + head.substr(17) + "obstacles 0\n" + tail,
        "BOTICELLI-STATE 3\nsequence 4\n" + head.substr(18) + "obstacles 0\n" + tail,
        "BOTICELLI-STATE 3\nsequence x\ncycle 3\nseed 1\nresult running\n" + head.substr(33) +
            "obstacles 0\n" + tail,
        "BOTICELLI-STATE 3\nsequence 4\ncycle 3\nseed 1\nresult won\n" + head.substr(33) +
            "obstacles 0\n" + tail,
        "BOTICELLI-STATE 3\nsequence 4\ncycle 3\nseed 1\nresult running late\n" + head.substr(33) +
            "obstacles 0\n" + tail,
        "BOTICELLI-STATE 3\nsequence 4\ncycle 3\nseed 1\nresult found \x1b[2J\n" + head.substr(33) +
            "obstacles 0\n" + tail,
        // Version 4 has the pose's time after the pose.
        "BOTICELLI-STATE 4\nsequence 4\ncycle 3\nseed 1\nresult running\n" + head.substr(33) +
            "obstacles 0\n" + tail,
        "BOTICELLI-STATE 4\nsequence 4\ncycle 3\nseed 1\nresult running\npose 0 0 0\n"
        "pose_time_ms -5\ngoal none\nobstacles 0\n" +
            tail,
        "BOTICELLI-STATE 0" + head.substr(17) + "obstacles 0\n" + tail,
        "BOTICELLI-STATE 2x" + head.substr(17) + "obstacles 0\n" + tail,
        "BOTICELLI-STATE 2\ncycle 3\nseed 1\npose 0 0 0\ngoal 1 2\nobstacles 0\n" + tail,
        head + "obstacles 0\nexploration 0\nmodel 5\nab\n\nlog 0\nend\n",
        head + "obstacles 0\n" + tail + "extra\n", head + "obstacles 0\n" + tail.substr(0, 20),
        head.substr(0, head.size() - 10) + "obstacles 0\n" + tail,  // no goal line
        head.substr(0, head.size() - 10),                           // nothing after the pose
        std::string("cycle 3\n")}) {
    f = with_crc(body);
    CHECK_FALSE_TEXT(decode_state(f, g_b, &why), body.c_str());
  }
}

TEST(Persistence, AWellChecksummedFileMustEndWithItsEndLine) {
  const char* why = "";
  const std::string head =
      "BOTICELLI-STATE 2\ncycle 3\nseed 1\npose 0 0 0\ngoal none\nobstacles 0\n"
      "exploration 0\nmodel 0\n\nlog 1\n2 saved\n";
  CHECK_TRUE_TEXT(decode_state(with_crc(head + "end\n"), g_b, &why), why);
  for (const char* last : {"END\n", "en\n", "end \n", "3 saved\n", "\n", "endx\n"}) {
    CHECK_FALSE_TEXT(decode_state(with_crc(head + last), g_b, &why), last);
    CHECK_EQUAL(0U, g_b.cycle);
  }
}

TEST(Persistence, AWellChecksummedLogLineWithAControlCharacterIsRejected) {
  // The log is shown on the console: a control byte in it (an escape sequence, a NUL, a
  // DEL) could do anything to the operator's terminal.
  const char* why = "";
  const std::string head =
      "BOTICELLI-STATE 2\ncycle 3\nseed 1\npose 0 0 0\ngoal none\nobstacles 0\n"
      "exploration 0\nmodel 0\n\nlog 1\n2 ";
  CHECK_TRUE_TEXT(decode_state(with_crc(head + "plain text ~!\nend\n"), g_b, &why), why);
  for (const std::string& bad :
       {std::string("a\x1b[2Jb"), std::string("tab\there"), std::string("nul\0x", 5),
        std::string("del\x7f"), std::string("cr\rx"), std::string("high\xc3\xa9")}) {
    CHECK_FALSE_TEXT(decode_state(with_crc(head + bad + "\nend\n"), g_b, &why), bad.c_str());
    CHECK_EQUAL(0U, g_b.log.size());
  }
}

TEST(Persistence, ReadsAVersionOneFileWhoseGoalHasNoHeight) {
  const char* why = "";
  const std::string body =
      "BOTICELLI-STATE 1\ncycle 3\nseed 1\npose 0 0 0\ngoal 1.5 -2\nobstacles 0\n"
      "exploration 0\nmodel 0\n\nlog 0\nend\n";
  char line[32];
  std::snprintf(line, sizeof line, "crc32 %08x\n", crc32(body.data(), body.size()));
  g_b.goal_height_m = 9.0F;
  CHECK_TRUE_TEXT(decode_state(body + line, g_b, &why), why);
  CHECK(g_b.has_goal);
  DOUBLES_EQUAL(1.5, g_b.goal.x_m, 0.0);
  DOUBLES_EQUAL(-2.0, g_b.goal.y_m, 0.0);
  DOUBLES_EQUAL(0.0, g_b.goal_height_m, 0.0);
}

// The wheel counters at the pose, to the last bit of a double (metres over a base's life),
// or none; a version 4 file has none and still loads.
TEST(Persistence, TheWheelCountersRoundTripExactlyAndAVersionFourFileHasNone) {
  make_state(7, g_a);
  CHECK(g_a.wheels_known);
  std::size_t n = encode_state(g_a, g_file, sizeof g_file);
  const char* why = "";
  CHECK_TRUE_TEXT(decode_state({g_file, n}, g_b, &why), why);
  CHECK(g_b.wheels_known);
  CHECK(g_a.wheel_left_m == g_b.wheel_left_m);
  CHECK(g_a.wheel_right_m == g_b.wheel_right_m);
  g_b.wheel_right_m = std::nextafter(g_b.wheel_right_m, 0.0);
  CHECK_FALSE(g_a == g_b);  // compared too
  g_a.wheels_known = false;
  n = encode_state(g_a, g_file, sizeof g_file);
  CHECK(std::string(g_file, n).find("\nwheels none\n") != std::string::npos);
  CHECK_TRUE_TEXT(decode_state({g_file, n}, g_b, &why), why);
  CHECK_FALSE(g_b.wheels_known);
  const std::string body =
      "BOTICELLI-STATE 4\nsequence 2\ncycle 3\nseed 1\nresult running\npose 0 0 0\n"
      "pose_time_ms 0\ngoal none\nobstacles 0\nexploration 0\nmodel 0\n\nlog 0\nend\n";
  g_b.wheels_known = true;
  CHECK_TRUE_TEXT(decode_state(with_crc(body), g_b, &why), why);
  CHECK_FALSE(g_b.wheels_known);
  // A version 5 file must say; a bad counter is refused.
  std::string v5 = body;
  v5.replace(v5.find(" 4\n"), 3, " 5\n");
  CHECK_FALSE(decode_state(with_crc(v5), g_b, &why));
  v5.insert(v5.find("goal none"), "wheels 1.5 nan\n");
  CHECK_FALSE(decode_state(with_crc(v5), g_b, &why));
  STRCMP_EQUAL("bad wheels", why);
}

// The stereo's learnt bias round trips exactly; a version 5 file has none (0) and still loads,
// a version 6 file must say, and a bias that is not a number or beyond ±1 /m is refused.
TEST(Persistence, TheStereoBiasRoundTripsAndAVersionFiveFileHasNone) {
  make_state(3, g_a);
  std::size_t n = encode_state(g_a, g_file, sizeof g_file);
  const char* why = "";
  CHECK_TRUE_TEXT(decode_state({g_file, n}, g_b, &why), why);
  CHECK(g_a.stereo_bias_per_m != 0.0F);
  CHECK(g_a.stereo_bias_per_m == g_b.stereo_bias_per_m);
  g_b.stereo_bias_per_m = std::nextafter(g_b.stereo_bias_per_m, 0.0F);
  CHECK_FALSE(g_a == g_b);  // compared too
  const std::string v5 =
      "BOTICELLI-STATE 5\nsequence 2\ncycle 3\nseed 1\nresult running\npose 0 0 0\n"
      "pose_time_ms 0\nwheels none\ngoal none\nobstacles 0\nexploration 0\ngrid 0 0\nmodel 0\n"
      "\nlog 0\nend\n";
  g_b.stereo_bias_per_m = 0.25F;
  CHECK_TRUE_TEXT(decode_state(with_crc(v5), g_b, &why), why);
  DOUBLES_EQUAL(0.0, g_b.stereo_bias_per_m, 0.0);
  std::string v6 = v5;
  v6.replace(v6.find(" 5\n"), 3, " 6\n");
  CHECK_FALSE(decode_state(with_crc(v6), g_b, &why));  // the line missing
  const std::size_t at = v6.find("goal none");
  for (const char* bad : {"stereo_bias nan\n", "stereo_bias 1.5\n", "stereo_bias -2\n",
                          "stereo_bias 0.1 0.2\n", "stereo_bias\n"}) {
    std::string text = v6;
    text.insert(at, bad);
    CHECK_FALSE_TEXT(decode_state(with_crc(text), g_b, &why), bad);
    STRCMP_EQUAL("bad stereo bias", why);
  }
  std::string good = v6;
  good.insert(at, "stereo_bias -0.0625\n");
  CHECK_TRUE_TEXT(decode_state(with_crc(good), g_b, &why), why);
  DOUBLES_EQUAL(-0.0625, g_b.stereo_bias_per_m, 0.0);
}

// The grid's tiles round trip exactly; a tile with a bad place, a short or non-hex line, or a
// log-odds beyond the grid's clamp is refused.
TEST(Persistence, TheGridsTilesRoundTripAndABadTileIsRefused) {
  make_state(8, g_a);
  CHECK_EQUAL(8U, g_a.grid.size());
  std::size_t n = encode_state(g_a, g_file, sizeof g_file);
  const char* why = "";
  CHECK_TRUE_TEXT(decode_state({g_file, n}, g_b, &why), why);
  CHECK_EQUAL(8U, g_b.grid.size());
  CHECK(g_a.grid[7].cells == g_b.grid[7].cells);
  CHECK_EQUAL(g_a.grid[7].ty, g_b.grid[7].ty);
  g_b.grid[3].cells[100] = static_cast<std::int8_t>(g_b.grid[3].cells[100] + 1);
  CHECK_FALSE(g_a == g_b);                 // compared cell by cell
  const std::string good(g_file, n - 15);  // without its crc line
  const std::size_t at = good.find("\ngrid ");
  CHECK(at != std::string::npos);
  const std::size_t tile = good.find('\n', at + 1) + 1;  // the first tile's line
  const std::size_t hex = good.find(' ', good.find(' ', tile) + 1) + 1;
  for (const auto& [from, len, to] :
       std::initializer_list<std::tuple<std::size_t, std::size_t, std::string>>{
           {tile, hex - tile, "64 0 "},  // outside the directory
           {hex, 2, "7f"},               // a log-odds of 127
           {hex, 2, "zz"},               // not hex
           {hex, 2, ""}}) {              // a cell short
    std::string bad = good;
    bad.replace(from, len, to);
    CHECK_FALSE_TEXT(decode_state(with_crc(bad), g_b, &why), to.c_str());
    STRCMP_EQUAL("bad grid tile", why);
  }
}

TEST(Persistence, KeepsTheMissionsResultAndTheSequenceNumber) {
  make_state(7, g_a);
  g_a.set_end(MissionEnd::kFound, "within the stand-off of the target");
  CHECK_EQUAL(1700000000007LL, g_a.pose_time_ms);
  const std::size_t n = encode_state(g_a, g_file, sizeof g_file, 41);
  const char* why = "";
  std::uint64_t sequence = 0;
  CHECK_TRUE_TEXT(decode_state({g_file, n}, g_b, &why, &sequence), why);
  CHECK(g_a == g_b);
  CHECK(g_b.end == MissionEnd::kFound);
  STRCMP_EQUAL("within the stand-off of the target", g_b.end_reason.data());
  CHECK_EQUAL(1700000000007LL, g_b.pose_time_ms);
  CHECK_EQUAL(41U, sequence);
  CHECK_TRUE_TEXT(peek_state({g_file, n}, sequence = 0, &why), why);
  CHECK_EQUAL(41U, sequence);
  // The result is part of what a state is: a different end is a different state.
  g_b.set_end(MissionEnd::kAborted, "within the stand-off of the target");
  CHECK_FALSE(g_a == g_b);
  // Version 3 (no pose time): the pose's time is unknown.
  const std::string v3 = with_crc(
      "BOTICELLI-STATE 3\nsequence 7\ncycle 3\nseed 1\nresult running\npose 1 2 0\ngoal none\n"
      "obstacles 0\nexploration 0\nmodel 0\n\nlog 0\nend\n");
  g_b.pose_time_ms = 5;
  CHECK_TRUE_TEXT(decode_state(v3, g_b, &why, &sequence), why);
  CHECK_EQUAL(7U, sequence);
  CHECK_EQUAL(0, g_b.pose_time_ms);
  DOUBLES_EQUAL(2.0, g_b.pose.y_m, 0.0);
  // A file written before the result was kept is a running mission with sequence 0.
  const std::string v2 = with_crc(
      "BOTICELLI-STATE 2\ncycle 3\nseed 1\npose 0 0 0\ngoal none\nobstacles 0\n"
      "exploration 0\nmodel 0\n\nlog 0\nend\n");
  sequence = 9;
  CHECK_TRUE_TEXT(decode_state(v2, g_b, &why, &sequence), why);
  CHECK(g_b.end == MissionEnd::kRunning);
  CHECK_EQUAL(0U, sequence);
}

TEST(Persistence, SavesAlternateBetweenTwoCopiesEachWithTheNextSequenceNumber) {
  CHECK_TRUE_TEXT(g_store.open(dir.c_str(), error, sizeof error), error);
  for (std::uint64_t c = 1; c <= 4; ++c) {
    make_state(c, g_a);
    CHECK_TRUE_TEXT(g_store.save(g_a, error, sizeof error), error);
  }
  // Saves 1 and 3 went to A, 2 and 4 to B; the newest (B, cycle 4) loads.
  STRCMP_CONTAINS("sequence 3\ncycle 3\n", read_file(dir + "/mission.state.a").c_str());
  STRCMP_CONTAINS("sequence 4\ncycle 4\n", read_file(dir + "/mission.state.b").c_str());
  CHECK(g_store.load(g_b, error, sizeof error) == LoadResult::kLoaded);
  CHECK_EQUAL(4U, g_b.cycle);
  STRCMP_EQUAL((dir + "/mission.state.b").c_str(), g_store.loaded_path());
  STRCMP_EQUAL("", g_store.load_warning());
  // A store opened afresh (a restart without --resume's load) carries the numbering on.
  CHECK(g_store.open(dir.c_str(), error, sizeof error));
  make_state(5, g_a);
  CHECK_TRUE_TEXT(g_store.save(g_a, error, sizeof error), error);
  STRCMP_CONTAINS("sequence 5\ncycle 5\n", read_file(dir + "/mission.state.a").c_str());
}

// A store opened on copies an earlier run left, where copy A holds the newer state, writes its
// first save over copy B: the newest state is never the one replaced.
TEST(Persistence, AReopenedStoreSavesOverTheOlderCopyWhicheverItIs) {
  CHECK(g_store.open(dir.c_str(), error, sizeof error));
  for (std::uint64_t c = 1; c <= 3; ++c) {  // A, B, A
    make_state(c, g_a);
    CHECK(g_store.save(g_a, error, sizeof error));
  }
  const std::string newest = read_file(dir + "/mission.state.a");
  static StateStore reopened;
  CHECK(reopened.open(dir.c_str(), error, sizeof error));
  make_state(4, g_a);
  CHECK(reopened.save(g_a, error, sizeof error));
  CHECK(read_file(dir + "/mission.state.a") == newest);
  CHECK(reopened.load(g_b, error, sizeof error) == LoadResult::kLoaded);
  STRCMP_CONTAINS("mission.state.b", reopened.loaded_path());
  CHECK(g_a == g_b);
}

// A copy that cannot be read at all (here a directory in its place) does not stop the store
// from looking at the others.
TEST(Persistence, ACopyThatCannotBeReadIsPassedOverForTheOther) {
  CHECK(g_store.open(dir.c_str(), error, sizeof error));
  for (std::uint64_t c = 1; c <= 2; ++c) {  // A, B
    make_state(c, g_a);
    CHECK(g_store.save(g_a, error, sizeof error));
  }
  CHECK(unlink((dir + "/mission.state.a").c_str()) == 0);
  CHECK(mkdir((dir + "/mission.state.a").c_str(), 0700) == 0);
  static StateStore reopened;
  CHECK(reopened.open(dir.c_str(), error, sizeof error));
  const LoadResult loaded = reopened.load(g_b, error, sizeof error);
  rmdir((dir + "/mission.state.a").c_str());
  CHECK(loaded == LoadResult::kLoaded);
  CHECK(g_a == g_b);
}

TEST(Persistence, AStoreThatWasNeverOpenedSavesNothingAndSaysWhy) {
  static StateStore closed;
  make_state(1, g_a);
  CHECK_FALSE(closed.save(g_a, error, sizeof error));
  STRCMP_EQUAL("no state directory", error);
  CHECK_FALSE(closed.save_parameters("gain = 1\n", error, sizeof error));
  STRCMP_EQUAL("no state directory", error);
}

TEST(Persistence, AFlippedByteInTheNewestCopyFallsBackToTheOtherWithAWarning) {
  CHECK(g_store.open(dir.c_str(), error, sizeof error));
  for (std::uint64_t c = 20; c <= 21; ++c) {
    make_state(c, g_a);
    CHECK_TRUE_TEXT(g_store.save(g_a, error, sizeof error), error);
  }
  const std::string newest = dir + "/mission.state.b";
  std::string bad = read_file(newest);
  bad[bad.size() / 2] = static_cast<char>(bad[bad.size() / 2] ^ 0x01);
  write_file(newest, bad);
  CHECK(g_store.load(g_b, error, sizeof error) == LoadResult::kLoaded);
  CHECK_EQUAL(20U, g_b.cycle);  // one save lost, not the mission
  make_state(20, g_a);
  CHECK(g_a == g_b);
  STRCMP_CONTAINS((newest + ": checksum mismatch (corrupt file)").c_str(), g_store.load_warning());
  STRCMP_CONTAINS(("loaded " + dir + "/mission.state.a (sequence 1) instead").c_str(),
                  g_store.load_warning());
  // The next save replaces the damaged copy, not the good one.
  make_state(22, g_a);
  CHECK_TRUE_TEXT(g_store.save(g_a, error, sizeof error), error);
  STRCMP_CONTAINS("sequence 2\ncycle 22\n", read_file(newest).c_str());
  STRCMP_CONTAINS("sequence 1\ncycle 20\n", read_file(dir + "/mission.state.a").c_str());
  CHECK(g_store.load(g_b, error, sizeof error) == LoadResult::kLoaded);
  CHECK_EQUAL(22U, g_b.cycle);
  STRCMP_EQUAL("", g_store.load_warning());
}

TEST(Persistence, WhenBothCopiesAreDamagedNothingLoadsAndEachCopySaysWhy) {
  CHECK(g_store.open(dir.c_str(), error, sizeof error));
  for (std::uint64_t c = 1; c <= 2; ++c) {
    make_state(c, g_a);
    CHECK(g_store.save(g_a, error, sizeof error));
  }
  const std::string a = read_file(dir + "/mission.state.a");
  write_file(dir + "/mission.state.a", a.substr(0, a.size() - 3));
  std::string b = read_file(dir + "/mission.state.b");
  b[40] = static_cast<char>(b[40] ^ 0x10);
  write_file(dir + "/mission.state.b", b);
  CHECK(g_store.load(g_b, error, sizeof error) == LoadResult::kCorrupt);
  STRCMP_CONTAINS((dir + "/mission.state.a: ").c_str(), error);
  STRCMP_CONTAINS((dir + "/mission.state.b: checksum mismatch").c_str(), error);
  CHECK_EQUAL(0U, g_b.cycle);
}

TEST(Persistence, AStateFileOfTheSingleFileLayoutLoadsAndGoesOnceBothCopiesAreNewer) {
  // As an earlier firmware left it: one file, version 2, no sequence number.
  const std::string old_file = with_crc(
      "BOTICELLI-STATE 2\ncycle 6\nseed 3\npose 1 2 0.5\ngoal none\nobstacles 1\n1 2\n"
      "exploration 0\nmodel 0\n\nlog 1\n6 looked\nend\n");
  write_file(dir + "/mission.state", old_file);
  CHECK(g_store.open(dir.c_str(), error, sizeof error));
  CHECK_TRUE_TEXT(g_store.load(g_b, error, sizeof error) == LoadResult::kLoaded, error);
  CHECK_EQUAL(6U, g_b.cycle);
  CHECK_EQUAL(3U, g_b.seed);
  STRCMP_EQUAL((dir + "/mission.state").c_str(), g_store.loaded_path());
  g_b.cycle = 7;
  CHECK(g_store.save(g_b, error, sizeof error));
  // Still there while only one copy is newer: it is the fallback for a damaged A.
  STRCMP_EQUAL(old_file.c_str(), read_file(dir + "/mission.state").c_str());
  g_b.cycle = 8;
  CHECK(g_store.save(g_b, error, sizeof error));
  struct stat st {};
  CHECK(stat((dir + "/mission.state").c_str(), &st) != 0);
  CHECK(g_store.load(g_a, error, sizeof error) == LoadResult::kLoaded);
  CHECK_EQUAL(8U, g_a.cycle);
}

TEST(Persistence, ANewMissionKeepsTheNewestValidCopyAndClearsBoth) {
  CHECK(g_store.open(dir.c_str(), error, sizeof error));
  char kept[600] = "";
  CHECK(g_store.keep_previous(kept, sizeof kept, error, sizeof error) == LoadResult::kMissing);
  for (std::uint64_t c = 30; c <= 32; ++c) {
    make_state(c, g_a);
    CHECK(g_store.save(g_a, error, sizeof error));
  }
  // A (cycle 32) damaged: B (cycle 31) is the mission to keep.
  std::string a = read_file(dir + "/mission.state.a");
  a[60] = static_cast<char>(a[60] ^ 0x04);
  write_file(dir + "/mission.state.a", a);
  CHECK(g_store.keep_previous(kept, sizeof kept, error, sizeof error) == LoadResult::kLoaded);
  STRCMP_EQUAL((dir + "/mission.state.1").c_str(), kept);
  STRCMP_CONTAINS("cycle 31\n", read_file(dir + "/mission.state.1").c_str());
  struct stat st {};
  CHECK(stat((dir + "/mission.state.a").c_str(), &st) != 0);
  CHECK(stat((dir + "/mission.state.b").c_str(), &st) != 0);
  CHECK(g_store.load(g_b, error, sizeof error) == LoadResult::kMissing);
  // The new mission numbers its saves from 1 again.
  make_state(1, g_a);
  CHECK(g_store.save(g_a, error, sizeof error));
  STRCMP_CONTAINS("sequence 1\n", read_file(dir + "/mission.state.a").c_str());
}

// The mission's own order: the previous mission kept, then the new one's first save at once
// (no load between them to survey the emptied directory again).
TEST(Persistence, TheFirstSaveRightAfterANewMissionKeptThePreviousHasSequenceOne) {
  CHECK(g_store.open(dir.c_str(), error, sizeof error));
  for (std::uint64_t c = 1; c <= 3; ++c) {
    make_state(c, g_a);
    CHECK(g_store.save(g_a, error, sizeof error));
  }
  char kept[600] = "";
  CHECK(g_store.keep_previous(kept, sizeof kept, error, sizeof error) == LoadResult::kLoaded);
  make_state(1, g_a);
  CHECK(g_store.save(g_a, error, sizeof error));
  std::uint64_t sequence = 0;
  const char* why = "";
  const std::string a = read_file(dir + "/mission.state.a");
  CHECK_TRUE_TEXT(peek_state(a, sequence, &why), why);
  CHECK_EQUAL(1U, sequence);
}

// Two valid files with one sequence number (an operator's copy, or a restore from a backup):
// the first of them wins, and the two copies win against the single file.
TEST(Persistence, OfTwoFilesWithTheSameSequenceTheFirstCopyLoadsAndACopyBeatsTheSingleFile) {
  const auto file_of = [](std::uint64_t cycle, std::uint64_t sequence) {
    make_state(cycle, g_a);
    const std::size_t n = encode_state(g_a, g_file, sizeof g_file, sequence);
    CHECK(n > 0);
    return std::string(g_file, n);
  };
  write_file(dir + "/mission.state.a", file_of(11, 7));
  write_file(dir + "/mission.state.b", file_of(12, 7));
  write_file(dir + "/mission.state", file_of(13, 7));
  CHECK(g_store.open(dir.c_str(), error, sizeof error));
  CHECK_TRUE_TEXT(g_store.load(g_b, error, sizeof error) == LoadResult::kLoaded, error);
  CHECK_EQUAL(11U, g_b.cycle);
  unlink((dir + "/mission.state.a").c_str());
  CHECK_TRUE_TEXT(g_store.load(g_b, error, sizeof error) == LoadResult::kLoaded, error);
  CHECK_EQUAL(12U, g_b.cycle);
  unlink((dir + "/mission.state.b").c_str());
  write_file(dir + "/mission.state.b", file_of(14, 6));
  CHECK_TRUE_TEXT(g_store.load(g_b, error, sizeof error) == LoadResult::kLoaded, error);
  CHECK_EQUAL(13U, g_b.cycle);  // the single file's 7 is newer than the copy's 6
}

TEST(Persistence, WithOnlyADamagedCopyANewMissionStillKeepsIt) {
  CHECK(g_store.open(dir.c_str(), error, sizeof error));
  make_state(40, g_a);
  CHECK(g_store.save(g_a, error, sizeof error));
  std::string a = read_file(dir + "/mission.state.a");
  a[60] = static_cast<char>(a[60] ^ 0x04);
  write_file(dir + "/mission.state.a", a);
  char kept[600] = "";
  CHECK(g_store.keep_previous(kept, sizeof kept, error, sizeof error) == LoadResult::kLoaded);
  STRCMP_EQUAL((dir + "/mission.state.1").c_str(), kept);
  CHECK(read_file(dir + "/mission.state.1") == a);
}

TEST(Persistence, AFileWhereTheStateDirectoryShouldBeIsRefusedWithTheReason) {
  const std::string file = dir + "/not-a-dir";
  write_file(file, "x");
  const bool opened = g_store.open(file.c_str(), error, sizeof error);
  unlink(file.c_str());
  CHECK_FALSE(opened);
  CHECK(g_store.refused());
  CHECK_FALSE(g_store.is_open());
  STRCMP_EQUAL(("state path " + file + " is not a directory").c_str(), error);
}

TEST(Persistence, SavesAtomicallyAndLoadsBack) {
  CHECK_TRUE_TEXT(g_store.open(dir.c_str(), error, sizeof error), error);
  CHECK(g_store.load(g_b, error, sizeof error) == LoadResult::kMissing);
  make_state(17, g_a);
  CHECK_TRUE_TEXT(g_store.save(g_a, error, sizeof error), error);
  struct stat st {};
  CHECK(stat((dir + "/mission.state.a.tmp").c_str(), &st) != 0);  // no temporary left behind
  CHECK(g_store.load(g_b, error, sizeof error) == LoadResult::kLoaded);
  CHECK(g_a == g_b);
}

TEST(Persistence, ASymlinkedTemporaryFileIsReplacedNotWrittenThrough) {
  // Someone who could write in the directory left mission.state.a.tmp pointing elsewhere.
  const std::string outside_dir = temp_dir("outside");
  const std::string outside = outside_dir + "/precious";
  write_file(outside, "do not touch\n");
  CHECK_EQUAL(0, symlink(outside.c_str(), (dir + "/mission.state.a.tmp").c_str()));
  CHECK_EQUAL(0, symlink(outside.c_str(), (dir + "/parameters.conf.tmp").c_str()));
  CHECK_TRUE_TEXT(g_store.open(dir.c_str(), error, sizeof error), error);
  make_state(12, g_a);
  CHECK_TRUE_TEXT(g_store.save(g_a, error, sizeof error), error);
  CHECK_TRUE_TEXT(g_store.save_parameters("telemetry_ms = 250\n", error, sizeof error), error);
  STRCMP_EQUAL("do not touch\n", read_file(outside).c_str());
  struct stat st {};
  CHECK_EQUAL(0, lstat((dir + "/mission.state.a").c_str(), &st));
  CHECK(S_ISREG(st.st_mode));  // a file of its own, not the symlink renamed into place
  CHECK_EQUAL(0, lstat((dir + "/parameters.conf").c_str(), &st));
  CHECK(S_ISREG(st.st_mode));
  CHECK(g_store.load(g_b, error, sizeof error) == LoadResult::kLoaded);
  CHECK(g_a == g_b);
  CHECK(lstat((dir + "/mission.state.a.tmp").c_str(), &st) != 0);
  unlink(outside.c_str());
  rmdir(outside_dir.c_str());
}

TEST(Persistence, AStaleTemporaryFileLeftByACrashDoesNotBlockASave) {
  write_file(dir + "/mission.state.a.tmp", "half a state from a killed run");
  write_file(dir + "/parameters.conf.tmp", "half");
  CHECK_TRUE_TEXT(g_store.open(dir.c_str(), error, sizeof error), error);
  make_state(5, g_a);
  CHECK_TRUE_TEXT(g_store.save(g_a, error, sizeof error), error);
  CHECK_TRUE_TEXT(g_store.save_parameters("telemetry_ms = 250\n", error, sizeof error), error);
  CHECK(g_store.load(g_b, error, sizeof error) == LoadResult::kLoaded);
  CHECK(g_a == g_b);
  STRCMP_EQUAL("telemetry_ms = 250\n", read_file(dir + "/parameters.conf").c_str());
  struct stat st {};
  CHECK(stat((dir + "/mission.state.a.tmp").c_str(), &st) != 0);
  CHECK(stat((dir + "/parameters.conf.tmp").c_str(), &st) != 0);
}

TEST(Persistence, ADirectoryOthersMayWriteInIsRefusedWithTheReason) {
  CHECK_EQUAL(0, chmod(dir.c_str(), 0777));
  CHECK_FALSE(g_store.open(dir.c_str(), error, sizeof error));
  CHECK(g_store.refused());
  CHECK_FALSE(g_store.is_open());
  STRCMP_CONTAINS("refused: writable by group and others (mode 0777", error);
  CHECK_EQUAL(0, chmod(dir.c_str(), 0770));
  CHECK_FALSE(g_store.open(dir.c_str(), error, sizeof error));
  STRCMP_CONTAINS("refused: writable by its group (mode 0770", error);
  CHECK_EQUAL(0, chmod(dir.c_str(), 0757));
  CHECK_FALSE(g_store.open(dir.c_str(), error, sizeof error));
  STRCMP_CONTAINS("refused: writable by others (mode 0757", error);
  // What mkdir with the usual umasks and systemd's StateDirectoryMode (0755 by default,
  // 0750 in the unit) give is accepted.
  for (const mode_t mode : {mode_t{0700}, mode_t{0750}, mode_t{0755}}) {
    CHECK_EQUAL(0, chmod(dir.c_str(), mode));
    CHECK_TRUE_TEXT(g_store.open(dir.c_str(), error, sizeof error), error);
    CHECK_FALSE(g_store.refused());
  }
  // A directory it creates itself is accepted too, whatever the umask.
  const std::string created = dir + "/new";
  const mode_t old_umask = umask(0);
  const bool opened = g_store.open(created.c_str(), error, sizeof error);
  umask(old_umask);
  CHECK_TRUE_TEXT(opened, error);
  rmdir(created.c_str());
}

TEST(Persistence, ADirectoryOfAnotherUserIsRefused) {
  if (geteuid() != 0) {
    UT_PRINT("not root: cannot give the directory to another user; owner check not run");
    return;
  }
  CHECK_EQUAL(0, chown(dir.c_str(), 54321, static_cast<gid_t>(-1)));
  CHECK_FALSE(g_store.open(dir.c_str(), error, sizeof error));
  CHECK(g_store.refused());
  STRCMP_CONTAINS("refused: owned by uid 54321, not by this user (uid 0)", error);
  CHECK_FALSE(g_store.is_open());
  CHECK_EQUAL(0, chown(dir.c_str(), 0, static_cast<gid_t>(-1)));
  CHECK_TRUE_TEXT(g_store.open(dir.c_str(), error, sizeof error), error);
}

TEST(Persistence, ReportsACorruptOrTruncatedFileAndDoesNotLoadIt) {
  CHECK(g_store.open(dir.c_str(), error, sizeof error));
  make_state(40, g_a);
  CHECK(g_store.save(g_a, error, sizeof error));
  const std::string path = dir + "/mission.state.a";  // the only copy after one save
  const std::string good = read_file(path);
  write_file(path, good.substr(0, good.size() / 2));
  CHECK(g_store.load(g_b, error, sizeof error) == LoadResult::kCorrupt);
  STRCMP_CONTAINS("mission.state", error);
  CHECK_EQUAL(0U, g_b.cycle);
  std::string bad = good;
  bad[bad.size() / 3] = static_cast<char>(bad[bad.size() / 3] ^ 0x20);
  write_file(path, bad);
  CHECK(g_store.load(g_b, error, sizeof error) == LoadResult::kCorrupt);
  STRCMP_CONTAINS("checksum", error);
  write_file(path, good + std::string(kMaxStateFileBytes, 'x'));
  CHECK(g_store.load(g_b, error, sizeof error) == LoadResult::kCorrupt);
  write_file(path, good);
  CHECK(g_store.load(g_b, error, sizeof error) == LoadResult::kLoaded);
}

namespace {
struct CrashAt {
  int after_calls;
  int calls = 0;
};
bool crash_hook(SaveStep, void* context) {
  auto* c = static_cast<CrashAt*>(context);
  return ++c->calls == c->after_calls;
}

// True when a forked child runs and exits (it does not under some qemu-user versions,
// where the child hangs; the crash-point test above covers that case without fork).
bool fork_works() {
  const pid_t child = fork();
  if (child == 0) _exit(0);
  if (child < 0) return false;
  return boticelli::test::wait_for_child(child, 2000) != -1;
}
}  // namespace

TEST(Persistence, ASaveCutShortAtAnyStepLeavesThePreviousOrTheNewStateNeverAMix) {
  CHECK(g_store.open(dir.c_str(), error, sizeof error));
  std::uint64_t cycle = 50;  // 1850 obstacle points: a file of several write chunks
  make_state(cycle, g_a);
  CHECK(g_store.save(g_a, error, sizeof error));
  bool completed = false;
  int steps_seen = 0;
  for (int crash_after = 1; !completed; ++crash_after) {
    CrashAt crash{crash_after};
    g_store.set_crash_hook(crash_hook, &crash);
    make_state(cycle + 1, g_a);
    completed = g_store.save(g_a, error, sizeof error);
    g_store.set_crash_hook(nullptr, nullptr);
    // "Restart": load what is on disk.
    CHECK(g_store.load(g_b, error, sizeof error) == LoadResult::kLoaded);
    CHECK(g_b.cycle == cycle || g_b.cycle == cycle + 1);
    make_state(g_b.cycle, g_a);
    CHECK(g_a == g_b);
    cycle = g_b.cycle;  // resume from there
    ++steps_seen;
  }
  CHECK(encode_state(g_a, g_file, sizeof g_file) > 2 * StateStore::kWriteChunkBytes);
  CHECK(steps_seen >= 7);  // created, three chunks, synced, renamed, then a full save
}

TEST(Persistence, AKilledRunResumesWithNothingLostAndNothingCorrupt) {
  if (!fork_works()) {
    UT_PRINT("fork() does not work in this emulator; SIGKILL part not run");
    return;
  }
  CHECK(g_store.open(dir.c_str(), error, sizeof error));
  std::uint64_t last_loaded = 0;
  // Kill the saving process at varied moments, several times, resuming each time.
  for (int kill_round = 0; kill_round < 6; ++kill_round) {
    int ready[2];
    CHECK_EQUAL(0, pipe(ready));
    const pid_t child = fork();
    CHECK(child >= 0);
    if (child == 0) {
      close(ready[0]);
      // Resume from the saved state (or start), then run cycles, saving after each.
      MissionState& s = g_a;
      std::uint64_t cycle = 0;
      if (g_store.load(s, error, sizeof error) == LoadResult::kLoaded) cycle = s.cycle;
      bool told = false;
      for (;;) {
        ++cycle;
        make_state(cycle, s);
        if (!g_store.save(s, error, sizeof error)) _exit(3);
        if (!told) {
          (void)!write(ready[1], "r", 1);
          told = true;
        }
      }
    }
    close(ready[1]);
    char c = 0;
    CHECK_EQUAL(1, read(ready[0], &c, 1));  // at least one save of this run finished
    close(ready[0]);
    timespec pause{0, 3000000L + 7000000L * kill_round};
    nanosleep(&pause, nullptr);
    CHECK_EQUAL(0, kill(child, SIGKILL));
    int status = 0;
    CHECK_EQUAL(child, waitpid(child, &status, 0));
    CHECK(WIFSIGNALED(status));

    // The state on disk is exactly one of the completed cycles, later than the last resume.
    CHECK(g_store.load(g_b, error, sizeof error) == LoadResult::kLoaded);
    CHECK(g_b.cycle > last_loaded);
    make_state(g_b.cycle, g_a);
    CHECK(g_a == g_b);
    last_loaded = g_b.cycle;
  }
  CHECK(last_loaded >= 6U);
}

namespace {
// Counts a save's storage calls in their order; fails the temporary file's sync with EIO when
// asked.
struct SyncWatch {
  int writes = 0;
  int syncs = 0;
  int writes_after_sync = 0;
  bool fail = false;
};
int watch_syncs(StorageCall call, void* context) {
  auto* w = static_cast<SyncWatch*>(context);
  if (call == StorageCall::kWrite) {
    ++w->writes;
    if (w->syncs > 0) ++w->writes_after_sync;
  }
  if (call != StorageCall::kSync) return 0;
  ++w->syncs;
  return w->fail ? EIO : 0;
}
}  // namespace

TEST(Persistence, ASaveSyncsTheWholeTemporaryFileBeforeTheRenameAndAFailedSyncKeepsTheOldState) {
  CHECK(g_store.open(dir.c_str(), error, sizeof error));
  static SyncWatch watch;
  watch = {};
  set_storage_fault_hook(watch_syncs, &watch);
  make_state(7, g_a);
  CHECK(g_store.save(g_a, error, sizeof error));
  CHECK(watch.writes >= 1);
  CHECK_EQUAL(1, watch.syncs);
  CHECK_EQUAL(0, watch.writes_after_sync);
  // Unsynced data must never replace a state: after a power cut it may read back empty.
  watch.fail = true;
  make_state(8, g_b);
  CHECK_FALSE(g_store.save(g_b, error, sizeof error));
  STRCMP_CONTAINS("cannot sync", error);
  set_storage_fault_hook(nullptr, nullptr);
  CHECK(access((dir + "/mission.state.a.tmp").c_str(), F_OK) != 0);
  CHECK(access((dir + "/mission.state.b.tmp").c_str(), F_OK) != 0);
  CHECK(g_store.load(g_b, error, sizeof error) == LoadResult::kLoaded);
  CHECK(g_a == g_b);
}

namespace {
// Fails the first `failures` creations of a temporary file with EIO.
struct FailingCreates {
  std::atomic<int> failures{0};
};
int fail_creates(StorageCall call, void* context) {
  auto* f = static_cast<FailingCreates*>(context);
  if (call != StorageCall::kCreate) return 0;
  return f->failures.fetch_sub(1) > 0 ? EIO : 0;
}
}  // namespace

TEST(Persistence, WithoutItsThreadTheSaverWritesEachStateAtOnce) {
  CHECK(g_store.open(dir.c_str(), error, sizeof error));
  auto owner = std::make_unique<StateSaver>(g_store);
  for (std::uint64_t c = 1; c <= 3; ++c) {
    make_state(c, g_a);
    CHECK(owner->submit(g_a));
    CHECK(g_store.load(g_b, error, sizeof error) == LoadResult::kLoaded);
    CHECK_EQUAL(c, g_b.cycle);
  }
  owner->flush();
  CHECK_EQUAL(3U, owner->saved());
  CHECK_FALSE(owner->failing());
  // A failed save is counted at once, with its reason, until the next one succeeds.
  static FailingCreates failing;
  failing.failures = 1;
  set_storage_fault_hook(fail_creates, &failing);
  CHECK(owner->submit(g_a));
  set_storage_fault_hook(nullptr, nullptr);
  CHECK_EQUAL(1U, owner->failures());
  CHECK_TRUE(owner->failing());
  char reason[256] = "";
  owner->last_error(reason, sizeof reason);
  STRCMP_CONTAINS("cannot create", reason);
  CHECK(owner->submit(g_a));
  CHECK_EQUAL(4U, owner->saved());
  CHECK_FALSE(owner->failing());
}

// qemu-user (the cross presets' test runner) hangs in thread creation on some hosts; the
// writer thread is tested by the native builds.
#ifndef BOTICELLI_TESTS_UNDER_EMULATOR
TEST(Persistence, TheWriterThreadEndsWithTheNewestSubmittedState) {
  CHECK(g_store.open(dir.c_str(), error, sizeof error));
  {
    auto owner = std::make_unique<StateSaver>(g_store);  // two states: not on the stack
    StateSaver& saver = *owner;
    saver.start();
    for (std::uint64_t c = 1; c <= 30; ++c) {
      make_state(c, g_a);
      while (!saver.submit(g_a)) {
      }
    }
    saver.flush();
    CHECK(saver.saved() >= 1U);
    CHECK(saver.saved() <= 30U);
    CHECK_EQUAL(0U, saver.failures());
  }
  CHECK(g_store.load(g_b, error, sizeof error) == LoadResult::kLoaded);
  CHECK_EQUAL(30U, g_b.cycle);
  make_state(30, g_a);
  CHECK(g_a == g_b);
}

// A state directory with a long path: a failed save's reason, path and all, is kept whole
// (up to its 255 bytes), saved at once or by the writer thread.
TEST(Persistence, AFailedSavesReasonIsKeptWholeForALongStateDirectory) {
  const std::string deep = dir + "/" + std::string(150, 'd');
  CHECK_EQUAL(0, mkdir(deep.c_str(), 0750));
  CHECK_TRUE_TEXT(g_store.open(deep.c_str(), error, sizeof error), error);
  const std::string expected =
      "cannot create " + deep + "/mission.state.a.tmp: " + std::strerror(EIO);
  CHECK(expected.size() > 180U && expected.size() < 256U);
  static FailingCreates failing;
  for (const bool threaded : {false, true}) {
    failing.failures = 1;
    set_storage_fault_hook(fail_creates, &failing);
    char reason[256] = "";
    {
      StateSaver saver(g_store);
      if (threaded) saver.start();
      make_state(3, g_a);
      CHECK(saver.submit(g_a));
      wait_while([&] { return saver.failures() == 0; });
      CHECK_EQUAL(1U, saver.failures());
      saver.last_error(reason, sizeof reason);
    }
    set_storage_fault_hook(nullptr, nullptr);
    STRCMP_EQUAL(expected.c_str(), reason);
  }
  remove_dir(deep);
}

// A disk that fails every save must not hold up the end: a saver stopped with its save failing
// stops at once, without another try (the state is as it was saved last).
TEST(Persistence, ASaverStoppedWhileItsSavesFailStopsWithoutTryingAgain) {
  CHECK(g_store.open(dir.c_str(), error, sizeof error));
  static FailingCreates failing;
  failing.failures = 1000;
  set_storage_fault_hook(fail_creates, &failing);
  {
    StateSaver saver(g_store);
    saver.set_retry_interval_ms(60000);  // no retry falls due while the test runs
    saver.start();
    make_state(5, g_a);
    CHECK(saver.submit(g_a));
    wait_while([&] { return saver.failures() == 0; });
    CHECK_EQUAL(1U, saver.failures());
  }
  set_storage_fault_hook(nullptr, nullptr);
  CHECK_EQUAL(999, failing.failures.load());  // one creation tried, none after the stop
}

TEST(Persistence, TheWriterThreadRetriesAFailedSaveWithoutANewSubmission) {
  CHECK(g_store.open(dir.c_str(), error, sizeof error));
  static FailingCreates failing;
  failing.failures = 2;
  set_storage_fault_hook(fail_creates, &failing);
  {
    auto owner = std::make_unique<StateSaver>(g_store);
    StateSaver& saver = *owner;
    saver.set_retry_interval_ms(20);
    saver.start();
    make_state(12, g_a);
    CHECK(saver.submit(g_a));
    // Nothing more is submitted (a finished mission): the writer tries again by itself.
    wait_while([&] { return saver.saved() == 0; });
    CHECK_EQUAL(1U, saver.saved());
    CHECK_EQUAL(2U, saver.failures());
    CHECK_EQUAL(2U, saver.retries());
    CHECK_FALSE(saver.failing());
    char reason[256] = "";
    saver.last_error(reason, sizeof reason);
    STRCMP_CONTAINS("cannot create", reason);  // the last failure's, kept after the success
  }
  set_storage_fault_hook(nullptr, nullptr);
  CHECK(g_store.load(g_b, error, sizeof error) == LoadResult::kLoaded);
  CHECK(g_a == g_b);
}
namespace {
// Holds the writer thread inside a save: the first creation of a temporary file waits until
// the test opens the gate (later ones pass).
struct SaveGate {
  std::mutex mutex;
  std::condition_variable changed;
  bool entered = false;
  bool open = false;
  void wait_entered() {
    std::unique_lock<std::mutex> lock(mutex);
    changed.wait(lock, [this] { return entered; });
  }
  // Opens the gate after `ms` from another thread (what the test does meanwhile is blocked).
  std::thread open_after_ms(int ms) {
    return std::thread([this, ms] {
      std::this_thread::sleep_for(std::chrono::milliseconds(ms));
      {
        std::lock_guard<std::mutex> lock(mutex);
        open = true;
      }
      changed.notify_all();
    });
  }
};
int gate_creates(StorageCall call, void* context) {
  auto* g = static_cast<SaveGate*>(context);
  if (call != StorageCall::kCreate) return 0;
  std::unique_lock<std::mutex> lock(g->mutex);
  g->entered = true;
  g->changed.notify_all();
  g->changed.wait(lock, [g] { return g->open; });
  return 0;
}
// The gate, closed, on every state file's creation from now on (the hook is cleared by each
// test when it is done).
SaveGate& install_save_gate() {
  static SaveGate gate;
  gate.entered = false;
  gate.open = false;
  set_storage_fault_hook(gate_creates, &gate);
  return gate;
}
}  // namespace

TEST(Persistence, FlushReturnsOnlyOnceTheSaveTheWriterIsMakingIsOnDisk) {
  CHECK(g_store.open(dir.c_str(), error, sizeof error));
  SaveGate& gate = install_save_gate();
  std::uint64_t saved_at_flush = 0;
  {
    auto owner = std::make_unique<StateSaver>(g_store);
    StateSaver& saver = *owner;
    saver.start();
    make_state(9, g_a);
    CHECK(saver.submit(g_a));
    gate.wait_entered();  // the writer took the state: nothing is pending, the save is under way
    std::thread opener = gate.open_after_ms(100);
    saver.flush();
    saved_at_flush = saver.saved();
    opener.join();
  }
  set_storage_fault_hook(nullptr, nullptr);
  CHECK_EQUAL(1U, saved_at_flush);
  CHECK(g_store.load(g_b, error, sizeof error) == LoadResult::kLoaded);
  CHECK(g_a == g_b);
}

TEST(Persistence, AStateSubmittedWhileTheWriterIsSavingIsWrittenBeforeTheSaverIsDestroyed) {
  CHECK(g_store.open(dir.c_str(), error, sizeof error));
  SaveGate& gate = install_save_gate();
  auto owner = std::make_unique<StateSaver>(g_store);
  owner->start();
  make_state(10, g_a);
  CHECK(owner->submit(g_a));
  gate.wait_entered();  // state 10 is being saved
  make_state(11, g_a);
  while (!owner->submit(g_a)) {
  }
  // No flush (an exit path that skips it): the destructor stops the writer while it is still
  // in the first save, with state 11 pending. The gate opens well after the stop is asked for.
  std::thread opener = gate.open_after_ms(100);
  owner.reset();
  opener.join();
  set_storage_fault_hook(nullptr, nullptr);
  CHECK(g_store.load(g_b, error, sizeof error) == LoadResult::kLoaded);
  CHECK_EQUAL(11U, g_b.cycle);
  CHECK(g_a == g_b);
}
TEST(Persistence, StartingTheWriterTwiceKeepsOneWriterThread) {
  CHECK(g_store.open(dir.c_str(), error, sizeof error));
  {
    auto owner = std::make_unique<StateSaver>(g_store);
    owner->start();
    owner->start();
    make_state(4, g_a);
    CHECK(owner->submit(g_a));
    owner->flush();
    CHECK_EQUAL(1U, owner->saved());
  }
  CHECK(g_store.load(g_b, error, sizeof error) == LoadResult::kLoaded);
  CHECK(g_a == g_b);
}

namespace {
// Fails the first `failures` creations with EIO and notes when each creation was tried.
struct TimedFailures {
  std::atomic<int> failures{0};
  std::atomic<int> tries{0};
  std::array<std::chrono::steady_clock::time_point, 8> at{};
};
int fail_creates_timed(StorageCall call, void* context) {
  auto* f = static_cast<TimedFailures*>(context);
  if (call != StorageCall::kCreate) return 0;
  const int n = f->tries.fetch_add(1);
  if (n < static_cast<int>(f->at.size()))
    f->at[static_cast<std::size_t>(n)] = std::chrono::steady_clock::now();
  return f->failures.fetch_sub(1) > 0 ? EIO : 0;
}
}  // namespace

TEST(Persistence, AFailedSaveIsTriedAgainOnlyOnceTheRetryIntervalHasPassed) {
  CHECK(g_store.open(dir.c_str(), error, sizeof error));
  static TimedFailures failing;
  failing.failures = 2;
  failing.tries = 0;
  set_storage_fault_hook(fail_creates_timed, &failing);
  {
    auto owner = std::make_unique<StateSaver>(g_store);
    owner->set_retry_interval_ms(60);
    owner->start();
    make_state(5, g_a);
    CHECK(owner->submit(g_a));
    wait_while([&] { return owner->saved() == 0; });
    CHECK_EQUAL(1U, owner->saved());
  }
  set_storage_fault_hook(nullptr, nullptr);
  CHECK_EQUAL(3, failing.tries.load());
  for (std::size_t i = 1; i < 3; ++i) {
    CHECK(failing.at[i] - failing.at[i - 1] >= std::chrono::milliseconds(60));
  }
}

TEST(Persistence, ParametersAndAStateHandedOverTogetherAreBothSaved) {
  CHECK(g_store.open(dir.c_str(), error, sizeof error));
  SaveGate& gate = install_save_gate();
  auto owner = std::make_unique<StateSaver>(g_store);
  owner->start();
  make_state(6, g_a);
  CHECK(owner->submit(g_a));
  gate.wait_entered();  // state 6 is being saved: what follows waits for the writer together
  CHECK(owner->submit_parameters("gain = 2\n") == StateSaver::Submitted::kQueued);
  make_state(7, g_a);
  while (!owner->submit(g_a)) {
  }
  gate.open_after_ms(0).join();
  wait_while([&] { return owner->saved() < 2 || owner->parameter_saves() < 1; });
  const std::uint64_t saved = owner->saved();
  const std::uint64_t parameters = owner->parameter_saves();
  owner.reset();
  set_storage_fault_hook(nullptr, nullptr);
  CHECK_EQUAL(2U, saved);
  CHECK_EQUAL(1U, parameters);
  STRCMP_EQUAL("gain = 2\n", read_file(dir + "/parameters.conf").c_str());
  CHECK(g_store.load(g_b, error, sizeof error) == LoadResult::kLoaded);
  CHECK(g_a == g_b);
}

TEST(Persistence, FlushReturnsOnlyOnceTheParameterSaveUnderWayIsOnDisk) {
  CHECK(g_store.open(dir.c_str(), error, sizeof error));
  SaveGate& gate = install_save_gate();
  std::uint64_t saved_at_flush = 0;
  {
    auto owner = std::make_unique<StateSaver>(g_store);
    owner->start();
    CHECK(owner->submit_parameters("gain = 3\n") == StateSaver::Submitted::kQueued);
    gate.wait_entered();
    std::thread opener = gate.open_after_ms(100);
    owner->flush();
    saved_at_flush = owner->parameter_saves();
    opener.join();
  }
  set_storage_fault_hook(nullptr, nullptr);
  CHECK_EQUAL(1U, saved_at_flush);
  STRCMP_EQUAL("gain = 3\n", read_file(dir + "/parameters.conf").c_str());
}
#endif
