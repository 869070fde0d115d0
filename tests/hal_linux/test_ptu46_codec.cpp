// Tests of the PTU-D46 codec: every command the driver sends and every reply it accepts.
#include <cmath>
#include <cstdint>
#include <numbers>
#include <string>
#include <string_view>

#include "hal/codec/ptu46_codec.h"

#include "CppUTest/TestHarness.h"
#include "alloc_guard.h"

namespace ptu = boticelli::codec::ptu46;

namespace {

std::string query(ptu::Axis a, ptu::Query q) {
  char buf[ptu::kMaxCommandLength];
  return {buf, ptu::encode_query(a, q, buf, sizeof buf)};
}
std::string setting(ptu::Setting s) {
  char buf[ptu::kMaxCommandLength];
  return {buf, ptu::encode_setting(s, buf, sizeof buf)};
}

// Feeds a string; returns the completed lines joined with '|' ('#' marks a corrupt line).
std::string lines_of(ptu::LineAssembler& a, std::string_view bytes) {
  std::string out;
  for (char c : bytes) {
    if (a.push(c)) {
      if (!out.empty()) out += '|';
      if (a.line_corrupt()) out += '#';
      out += a.line();
    }
  }
  return out;
}

}  // namespace

TEST_GROUP(Ptu46Commands){};

TEST(Ptu46Commands, QueriesAreTwoLettersAndADelimiter) {
  STRCMP_EQUAL("PP ", query(ptu::Axis::kPan, ptu::Query::kPosition).c_str());
  STRCMP_EQUAL("TP ", query(ptu::Axis::kTilt, ptu::Query::kPosition).c_str());
  STRCMP_EQUAL("PR ", query(ptu::Axis::kPan, ptu::Query::kResolution).c_str());
  STRCMP_EQUAL("TR ", query(ptu::Axis::kTilt, ptu::Query::kResolution).c_str());
  STRCMP_EQUAL("PN ", query(ptu::Axis::kPan, ptu::Query::kMinPosition).c_str());
  STRCMP_EQUAL("PX ", query(ptu::Axis::kPan, ptu::Query::kMaxPosition).c_str());
  STRCMP_EQUAL("TN ", query(ptu::Axis::kTilt, ptu::Query::kMinPosition).c_str());
  STRCMP_EQUAL("TX ", query(ptu::Axis::kTilt, ptu::Query::kMaxPosition).c_str());
  STRCMP_EQUAL("PS ", query(ptu::Axis::kPan, ptu::Query::kSpeed).c_str());
  STRCMP_EQUAL("TU ", query(ptu::Axis::kTilt, ptu::Query::kMaxSpeed).c_str());
}

TEST(Ptu46Commands, SettingsAreTheirLettersAndADelimiter) {
  STRCMP_EQUAL("FT ", setting(ptu::Setting::kTerse).c_str());
  STRCMP_EQUAL("ED ", setting(ptu::Setting::kEchoOff).c_str());
  STRCMP_EQUAL("CI ", setting(ptu::Setting::kIndependentMode).c_str());
  STRCMP_EQUAL("A ", setting(ptu::Setting::kAwait).c_str());
  STRCMP_EQUAL("H ", setting(ptu::Setting::kHalt).c_str());
  STRCMP_EQUAL("R ", setting(ptu::Setting::kReset).c_str());
}

TEST(Ptu46Commands, PositionsAndSpeedsCarryASignedInteger) {
  char buf[ptu::kMaxCommandLength];
  std::size_t n = ptu::encode_position(ptu::Axis::kPan, -1234, buf, sizeof buf);
  STRCMP_EQUAL("PP-1234 ", std::string(buf, n).c_str());
  n = ptu::encode_position(ptu::Axis::kTilt, 0, buf, sizeof buf);
  STRCMP_EQUAL("TP0 ", std::string(buf, n).c_str());
  n = ptu::encode_position(ptu::Axis::kPan, INT32_MIN, buf, sizeof buf);
  STRCMP_EQUAL("PP-2147483648 ", std::string(buf, n).c_str());
  n = ptu::encode_speed(ptu::Axis::kTilt, 2902, buf, sizeof buf);
  STRCMP_EQUAL("TS2902 ", std::string(buf, n).c_str());
}

TEST(Ptu46Commands, AnEncoderRefusesATooSmallBuffer) {
  char buf[4] = {'x', 'x', 'x', 'x'};
  CHECK_EQUAL(0U, ptu::encode_position(ptu::Axis::kPan, 12345, buf, sizeof buf));
  CHECK_EQUAL(0U, ptu::encode_query(ptu::Axis::kPan, ptu::Query::kPosition, buf, 2));
  CHECK_EQUAL('x', buf[0]);
}

TEST_GROUP(Ptu46Replies){};

TEST(Ptu46Replies, AStarWithANumberIsAnOkWithValue) {
  const ptu::Reply r = ptu::parse_reply("* -1234");
  CHECK(r.kind == ptu::ReplyKind::kOk);
  CHECK_TRUE(r.has_value);
  DOUBLES_EQUAL(-1234.0, r.value, 0.0);
  CHECK_EQUAL(0U, r.skipped);
}

TEST(Ptu46Replies, TheResolutionIsADecimalNumber) {
  const ptu::Reply r = ptu::parse_reply("* 185.1428");
  CHECK_TRUE(r.has_value);
  DOUBLES_EQUAL(185.1428, r.value, 1e-9);
}

TEST(Ptu46Replies, ABareStarIsAnOkWithoutValue) {
  const ptu::Reply r = ptu::parse_reply("*");
  CHECK(r.kind == ptu::ReplyKind::kOk);
  CHECK_FALSE(r.has_value);
}

TEST(Ptu46Replies, AVerboseReplyIsAnOkWithoutAParsedValue) {
  const ptu::Reply r = ptu::parse_reply("* Current Pan position is 55");
  CHECK(r.kind == ptu::ReplyKind::kOk);
  CHECK_FALSE(r.has_value);
}

TEST(Ptu46Replies, EchoBeforeTheMarkerIsSkippedAndCounted) {
  const ptu::Reply r = ptu::parse_reply("PP * 10");
  CHECK(r.kind == ptu::ReplyKind::kOk);
  CHECK_EQUAL(3U, r.skipped);
  DOUBLES_EQUAL(10.0, r.value, 0.0);
}

TEST(Ptu46Replies, UnsolicitedLimitReportsNameTheAxis) {
  CHECK(ptu::parse_reply("!P").kind == ptu::ReplyKind::kLimitPan);
  CHECK(ptu::parse_reply("!T").kind == ptu::ReplyKind::kLimitTilt);
  CHECK(ptu::parse_reply("!T").error == ptu::ErrorKind::kLimit);
}

TEST(Ptu46Replies, ErrorMessagesAreClassified) {
  CHECK(ptu::parse_reply("! Illegal Command").error == ptu::ErrorKind::kIllegalCommand);
  CHECK(ptu::parse_reply("! Illegal Command Argument").error == ptu::ErrorKind::kIllegalArgument);
  CHECK(ptu::parse_reply("! Maximum allowable Pan position exceeded").error ==
        ptu::ErrorKind::kLimit);
  CHECK(ptu::parse_reply("! Tilt limit").error == ptu::ErrorKind::kLimit);
  const ptu::Reply r = ptu::parse_reply("! something odd");
  CHECK(r.kind == ptu::ReplyKind::kError);
  CHECK(r.error == ptu::ErrorKind::kOther);
  STRCMP_EQUAL("! something odd", std::string(r.text).c_str());
}

TEST(Ptu46Replies, ALineWithoutAMarkerIsGarbage) {
  CHECK(ptu::parse_reply("hello").kind == ptu::ReplyKind::kGarbage);
  CHECK(ptu::parse_reply("").kind == ptu::ReplyKind::kGarbage);
  CHECK(ptu::parse_reply("\x01\x02\xff").kind == ptu::ReplyKind::kGarbage);
}

TEST(Ptu46Replies, AMalformedNumberGivesNoValue) {
  CHECK_FALSE(ptu::parse_reply("* 12x").has_value);
  CHECK_FALSE(ptu::parse_reply("* -").has_value);
  CHECK_FALSE(ptu::parse_reply("* 1.2.3").has_value);
  CHECK_FALSE(ptu::parse_reply("* 12345678901234567").has_value);
}

TEST(Ptu46Replies, NumbersParseStrictly) {
  double v = 0;
  CHECK_TRUE(ptu::parse_number("+12", v));
  DOUBLES_EQUAL(12.0, v, 0.0);
  CHECK_FALSE(ptu::parse_number("", v));
  CHECK_FALSE(ptu::parse_number("+", v));
  CHECK_FALSE(ptu::parse_number(" 1", v));
  CHECK_TRUE(ptu::parse_number(".5", v));
  DOUBLES_EQUAL(0.5, v, 1e-12);
}

TEST(Ptu46Replies, ParsingDoesNotAllocate) {
  ptu::Reply r;
  CHECK_NO_ALLOCATION(r = ptu::parse_reply("* 185.1428"));
  CHECK_TRUE(r.has_value);
}

TEST_GROUP(Ptu46Lines){};

TEST(Ptu46Lines, CrLfEndsOneLineAndEmptyLinesAreDropped) {
  ptu::LineAssembler a;
  STRCMP_EQUAL("* 1|* 2", lines_of(a, "* 1\r\n\r\n* 2\n").c_str());
}

TEST(Ptu46Lines, ALineMaySpanManyPushes) {
  ptu::LineAssembler a;
  STRCMP_EQUAL("", lines_of(a, "* 12").c_str());
  STRCMP_EQUAL("* 1234", lines_of(a, "34\r\n").c_str());
}

TEST(Ptu46Lines, TheResetAnswerIsSplitIntoItsReports) {
  ptu::LineAssembler a;
  STRCMP_EQUAL("!T|!T|!P|!P|*", lines_of(a, "!T!T!P!P*\r\n").c_str());
}

TEST(Ptu46Lines, AnOverlongLineIsDiscardedAndCounted) {
  ptu::LineAssembler a;
  const std::string junk(ptu::kMaxLineLength + 20, 'x');
  STRCMP_EQUAL("* 5", lines_of(a, junk + "\r\n* 5\r\n").c_str());
  CHECK_EQUAL(1U, a.overflows());
}

TEST(Ptu46Lines, NonPrintableBytesMarkTheLineCorrupt) {
  ptu::LineAssembler a;
  STRCMP_EQUAL(std::string("#*\x01 5|* 6").c_str(), lines_of(a, "*\x01 5\n* 6\n").c_str());
}

TEST(Ptu46Lines, DelAndBytesWithTheHighBitSetMarkTheLineCorruptToo) {
  // Line noise at the wrong baud rate shows up as bytes above 0x7E as often as below 0x20.
  ptu::LineAssembler a;
  STRCMP_EQUAL(std::string("#* 5\x7f|#*\x80 6|#\xff*|* 7").c_str(),
               lines_of(a, "* 5\x7f\n*\x80 6\n\xff*\n* 7\n").c_str());
}

TEST(Ptu46Lines, ResetForgetsAHalfLine) {
  ptu::LineAssembler a;
  lines_of(a, "* 99");
  a.reset();
  STRCMP_EQUAL("* 1", lines_of(a, "* 1\n").c_str());
}

TEST_GROUP(Ptu46Units){};

TEST(Ptu46Units, CountsConvertWithTheArcSecondResolution) {
  // 3600 arc-seconds per count: one count is one degree.
  DOUBLES_EQUAL(std::numbers::pi / 180.0, ptu::counts_to_rad(1.0, 3600.0), 1e-12);
  std::int32_t c = 0;
  CHECK_TRUE(ptu::rad_to_counts(std::numbers::pi / 2.0, 185.1428, c));
  CHECK_EQUAL(1750, c);  // 90 deg * 3600 / 185.1428 = 1750.0
  CHECK_TRUE(ptu::rad_to_counts(-0.1, 46.2857, c));
  CHECK_EQUAL(-446, c);
}

TEST(Ptu46Units, ImpossibleConversionsAreRefused) {
  std::int32_t c = 7;
  CHECK_FALSE(ptu::rad_to_counts(1.0, 0.0, c));
  CHECK_FALSE(ptu::rad_to_counts(1.0, -5.0, c));
  CHECK_FALSE(ptu::rad_to_counts(NAN, 185.0, c));
  CHECK_FALSE(ptu::rad_to_counts(1e12, 1e-6, c));
  CHECK_EQUAL(7, c);
}
