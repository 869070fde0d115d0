// Tests of the firmware's command-line parsing.
#include <cstring>

#include "firmware/app/options.h"
#include "CppUTest/TestHarness.h"

using namespace boticelli::firmware;

TEST_GROUP(Options) {
  Options options;
};

TEST(Options, ReadsEveryDesignOption) {
  const char* argv[] = {"boticelli",    "--world",   "w.sdf",       "--seed", "42",
                        "--max-cycles", "7",         "--snapshots", "snap",   "--trace",
                        "t.csv",        "--console", "pty"};
  const ParseResult r = parse_options(13, argv, true, options);
  CHECK_TRUE_TEXT(r.ok, r.error);
  STRCMP_EQUAL("w.sdf", options.world_file);
  CHECK(options.seed == 42U);
  CHECK(options.max_cycles == 7U);
  STRCMP_EQUAL("snap", options.snapshots_dir);
  STRCMP_EQUAL("t.csv", options.trace_file);
  CHECK(options.console == ConsoleKind::kPty);
}

TEST(Options, TakesAMapPrefixAndRefusesAnEmptyOne) {
  const char* argv[] = {"boticelli", "--map", "out/end"};
  CHECK(parse_options(3, argv, false, options).ok);
  STRCMP_EQUAL("out/end", options.map_prefix);
  const char* empty[] = {"boticelli", "--map", ""};
  const ParseResult r = parse_options(3, empty, false, options);
  CHECK_FALSE(r.ok);
  STRCMP_EQUAL("option '--map' needs a PREFIX", r.error);
  const char* missing[] = {"boticelli", "--map"};
  CHECK_FALSE(parse_options(2, missing, false, options).ok);
}

TEST(Options, TakesASerialDeviceAsConsolePath) {
  const char* argv[] = {"boticelli", "--console", "/dev/ttyAMA0"};
  CHECK(parse_options(3, argv, false, options).ok);
  CHECK(options.console == ConsoleKind::kPath);
  STRCMP_EQUAL("/dev/ttyAMA0", options.console_path);
}

TEST(Options, RejectsAnUnknownOptionByName) {
  const char* argv[] = {"boticelli", "--fly"};
  const ParseResult r = parse_options(2, argv, true, options);
  CHECK_FALSE(r.ok);
  STRCMP_EQUAL("unknown option '--fly'", r.error);
}

TEST(Options, RejectsAMissingOrMalformedNumber) {
  const char* missing[] = {"boticelli", "--seed"};
  CHECK_FALSE(parse_options(2, missing, true, options).ok);
  const char* negative[] = {"boticelli", "--max-cycles", "-3"};
  CHECK_FALSE(parse_options(3, negative, true, options).ok);
  const char* trailing[] = {"boticelli", "--seed", "12x"};
  CHECK_FALSE(parse_options(3, trailing, true, options).ok);
  const char* huge[] = {"boticelli", "--seed", "99999999999999999999999"};
  CHECK_FALSE(parse_options(3, huge, true, options).ok);
}

TEST(Options, RefusesAWorldOnAHardwareBoard) {
  const char* argv[] = {"boticelli", "--world", "room.sdf"};
  const ParseResult r = parse_options(3, argv, false, options);
  CHECK_FALSE(r.ok);
  CHECK(std::strstr(r.error, "sim board") != nullptr);
}

TEST(Options, ResumeNeedsAStateDirectory) {
  const char* bare[] = {"boticelli", "--resume"};
  CHECK_FALSE(parse_options(2, bare, true, options).ok);
  const char* good[] = {"boticelli", "--state", "st", "--resume"};
  CHECK(parse_options(4, good, true, options).ok);
  CHECK(options.resume);
}

TEST(Options, TakesASpeedOnlyOnTheSimBoardAndOnlyFromZeroUp) {
  CHECK(options.speed == 0.0);  // as fast as possible unless asked
  const char* real_time[] = {"boticelli", "--speed", "1"};
  CHECK(parse_options(3, real_time, true, options).ok);
  DOUBLES_EQUAL(1.0, options.speed, 0.0);
  const char* slow[] = {"boticelli", "--speed", "0.25"};
  CHECK(parse_options(3, slow, true, options).ok);
  DOUBLES_EQUAL(0.25, options.speed, 0.0);
  for (const char* bad : {"-1", "", "x", "1e9", "inf", "nan", "0x2", "2s"}) {
    const char* argv[] = {"boticelli", "--speed", bad};
    const ParseResult r = parse_options(3, argv, true, options);
    CHECK_FALSE_TEXT(r.ok, bad);
    STRCMP_CONTAINS("'--speed' needs a number", r.error);
  }
  const ParseResult r = parse_options(3, real_time, false, options);
  CHECK_FALSE(r.ok);
  STRCMP_CONTAINS("sim board", r.error);
}

TEST(Options, TakesHostSlicesAndTheRobotsProcessSetUpOnlyOnTheSimBoard) {
  CHECK_FALSE(options.host_slices);
  CHECK_FALSE(options.realtime);
  const char* argv[] = {"boticelli", "--host-slices", "--realtime"};
  CHECK(parse_options(3, argv, true, options).ok);
  CHECK(options.host_slices);
  CHECK(options.realtime);
  const char* one[] = {"boticelli", "--realtime"};
  CHECK(parse_options(2, one, true, options).ok);
  CHECK_FALSE(options.host_slices);
  CHECK(options.realtime);
  for (const char* option : {"--host-slices", "--realtime"}) {
    const char* hardware[] = {"boticelli", option};
    const ParseResult r = parse_options(2, hardware, false, options);
    CHECK_FALSE_TEXT(r.ok, option);
    STRCMP_CONTAINS("is only for the sim board", r.error);
  }
}

TEST(Options, TakesAConfigFileAndRefusesAnEmptyOne) {
  const char* argv[] = {"boticelli", "--config", "/etc/robot2.conf"};
  CHECK(parse_options(3, argv, false, options).ok);
  STRCMP_EQUAL("/etc/robot2.conf", options.config_file);
  const char* empty[] = {"boticelli", "--config", ""};
  const ParseResult r = parse_options(3, empty, false, options);
  CHECK_FALSE(r.ok);
  STRCMP_EQUAL("option '--config' needs a FILE", r.error);
  const char* missing[] = {"boticelli", "--config"};
  CHECK_FALSE(parse_options(2, missing, false, options).ok);
  const char* none[] = {"boticelli"};
  CHECK(parse_options(1, none, false, options).ok);
  CHECK(options.config_file == nullptr);
}
