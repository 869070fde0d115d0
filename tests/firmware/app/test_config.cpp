// Tests of the configuration file (good and bad files, the shipped conffile), the saved
// parameters' round trip and the atomic write both stores share.
#include <dirent.h>
#include <fcntl.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "board_config.h"  // boards/rpi4: its device keys
#include "firmware/state/atomic_file.h"
#include "firmware/app/board.h"
#include "firmware/app/config_file.h"
#include "firmware/common/parameters.h"
#include "firmware/state/persistence.h"
#include "firmware/state/state_saver.h"

#include "test_files.h"
#include "CppUTest/TestHarness.h"

using namespace boticelli::firmware;
namespace rpi4 = boticelli::boards::rpi4;

namespace {

using boticelli::test::read_file;
using boticelli::test::temp_dir;
using boticelli::test::write_file;

void remove_dir(const std::string& dir) {
  for (const char* name :
       {"/parameters.conf", "/parameters.conf.tmp", "/a.txt", "/a.txt.tmp", "/boticelli.conf"}) {
    unlink((dir + name).c_str());
  }
  rmdir(dir.c_str());
}

// The rpi4 board's keys, bound to its defaults.
struct Rpi4Keys {
  BoardConfig config = rpi4::make_config();
  rpi4::Rpi4Devices devices;
  ConfigSchema schema;
  Rpi4Keys() {
    CHECK(add_board_config_keys(schema, config));
    CHECK(rpi4::add_device_config_keys(schema, devices));
  }
};

bool same_config(const BoardConfig& a, const BoardConfig& b) {
  return std::memcmp(&a, &b, sizeof a) == 0;
}

// The text `key` (a path or a name) holds in `schema`'s bindings.
const DeviceName& key_text(const ConfigSchema& schema, const ConfigKey& key) {
  return *schema.find(key.table, key.name)->text;
}

}  // namespace

TEST_GROUP(ConfigFile){};

TEST(ConfigFile, AGoodFileSetsEveryKeyItNamesAndLeavesTheRest) {
  Rpi4Keys k;
  char error[320] = "";
  const std::string text =
      "# robot 2\n"
      "[camera]\n"
      "device = \"/dev/video2\"\n"
      "width_px = 1280\n"
      "focal_px = 1200  # an integer is a number too\n"
      "[base]\n"
      "can_interface = \"can1\"\n"
      "left_node_id = 3\n"
      "right_node_id = 4\n"
      "track_width_m = 0.45\n"
      "[gpio]\n"
      "estop_active_low = true\n"
      "[console]\n"
      "baud = 57600\n";
  CHECK_TEXT(apply_config_text(text, "good.conf", k.schema, error, sizeof error), error);
  STRCMP_EQUAL("/dev/video2", k.devices.camera_device.data());
  CHECK_EQUAL(1280U, k.config.camera_width_px);
  CHECK_EQUAL(480U, k.config.camera_height_px);  // not named: the default
  DOUBLES_EQUAL(1200.0, static_cast<double>(k.config.focal_px), 0.0);
  STRCMP_EQUAL("can1", k.devices.can_interface.data());
  CHECK_EQUAL(3U, k.devices.odrive_left_node_id);
  CHECK_EQUAL(4U, k.devices.odrive_right_node_id);
  DOUBLES_EQUAL(0.45, static_cast<double>(k.config.track_width_m), 1e-7);
  CHECK(k.devices.estop_active_low);
  CHECK_EQUAL(57600U, k.config.console_baud);
  STRCMP_EQUAL("/dev/ttyUSB0", k.devices.ptu_device.data());
}

// OpenCV's five distortion coefficients as calibrateCamera prints them, pasted into [camera].
TEST(ConfigFile, TheFiveDistortionCoefficientsAreReadAsCalibrationReportsThem) {
  Rpi4Keys k;
  char error[320] = "";
  const std::string text =
      "[camera]\n"
      "k1 = -0.121\n"
      "k2 = 0.084\n"
      "p1 = 0.0012\n"
      "p2 = -0.0007\n"
      "k3 = -0.013\n";
  CHECK_TEXT(apply_config_text(text, "lens.conf", k.schema, error, sizeof error), error);
  DOUBLES_EQUAL(-0.121, static_cast<double>(k.config.k1), 1e-7);
  DOUBLES_EQUAL(0.084, static_cast<double>(k.config.k2), 1e-7);
  DOUBLES_EQUAL(0.0012, static_cast<double>(k.config.p1), 1e-7);
  DOUBLES_EQUAL(-0.0007, static_cast<double>(k.config.p2), 1e-7);
  DOUBLES_EQUAL(-0.013, static_cast<double>(k.config.k3), 1e-7);
}

// Every bad file gives "FILE:LINE: why" with the line of the offending value, and changes
// nothing (the good key on line 2 is not applied either).
TEST(ConfigFile, EachKindOfBadValueIsReportedAsFileLineWhyAndChangesNothing) {
  struct Case {
    const char* line3;  // the third line of the file
    const char* why;
  };
  const Case cases[] = {
      {"width_px = \"640\"", "camera.width_px must be a whole number"},
      {"width_px = 640.5", "camera.width_px must be a whole number"},
      {"width_px = 2000", "camera.width_px = 2000 is out of range (160 to 1280)"},
      {"width_px = -8", "camera.width_px = -8 is out of range (160 to 1280)"},
      {"width_px = 642", "camera.width_px = 642 must be a multiple of 8"},
      {"focal_px = 10", "camera.focal_px = 10 is out of range (50 to 5000)"},
      {"k1 = -1.5", "camera.k1 = -1.5 is out of range (-1 to 1)"},
      {"k3 = 2", "camera.k3 = 2 is out of range (-1 to 1)"},
      {"p1 = 0.2", "camera.p1 = 0.2 is out of range (-0.1 to 0.1)"},
      {"p2 = -0.25", "camera.p2 = -0.25 is out of range (-0.1 to 0.1)"},
      {"radial_k1 = -0.1", "unknown key 'camera.radial_k1'"},  // the one-term model's key
      {"focal_px = inf", "camera.focal_px must be a finite number"},
      {"focal_px = nan", "camera.focal_px must be a finite number"},
      {"focal_px = true", "camera.focal_px must be a number"},
      {"device = \"video0\"", "camera.device must be an absolute path"},
      {"device = \"\"", "camera.device must be 1 to 63 bytes long"},
      {"device = \"/dev/my camera\"", "camera.device must be printable ASCII without spaces"},
      {"device = 7", "camera.device must be a string"},
      {"fps = 30", "unknown key 'camera.fps'"},
      {"[ptu]\nbaud = 9601", "ptu.baud = 9601 is not a standard baud rate"},
      {"[base]\nleft_node_id = 64", "base.left_node_id = 64 is out of range (0 to 63)"},
      {"[base]\ncan_interface = \"can 0\"", "base.can_interface may hold only letters"},
      {"[gpio]\nestop_active_low = 1", "gpio.estop_active_low must be true or false"},
      {"[gpio]\nled_line = 58", "gpio.led_line = 58 is out of range (0 to 57)"},
      {"[faults]\nretry_s = 0.5", "faults.retry_s = 0.5 is out of range (1 to 600)"},
      {"[faults]\nretry_s = 601", "faults.retry_s = 601 is out of range (1 to 600)"},
      {"[lidar]", "unknown table 'lidar'"},
      {"[[camera]]", ""},  // a redefinition: a syntax error from the TOML library
      {"width_px = 640\nwidth_px = 800", ""},  // a duplicate key: the library refuses it too
      {"height_px = = 3", ""},                 // syntax
  };
  for (const Case& c : cases) {
    Rpi4Keys k;
    const BoardConfig before = k.config;
    char error[320] = "";
    const std::string text = std::string("[camera]\nheight_px = 240\n") + c.line3 + "\n";
    CHECK_FALSE_TEXT(apply_config_text(text, "bad.conf", k.schema, error, sizeof error), c.line3);
    const bool two_lines = std::strchr(c.line3, '\n') != nullptr;
    const std::string where = two_lines ? "bad.conf:4: " : "bad.conf:3: ";
    // A duplicate key is reported where it repeats (line 4), like the second line of a pair.
    const std::string message = error;
    CHECK_TEXT(message.rfind(where, 0) == 0, (std::string(c.line3) + " -> " + message).c_str());
    STRCMP_CONTAINS(c.why, error);
    CHECK_TEXT(same_config(before, k.config), c.line3);
  }
}

// Every range-checked key of the board and the rpi4 devices: its minimum and maximum are
// accepted, and the next value below the minimum or above the maximum refused, with the range
// in the message and the value not set.
TEST(ConfigFile, EveryNumberKeyAcceptsItsBoundsAndRefusesTheNextValueOutsideThem) {
  const Rpi4Keys keys;
  std::size_t checked = 0;
  for (std::size_t i = 0; i < keys.schema.size(); ++i) {
    const ConfigKey& key = keys.schema[i];
    if (key.kind != ConfigKind::kWhole && key.kind != ConfigKind::kNumber) continue;
    for (const bool upper : {false, true}) {
      const double bound = upper ? key.max : key.min;
      char at[64];
      char beyond[64];
      if (key.kind == ConfigKind::kWhole) {
        const auto whole = static_cast<long long>(bound);
        const long long step = upper ? key.multiple_of : -static_cast<long long>(key.multiple_of);
        std::snprintf(at, sizeof at, "%lld", whole);
        std::snprintf(beyond, sizeof beyond, "%lld", whole + step);
      } else {
        std::snprintf(at, sizeof at, "%.17g", bound);
        std::snprintf(beyond, sizeof beyond, "%.17g", upper ? bound + 0.5 : bound - 0.5);
      }
      const std::string head = std::string("[") + key.table + "]\n" + key.name + " = ";
      Rpi4Keys k;
      char error[320] = "";
      const bool accepted =
          apply_config_text(head + at + "\n", "bound.conf", k.schema, error, sizeof error);
      CHECK_TRUE_TEXT(accepted, (head + at + ": " + error).c_str());
      Rpi4Keys fresh;
      const BoardConfig before = fresh.config;
      CHECK_FALSE_TEXT(
          apply_config_text(head + beyond + "\n", "bound.conf", fresh.schema, error, sizeof error),
          (head + beyond).c_str());
      const std::string message = error;
      const std::string said = std::string(key.table) + "." + key.name + " = ";
      CHECK_TEXT(message.rfind("bound.conf:2: " + said, 0) == 0, message.c_str());
      STRCMP_CONTAINS(" is out of range (", error);
      CHECK_TEXT(same_config(before, fresh.config), (head + beyond).c_str());
      ++checked;
    }
  }
  CHECK(checked >= 40);
}

// The camera's height has its own limit: the low-resolution frame's 240 rows times 4, less
// than the width's 1280 (a height between the two is refused at start, not at the first frame).
TEST(ConfigFile, ACameraHeightAboveItsMaximumIsRefusedEvenWhenBelowTheWidthsMaximum) {
  Rpi4Keys k;
  char error[320] = "";
  CHECK_TRUE_TEXT(
      apply_config_text("[camera]\nheight_px = 960\n", "h.conf", k.schema, error, sizeof error),
      error);
  CHECK_EQUAL(960U, k.config.camera_height_px);
  Rpi4Keys fresh;
  CHECK_FALSE(apply_config_text("[camera]\nheight_px = 1000\n", "h.conf", fresh.schema, error,
                                sizeof error));
  STRCMP_EQUAL("h.conf:2: camera.height_px = 1000 is out of range (120 to 960)", error);
  CHECK_EQUAL(480U, fresh.config.camera_height_px);
}

// A text key holds its value and the NUL after it: 63 bytes fit the 64-byte array, 64 do not.
TEST(ConfigFile, ATextKeyOfExactlyItsCapacityIsRefusedAndOneByteLessIsAccepted) {
  const Rpi4Keys keys;
  std::size_t checked = 0;
  for (std::size_t i = 0; i < keys.schema.size(); ++i) {
    const ConfigKey& key = keys.schema[i];
    if (key.kind != ConfigKind::kPath && key.kind != ConfigKind::kName) continue;
    const std::size_t capacity = std::tuple_size_v<DeviceName>;
    const std::string lead = key.kind == ConfigKind::kPath ? "/" : "d";
    const std::string fits = lead + std::string(capacity - 2, 'd');
    const std::string full = lead + std::string(capacity - 1, 'd');
    const std::string head = std::string("[") + key.table + "]\n" + key.name + " = \"";
    Rpi4Keys k;
    char error[320] = "";
    CHECK_TRUE_TEXT(
        apply_config_text(head + fits + "\"\n", "t.conf", k.schema, error, sizeof error), error);
    STRCMP_EQUAL(fits.c_str(), key_text(k.schema, key).data());
    Rpi4Keys fresh;
    const std::string was = key_text(fresh.schema, key).data();
    CHECK_FALSE_TEXT(
        apply_config_text(head + full + "\"\n", "t.conf", fresh.schema, error, sizeof error),
        key.name);
    const std::string why =
        std::string("t.conf:2: ") + key.table + "." + key.name + " must be 1 to 63 bytes long";
    STRCMP_EQUAL(why.c_str(), error);
    STRCMP_EQUAL(was.c_str(), key_text(fresh.schema, key).data());
    ++checked;
  }
  CHECK(checked >= 3);
}

TEST(ConfigFile, EveryStandardBaudRateIsAcceptedAndTheRatesBesideItAreNot) {
  const std::uint32_t rates[] = {1200,  2400,   4800,   9600,   19200,  38400,
                                 57600, 115200, 230400, 460800, 500000, 921600};
  for (const std::uint32_t rate : rates) {
    Rpi4Keys k;
    char error[320] = "";
    const std::string line = "[console]\nbaud = " + std::to_string(rate) + "\n";
    CHECK_TRUE_TEXT(apply_config_text(line, "b.conf", k.schema, error, sizeof error), error);
    CHECK_EQUAL(rate, k.config.console_baud);
    for (const std::uint32_t beside : {rate - 1, rate + 1}) {
      const std::string bad = "[console]\nbaud = " + std::to_string(beside) + "\n";
      CHECK_FALSE(apply_config_text(bad, "b.conf", k.schema, error, sizeof error));
      STRCMP_CONTAINS("is not a standard baud rate", error);
    }
  }
}

TEST(ConfigFile, AnInterfaceNameTakesLettersDigitsUnderscoreDashAndDotAndNothingElse) {
  {
    Rpi4Keys k;
    char error[320] = "";
    CHECK_TRUE_TEXT(apply_config_text("[base]\ncan_interface = \"azAZ09_-.\"\n", "n.conf", k.schema,
                                      error, sizeof error),
                    error);
    STRCMP_EQUAL("azAZ09_-.", k.devices.can_interface.data());
  }
  // The characters just outside each accepted range, and a few others.
  for (const char c : std::string("`{@[/:~!+")) {
    Rpi4Keys k;
    char error[320] = "";
    const std::string text = std::string("[base]\ncan_interface = \"can") + c + "\"\n";
    CHECK_FALSE_TEXT(apply_config_text(text, "n.conf", k.schema, error, sizeof error),
                     text.c_str());
    STRCMP_CONTAINS("may hold only letters, digits", error);
  }
}

TEST(ConfigFile, ADevicePathTakesPrintableAsciiFromTheExclamationMarkToTheTilde) {
  Rpi4Keys k;
  char error[320] = "";
  CHECK_TRUE_TEXT(apply_config_text("[camera]\ndevice = \"/dev/!~\"\n", "p.conf", k.schema, error,
                                    sizeof error),
                  error);
  STRCMP_EQUAL("/dev/!~", k.devices.camera_device.data());
  for (const char* bad : {"/dev/a b", "/dev/a\\u007F", "/dev/a\\t"}) {
    const std::string text = std::string("[camera]\ndevice = \"") + bad + "\"\n";
    CHECK_FALSE_TEXT(apply_config_text(text, "p.conf", k.schema, error, sizeof error), bad);
    STRCMP_CONTAINS("must be printable ASCII without spaces", error);
  }
}

TEST(ConfigFile, AReasonLongerThanTheErrorBufferIsCutInsideIt) {
  Rpi4Keys k;
  for (const std::size_t size : {std::size_t{30}, std::size_t{6}}) {
    std::array<char, 64> buffer{};
    buffer.fill('#');
    CHECK_FALSE(apply_config_text("[camera]\nwidth_px = 2000\n", "long-file-name.conf", k.schema,
                                  buffer.data(), size));
    CHECK_EQUAL(size - 1, std::strlen(buffer.data()));
    for (std::size_t i = size; i < buffer.size(); ++i) CHECK_EQUAL('#', buffer[i]);
  }
}

// The watchdog's timeout stays where a hang restarts the service before the board resets
// (docs/flashing.md, "Watchdogs"), and 0 no longer switches it off: only `enabled = false`.
TEST(ConfigFile, TheWatchdogTimeoutIsBoundedByTheRestartChainAndOnlyAKeySwitchesItOff) {
  struct Case {
    const char* line;
    const char* why;  // nullptr: accepted
  };
  const Case cases[] = {
      {"timeout_ms = 9999",
       "watchdog.timeout_ms = 9999 is out of range (10000 to 15000): shorter, the hardware "
       "watchdog would reset the board before systemd restarts a hung firmware (to switch the "
       "watchdog off: enabled = false)"},
      {"timeout_ms = 0", "watchdog.timeout_ms = 0 is out of range (10000 to 15000): shorter"},
      {"timeout_ms = 1", "watchdog.timeout_ms = 1 is out of range (10000 to 15000): shorter"},
      {"timeout_ms = 15001",
       "watchdog.timeout_ms = 15001 is out of range (10000 to 15000): longer than the board's "
       "watchdog can count"},
      {"timeout_ms = 60000", "is out of range (10000 to 15000): longer"},
      {"enabled = 0", "watchdog.enabled must be true or false"},
      {"timeout_ms = 10000", nullptr},
      {"timeout_ms = 15000", nullptr},
  };
  for (const Case& c : cases) {
    Rpi4Keys k;
    char error[320] = "";
    const std::string text = std::string("[watchdog]\n") + c.line + "\n";
    const bool ok = apply_config_text(text, "w.conf", k.schema, error, sizeof error);
    if (c.why == nullptr) {
      CHECK_TRUE_TEXT(ok, error);
    } else {
      CHECK_FALSE_TEXT(ok, c.line);
      STRCMP_CONTAINS(c.why, error);
      CHECK_EQUAL(12000U, k.config.watchdog_timeout_ms);
    }
  }
  Rpi4Keys k;
  char error[320] = "";
  CHECK(k.config.watchdog_enabled);
  CHECK_TEXT(
      apply_config_text("[watchdog]\nenabled = false\n", "w.conf", k.schema, error, sizeof error),
      error);
  CHECK_FALSE(k.config.watchdog_enabled);
  CHECK_EQUAL(12000U, k.config.watchdog_timeout_ms);
}

// toml++ 3.3.0 reaches undefined behaviour on some non-ASCII code points (fuzz_config_file
// found U+FEBF); such bytes never get to it.
TEST(ConfigFile, ANonAsciiByteIsRefusedWithItsLineBeforeTheTomlLibrarySeesIt) {
  Rpi4Keys k;
  char error[320] = "";
  CHECK_FALSE(apply_config_text("[camera]\n# \xef\xba\xbf\nwidth_px = 640\n", "u.conf", k.schema,
                                error, sizeof error));
  STRCMP_EQUAL("u.conf:2: non-ASCII byte 0xEF (the file must be ASCII)", error);
  float gain = 0.0F;
  ParameterTable table;
  CHECK(table.add({"gain", &gain, 0.0F, 1.0F, false, ""}));
  CHECK(apply_parameters_text("gain = 1 \xef\xba\xbf\n", "p.conf", table, error, sizeof error,
                              nullptr, nullptr) == ConfigLoad::kInvalid);
  STRCMP_EQUAL("p.conf:1: non-ASCII byte 0xEF (the file must be ASCII)", error);
}

TEST(ConfigFile, KeysOutsideATableAndTablesGivenAsValuesAreRejected) {
  Rpi4Keys k;
  char error[320] = "";
  CHECK_FALSE(apply_config_text("\nwidth_px = 640\n", "x.conf", k.schema, error, sizeof error));
  STRCMP_EQUAL("x.conf:2: unknown key 'width_px' (keys belong in a [table])", error);
  CHECK_FALSE(apply_config_text("camera = 5\n", "x.conf", k.schema, error, sizeof error));
  STRCMP_EQUAL("x.conf:1: 'camera' must be a table", error);
}

TEST(ConfigFile, AMissingFileIsReportedAsMissingAndAnUnreadableOneAsInvalid) {
  Rpi4Keys k;
  char error[320] = "";
  CHECK(load_config_file("/nonexistent/boticelli.conf", k.schema, error, sizeof error) ==
        ConfigLoad::kMissing);
  STRCMP_CONTAINS("/nonexistent/boticelli.conf: No such file", error);
  const std::string dir = temp_dir("config");
  // A directory cannot be read as a file.
  CHECK(load_config_file(dir.c_str(), k.schema, error, sizeof error) == ConfigLoad::kInvalid);
  write_file(dir + "/boticelli.conf", "[robot]\nradius_m = 0.3\n");
  CHECK(load_config_file((dir + "/boticelli.conf").c_str(), k.schema, error, sizeof error) ==
        ConfigLoad::kLoaded);
  DOUBLES_EQUAL(0.3, static_cast<double>(k.config.robot_radius_m), 1e-7);
  remove_dir(dir);
}

// A file of up to 64 KiB is read (comments count too); a longer one is refused whole.
TEST(ConfigFile, AFileOfUpTo64KiBIsReadAndALongerOneIsRefused) {
  const std::string dir = temp_dir("config");
  const std::string path = dir + "/boticelli.conf";
  const std::string key = "[robot]\nradius_m = 0.3\n";
  std::string text = key;
  while (text.size() + 64 <= 64 * 1024) text += "# " + std::string(61, 'c') + "\n";
  text += std::string(64 * 1024 - text.size() - 1, '#') + "\n";
  CHECK_EQUAL(64U * 1024U, text.size());
  write_file(path, text);
  Rpi4Keys k;
  char error[320] = "";
  CHECK_TRUE_TEXT(
      load_config_file(path.c_str(), k.schema, error, sizeof error) == ConfigLoad::kLoaded, error);
  DOUBLES_EQUAL(0.3, static_cast<double>(k.config.robot_radius_m), 1e-7);
  write_file(path, text + "\n");
  Rpi4Keys fresh;
  const ConfigLoad longer = load_config_file(path.c_str(), fresh.schema, error, sizeof error);
  remove_dir(dir);
  CHECK(longer == ConfigLoad::kInvalid);
  STRCMP_EQUAL((path + ": larger than 64 KiB").c_str(), error);
}

// The shipped conffile names every key exactly once, commented out with the compiled-in
// default: uncommented, it parses and changes nothing.
TEST(ConfigFile, TheShippedConffileDocumentsEveryKeyWithItsDefault) {
  const std::string shipped =
      read_file(BOTICELLI_SOURCE_DIR "/boards/rpi4/packaging/boticelli.conf");
  CHECK(!shipped.empty());
  std::istringstream in(shipped);
  std::string line;
  std::string uncommented;
  std::string table;
  std::map<std::string, int> seen;
  const std::regex key_line("^#([a-z0-9_]+) = (.*)$");
  std::smatch m;
  while (std::getline(in, line)) {
    if (!line.empty() && line[0] == '[') table = line.substr(1, line.size() - 2);
    if (std::regex_match(line, m, key_line)) {
      ++seen[table + "." + m[1].str()];
      uncommented += line.substr(1) + "\n";
    } else {
      uncommented += line + "\n";
    }
  }
  Rpi4Keys k;
  const BoardConfig defaults = k.config;
  const rpi4::Rpi4Devices device_defaults = k.devices;
  char error[320] = "";
  CHECK_TEXT(apply_config_text(uncommented, "boticelli.conf", k.schema, error, sizeof error),
             error);
  // Copies compared bytewise: the parser stores field by field, so padding stays as it was.
  CHECK(same_config(defaults, k.config));
  CHECK(std::memcmp(&device_defaults, &k.devices, sizeof device_defaults) == 0);
  for (std::size_t i = 0; i < k.schema.size(); ++i) {
    const std::string name = std::string(k.schema[i].table) + "." + k.schema[i].name;
    CHECK_EQUAL_TEXT(1, seen[name], name.c_str());
  }
  CHECK_EQUAL(k.schema.size(), seen.size());
}

// docs/configuration.md's table of keys gives each number key's range (and a width's or
// height's multiple): the schema checks exactly those, so neither can drift from the other.
TEST(ConfigFile, EveryRangeTheConfigurationDocGivesIsTheOneItsKeyChecks) {
  const Rpi4Keys k;
  std::istringstream doc(read_file(BOTICELLI_SOURCE_DIR "/docs/configuration.md"));
  const std::regex row(R"(^\| (`[^|]+`) \| (c|rpi4) \| [^|]* \| ([^|]+) \|$)");
  const std::regex key_name("`([a-z_0-9.]+)`");
  const std::regex range("(-?[0-9.]+) … (-?[0-9.]+)");
  const std::regex multiple("multiple of ([0-9]+)");
  std::size_t checked = 0;
  std::string line;
  while (std::getline(doc, line)) {
    std::smatch m;
    if (!std::regex_match(line, m, row)) continue;
    const std::string names = m[1].str();
    const std::string cell = m[3].str();
    if (cell.rfind("the board's range", 0) == 0) continue;  // watchdog.timeout_ms: per board
    std::vector<std::pair<double, double>> ranges;
    for (std::sregex_iterator r(cell.begin(), cell.end(), range), end; r != end; ++r) {
      ranges.emplace_back(std::stod((*r)[1].str()), std::stod((*r)[2].str()));
    }
    if (ranges.empty()) continue;
    std::smatch mult;
    const bool has_multiple = std::regex_search(cell, mult, multiple);
    std::string table;
    std::size_t i = 0;
    for (std::sregex_iterator n(names.begin(), names.end(), key_name), end; n != end; ++n, ++i) {
      std::string name = (*n)[1].str();
      const std::size_t dot = name.find('.');
      if (dot != std::string::npos) {
        table = name.substr(0, dot);
        name = name.substr(dot + 1);
      }
      const ConfigKey* key = k.schema.find(table, name);
      const std::string what = table + "." + name;
      CHECK_TEXT(key != nullptr, what.c_str());
      const auto& [lo, hi] = ranges[ranges.size() == 1 ? 0 : i];
      DOUBLES_EQUAL_TEXT(lo, key->min, 0.0, what.c_str());
      DOUBLES_EQUAL_TEXT(hi, key->max, 0.0, what.c_str());
      if (key->kind == ConfigKind::kWhole) {
        const unsigned expected =
            has_multiple ? static_cast<unsigned>(std::stoul(mult[1].str())) : 1U;
        CHECK_EQUAL_TEXT(expected, std::max(1U, static_cast<unsigned>(key->multiple_of)),
                         what.c_str());
      }
      ++checked;
    }
  }
  CHECK(checked >= 28U);  // every number key of both tables
}

// A table named by an empty quoted key is unknown like any other (no key has an empty table).
TEST(ConfigFile, ATableWithAnEmptyNameIsUnknown) {
  Rpi4Keys k;
  char error[320] = "";
  CHECK_FALSE(apply_config_text("[\"\"]\nx = 1\n", "e.conf", k.schema, error, sizeof error));
  STRCMP_EQUAL("e.conf:1: unknown table ''", error);
}

TEST(ConfigFile, TheSchemaRefusesATakenKey) {
  ConfigSchema schema;
  std::uint32_t a = 0;
  CHECK(schema.add(ConfigKey::whole("t", "a", a, 0, 10)));
  CHECK_FALSE(schema.add(ConfigKey::whole("t", "a", a, 0, 10)));
  CHECK(schema.add(ConfigKey::whole("u", "a", a, 0, 10)));
}

TEST_GROUP(SavedParameters) {
  float rate = 10.0F;
  float gain = 0.5F;
  float mode = 1.0F;
  ParameterTable table;
  std::vector<std::string> warnings;
  void setup() override {
    CHECK(table.add({"rate_hz", &rate, 0.0F, 100.0F, false, "a rate [Hz]"}));
    CHECK(table.add({"gain", &gain, -1.0F, 1.0F, false, "a gain [1]"}));
    CHECK(table.add({"mode", &mode, 0.0F, 3.0F, true, "a mode"}));
  }
  static void warn(const char* message, void* context) {
    static_cast<std::vector<std::string>*>(context)->push_back(message);
  }
};

// A double beyond a float's range would become infinite as a float: it is out of range, not
// "not a finite number" (which only inf and nan in the file are).
TEST(SavedParameters, AValueBeyondTheFloatRangeIsOutOfRangeAndTheDefaultKept) {
  char error[320] = "";
  CHECK(apply_parameters_text("gain = 1e39\n", "p.conf", table, error, sizeof error, warn,
                              &warnings) == ConfigLoad::kLoaded);
  CHECK_EQUAL(1U, warnings.size());
  STRCMP_EQUAL("p.conf:1: gain: value out of range; default kept", warnings[0].c_str());
  CHECK(gain == 0.5F);
}

TEST(SavedParameters, OnlyTheChangedValuesAreWrittenAndTheyReadBackExactly) {
  char text[ParameterTable::kMaxFileBytes];
  CHECK_EQUAL(0U, table.changed_count());
  CHECK(table.set("gain", 0.1F) == nullptr);  // not exact in binary: %.9g must keep it
  CHECK(table.set("mode", 3.0F) == nullptr);
  CHECK_EQUAL(2U, table.changed_count());
  const std::size_t n = table.encode_changed(text, sizeof text);
  CHECK(n > 0);
  const std::string file(text, n);
  STRCMP_CONTAINS("gain = 0.100000001\n", file.c_str());
  STRCMP_CONTAINS("mode = 3\n", file.c_str());
  CHECK(file.find("rate_hz") == std::string::npos);

  // A fresh start: the same table with its defaults, then the file.
  gain = 0.5F;
  mode = 1.0F;
  ParameterTable fresh;
  CHECK(fresh.add({"rate_hz", &rate, 0.0F, 100.0F, false, ""}));
  CHECK(fresh.add({"gain", &gain, -1.0F, 1.0F, false, ""}));
  CHECK(fresh.add({"mode", &mode, 0.0F, 3.0F, true, ""}));
  char error[320] = "";
  CHECK(apply_parameters_text(file, "p.conf", fresh, error, sizeof error, warn, &warnings) ==
        ConfigLoad::kLoaded);
  CHECK(warnings.empty());
  CHECK(gain == 0.1F);
  CHECK(mode == 3.0F);
  CHECK(rate == 10.0F);
  // The loaded values differ from the defaults: they are what `param show` lists.
  CHECK_EQUAL(2U, fresh.changed_count());
  CHECK(fresh.default_value(1) == 0.5F);
}

TEST(SavedParameters, AnEncodingThatDoesNotFitIsRefusedWhole) {
  CHECK(table.set("gain", 0.25F) == nullptr);
  char text[64];
  CHECK_EQUAL(0U, table.encode_changed(text, sizeof text));
}

TEST(SavedParameters, UnknownNamesAndRefusedValuesAreSkippedWithTheirLine) {
  char error[320] = "";
  const std::string file = "gain = 0.25\nspeed = 3\nmode = 2.5\nrate_hz = 1e9\nmode = 2\n";
  // A duplicate key is a TOML error; without it:
  const std::string text = "gain = 0.25\nspeed = 3\nmode = 2.5\nrate_hz = 1e9\nlabel = \"x\"\n";
  CHECK(apply_parameters_text(file, "p.conf", table, error, sizeof error, warn, &warnings) ==
        ConfigLoad::kInvalid);
  STRCMP_CONTAINS("p.conf:5: ", error);
  CHECK(gain == 0.5F);  // a file that is not TOML sets nothing
  CHECK(apply_parameters_text(text, "p.conf", table, error, sizeof error, warn, &warnings) ==
        ConfigLoad::kLoaded);
  CHECK(gain == 0.25F);
  CHECK(mode == 1.0F);
  CHECK(rate == 10.0F);
  CHECK_EQUAL(4U, warnings.size());
  STRCMP_EQUAL("p.conf:2: speed: unknown parameter; default kept", warnings[0].c_str());
  STRCMP_EQUAL("p.conf:3: mode: value must be a whole number; default kept", warnings[1].c_str());
  STRCMP_EQUAL("p.conf:4: rate_hz: value out of range; default kept", warnings[2].c_str());
  STRCMP_EQUAL("p.conf:5: label: not a number; default kept", warnings[3].c_str());
}

TEST(SavedParameters, ARoundTripThroughTheStateDirectoryKeepsEveryChangedValue) {
  const std::string dir = temp_dir("config");
  static StateStore store;
  char error[320] = "";
  CHECK(store.open(dir.c_str(), error, sizeof error));
  StateSaver saver(store);
  CHECK(table.set("rate_hz", 12.5F) == nullptr);
  char text[ParameterTable::kMaxFileBytes];
  const std::size_t n = table.encode_changed(text, sizeof text);
  CHECK(saver.submit_parameters({text, n}) == StateSaver::Submitted::kSaved);
  CHECK_EQUAL(1U, saver.parameter_saves());
  rate = 10.0F;
  CHECK(load_parameters_file(store.parameters_path(), table, error, sizeof error, warn,
                             &warnings) == ConfigLoad::kLoaded);
  CHECK(rate == 12.5F);
  remove_dir(dir);
  // Gone directory: the failure is counted and its reason kept.
  CHECK(saver.submit_parameters({text, n}) == StateSaver::Submitted::kFailed);
  CHECK_EQUAL(1U, saver.parameter_failures());
  CHECK(saver.parameter_error(error, sizeof error));
  STRCMP_CONTAINS("cannot create", error);
}

// A parameters text longer than a parameters file may be is refused as too long, with or
// without the writer thread, and nothing is written or counted.
TEST(SavedParameters, ATextLongerThanAParametersFileIsRefusedAndNothingIsWritten) {
  const std::string dir = temp_dir("config");
  static StateStore store;
  char error[320] = "";
  CHECK(store.open(dir.c_str(), error, sizeof error));
  const std::string longer(ParameterTable::kMaxFileBytes + 1, '#');
  {
    StateSaver saver(store);
    CHECK(saver.submit_parameters(longer) == StateSaver::Submitted::kTooLong);
    CHECK_EQUAL(0U, saver.parameter_saves());
    CHECK_EQUAL(0U, saver.parameter_failures());
  }
#ifndef BOTICELLI_TESTS_UNDER_EMULATOR
  {
    StateSaver saver(store);
    saver.start();
    CHECK(saver.submit_parameters(longer) == StateSaver::Submitted::kTooLong);
    saver.flush();
    CHECK_EQUAL(0U, saver.parameter_saves());
  }
#endif
  std::FILE* f = std::fopen((dir + "/parameters.conf").c_str(), "r");
  CHECK(f == nullptr);
  if (f != nullptr) std::fclose(f);
  // A text of exactly the file's size is taken.
  const std::string full(ParameterTable::kMaxFileBytes, '#');
  StateSaver saver(store);
  CHECK(saver.submit_parameters(full) == StateSaver::Submitted::kSaved);
  remove_dir(dir);
}

#ifndef BOTICELLI_TESTS_UNDER_EMULATOR
TEST(SavedParameters, TheWriterThreadSavesWhatTheConsoleHandsItWithoutBlockingIt) {
  const std::string dir = temp_dir("config");
  static StateStore store;
  char error[320] = "";
  CHECK(store.open(dir.c_str(), error, sizeof error));
  StateSaver saver(store);
  saver.start();
  CHECK(saver.submit_parameters("gain = 0.75\n") == StateSaver::Submitted::kQueued);
  saver.flush();
  CHECK_EQUAL(1U, saver.parameter_saves());
  STRCMP_EQUAL("gain = 0.75\n", read_file(dir + "/parameters.conf").c_str());
  remove_dir(dir);
}
#endif

TEST_GROUP(AtomicWrite) {
  std::string dir;
  void setup() override {
    dir = temp_dir("config");
  }
  void teardown() override {
    remove_dir(dir);
  }
};

namespace {
struct Crash {
  SaveStep at;
  int chunk = 0;  // for kChunkWritten: which one
  int seen = 0;
};
bool crash_at(SaveStep step, void* context) {
  auto* c = static_cast<Crash*>(context);
  if (step != c->at) return false;
  return c->seen++ == c->chunk;
}
}  // namespace

TEST(AtomicWrite, AWriteCutShortAtAnyStepLeavesTheOldFileWholeUntilTheRename) {
  char error[320] = "";
  const std::string old_text(3 * kAtomicWriteChunkBytes + 17, 'o');
  const std::string new_text(2 * kAtomicWriteChunkBytes + 5, 'n');
  const Crash crashes[] = {{SaveStep::kTempCreated},     {SaveStep::kChunkWritten, 0},
                           {SaveStep::kChunkWritten, 1}, {SaveStep::kChunkWritten, 2},
                           {SaveStep::kTempSynced},      {SaveStep::kRenamed}};
  for (Crash c : crashes) {
    CHECK(write_file_atomically(dir.c_str(), "a.txt", old_text, error, sizeof error));
    CHECK_FALSE(
        write_file_atomically(dir.c_str(), "a.txt", new_text, error, sizeof error, crash_at, &c));
    STRCMP_EQUAL("save interrupted (test crash hook)", error);
    const std::string now = read_file(dir + "/a.txt");
    if (c.at == SaveStep::kRenamed) {
      CHECK(now == new_text);
    } else {
      CHECK(now == old_text);
    }
  }
  // And a write that is not cut short replaces it, leaving no temporary file.
  CHECK(write_file_atomically(dir.c_str(), "a.txt", new_text, error, sizeof error));
  CHECK(read_file(dir + "/a.txt") == new_text);
  CHECK(access((dir + "/a.txt.tmp").c_str(), F_OK) != 0);
}

TEST(AtomicWrite, TheStateStoreSavesItsParametersTheSameWay) {
  static StateStore store;
  char error[320] = "";
  CHECK(store.open(dir.c_str(), error, sizeof error));
  CHECK(store.save_parameters("gain = 1\n", error, sizeof error));
  Crash c{SaveStep::kTempSynced};
  store.set_crash_hook(crash_at, &c);
  CHECK_FALSE(store.save_parameters("gain = 2\n", error, sizeof error));
  store.set_crash_hook(nullptr, nullptr);
  STRCMP_EQUAL("gain = 1\n", read_file(dir + "/parameters.conf").c_str());
}

namespace {
// The process's open file descriptors.
int open_descriptors() {
  DIR* d = opendir("/proc/self/fd");
  CHECK(d != nullptr);
  int n = 0;
  while (readdir(d) != nullptr) ++n;
  closedir(d);
  return n;
}
// Fails every call of one kind with EIO.
int fail_call(StorageCall call, void* context) {
  return call == *static_cast<StorageCall*>(context) ? EIO : 0;
}
}  // namespace

TEST(AtomicWrite, AWriteCutShortOrFailedClosesWhatItOpenedAndAFailureLeavesNoTemporaryFile) {
  char error[320] = "";
  const std::string text(2 * kAtomicWriteChunkBytes + 5, 'n');
  const int before = open_descriptors();
  for (Crash c : {Crash{SaveStep::kTempCreated}, Crash{SaveStep::kChunkWritten, 1},
                  Crash{SaveStep::kTempSynced}}) {
    CHECK_FALSE(
        write_file_atomically(dir.c_str(), "a.txt", text, error, sizeof error, crash_at, &c));
    CHECK_EQUAL(before, open_descriptors());
  }
  for (StorageCall call : {StorageCall::kWrite, StorageCall::kSync, StorageCall::kCreate,
                           StorageCall::kSyncDirectory}) {
    set_storage_fault_hook(fail_call, &call);
    CHECK_FALSE(write_file_atomically(dir.c_str(), "a.txt", text, error, sizeof error));
    set_storage_fault_hook(nullptr, nullptr);
    const std::string step = call == StorageCall::kCreate  ? "cannot create " + dir + "/a.txt.tmp"
                             : call == StorageCall::kWrite ? "cannot write " + dir + "/a.txt.tmp"
                             : call == StorageCall::kSync  ? "cannot sync " + dir + "/a.txt.tmp"
                                                           : "cannot sync directory " + dir;
    STRCMP_EQUAL((step + ": " + std::strerror(EIO)).c_str(), error);
    CHECK_EQUAL(before, open_descriptors());
    CHECK(access((dir + "/a.txt.tmp").c_str(), F_OK) != 0);
  }
}

// A rename that fails (a directory where the file goes) fails the save with the path, and
// removes the temporary file; what stood at the name is untouched.
TEST(AtomicWrite, ARenameThatFailsFailsTheSaveAndLeavesNoTemporaryFile) {
  const std::string target = dir + "/a.txt";
  CHECK_EQUAL(0, ::mkdir(target.c_str(), 0750));
  write_file(target + "/inside", "kept\n");
  char error[320] = "";
  const int before = open_descriptors();
  const bool written = write_file_atomically(dir.c_str(), "a.txt", "new\n", error, sizeof error);
  CHECK_FALSE(written);
  STRCMP_CONTAINS(("cannot rename onto " + target + ": ").c_str(), error);
  CHECK_EQUAL(before, open_descriptors());
  CHECK(access((target + ".tmp").c_str(), F_OK) != 0);
  STRCMP_EQUAL("kept\n", read_file(target + "/inside").c_str());
  ::unlink((target + "/inside").c_str());
  ::rmdir(target.c_str());
}

// write() itself failing partway through the data (the storage-fault hook fails the call before
// it runs): here past the process's file size limit (EFBIG), as a full disk refuses with
// ENOSPC. The first chunk is written whole, the second cut short and the rest refused; the save
// fails with the reason, the old file stays whole and no temporary file is left.
TEST(AtomicWrite, AWriteTheFileSystemRefusesPartwayFailsTheSaveAndKeepsTheOldFile) {
  char error[320] = "";
  const std::string old_text(100, 'o');
  const std::string new_text(3 * kAtomicWriteChunkBytes, 'n');
  CHECK(write_file_atomically(dir.c_str(), "a.txt", old_text, error, sizeof error));
  struct sigaction ignore {};
  ignore.sa_handler = SIG_IGN;
  sigemptyset(&ignore.sa_mask);
  struct sigaction old_action {};
  CHECK_EQUAL(0, ::sigaction(SIGXFSZ, &ignore, &old_action));
  rlimit saved{};
  CHECK_EQUAL(0, ::getrlimit(RLIMIT_FSIZE, &saved));
  rlimit small = saved;
  small.rlim_cur = kAtomicWriteChunkBytes + 100;
  CHECK_EQUAL(0, ::setrlimit(RLIMIT_FSIZE, &small));
  const bool written = write_file_atomically(dir.c_str(), "a.txt", new_text, error, sizeof error);
  ::setrlimit(RLIMIT_FSIZE, &saved);
  ::sigaction(SIGXFSZ, &old_action, nullptr);
  CHECK_FALSE(written);
  STRCMP_EQUAL(("cannot write " + dir + "/a.txt.tmp: " + std::strerror(EFBIG)).c_str(), error);
  CHECK(read_file(dir + "/a.txt") == old_text);
  CHECK(access((dir + "/a.txt.tmp").c_str(), F_OK) != 0);
}

TEST(AtomicWrite, TheFileIsReadableAndWritableByItsOwnerAndReadableByItsGroup) {
  char error[320] = "";
  const mode_t old_mask = umask(022);
  const bool written = write_file_atomically(dir.c_str(), "a.txt", "x", error, sizeof error);
  umask(old_mask);
  CHECK(written);
  struct stat st {};
  CHECK(stat((dir + "/a.txt").c_str(), &st) == 0);
  LONGS_EQUAL(0640, st.st_mode & 07777);
}

TEST(AtomicWrite, ATemporaryFileItCannotRemoveFailsTheSaveWithItsPath) {
  char error[320] = "";
  CHECK(write_file_atomically(dir.c_str(), "a.txt", "old", error, sizeof error));
  CHECK(mkdir((dir + "/a.txt.tmp").c_str(), 0700) == 0);  // unlink() fails on a directory
  const bool written = write_file_atomically(dir.c_str(), "a.txt", "new", error, sizeof error);
  rmdir((dir + "/a.txt.tmp").c_str());
  CHECK_FALSE(written);
  STRCMP_CONTAINS(("cannot remove the stale " + dir + "/a.txt.tmp").c_str(), error);
  STRCMP_EQUAL("old", read_file(dir + "/a.txt").c_str());
}

// The paths are built in 512-byte buffers: a temporary file's path of 511 bytes fits, one of
// 512 would be cut short and is refused.
TEST(AtomicWrite, ATemporaryPathThatJustFitsIsWrittenAndOneByteLongerIsRefused) {
  char error[600] = "";
  const std::string deep = dir + "/" + std::string(200, 'd');
  const std::string deeper = deep + "/" + std::string(200, 'e');
  CHECK(mkdir(deep.c_str(), 0700) == 0);
  CHECK(mkdir(deeper.c_str(), 0700) == 0);
  const std::size_t fits = 511 - deeper.size() - 1 - 4;  // "/" and ".tmp"
  const std::string name(fits, 'f');
  const std::string longer(fits + 1, 'f');
  const bool written =
      write_file_atomically(deeper.c_str(), name.c_str(), "x", error, sizeof error);
  const std::string text = read_file(deeper + "/" + name);
  const bool refused =
      !write_file_atomically(deeper.c_str(), longer.c_str(), "x", error, sizeof error);
  const bool longer_exists = access((deeper + "/" + longer).c_str(), F_OK) == 0;
  unlink((deeper + "/" + name).c_str());
  unlink((deeper + "/" + longer).c_str());
  unlink((deeper + "/" + longer + ".tm").c_str());  // what a cut path would name
  rmdir(deeper.c_str());
  rmdir(deep.c_str());
  CHECK(written);
  STRCMP_EQUAL("x", text.c_str());
  CHECK(refused);
  CHECK_FALSE(longer_exists);
  STRCMP_CONTAINS("path too long", error);
}

// A service started with its standard input closed gets descriptor 0 for the first file it
// opens: a temporary file on descriptor 0 is written like any other, and a directory opened on
// descriptor 0 to sync the rename is closed also when its sync fails.
TEST(AtomicWrite, WorkOnDescriptorZeroIsWrittenAndClosedLikeAnyOther) {
  for (const bool dir_sync_fails : {false, true}) {
    StorageCall call = StorageCall::kSyncDirectory;
    if (dir_sync_fails) set_storage_fault_hook(fail_call, &call);
    const int saved_stdin = ::dup(0);
    CHECK(saved_stdin >= 0);
    ::close(0);
    char error[320] = "";
    const bool written =
        write_file_atomically(dir.c_str(), "zero.txt", "on descriptor 0\n", error, sizeof error);
    const int probe = ::open("/dev/null", O_RDONLY | O_CLOEXEC);  // 0 again if it was closed
    ::dup2(saved_stdin, 0);
    ::close(saved_stdin);
    if (probe > 0) ::close(probe);
    set_storage_fault_hook(nullptr, nullptr);
    CHECK_EQUAL(0, probe);  // the save closed every descriptor it used
    CHECK_EQUAL(!dir_sync_fails, written);
    if (dir_sync_fails) STRCMP_CONTAINS("cannot sync directory", error);
    STRCMP_EQUAL("on descriptor 0\n", read_file(dir + "/zero.txt").c_str());
  }
}

TEST(AtomicWrite, AMissingDirectoryIsAnErrorWithItsPath) {
  char error[320] = "";
  CHECK_FALSE(write_file_atomically("/nonexistent-dir", "a.txt", "x", error, sizeof error));
  STRCMP_CONTAINS("cannot create /nonexistent-dir/a.txt.tmp", error);
}
