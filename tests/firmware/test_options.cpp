// Tests of the firmware's command-line parsing.
#include <cstring>

#include "firmware/options.h"
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
