// Tests of the fault plan: the file format's strict parser (FILE:LINE: why), its round trip,
// the applicable pairs, the seeded generator and the injector's timing.
#include <cstring>
#include <string>

#include "hal/sim/fault_injector.h"
#include "hal/sim/fault_plan.h"

#include "alloc_guard.h"
#include "CppUTest/TestHarness.h"

using namespace boticelli::hal::sim;

namespace {
FaultPlan g_plan;
FaultPlan g_other;
char g_error[256];

bool parse(const std::string& text) {
  g_error[0] = '\0';
  return parse_fault_plan(text, "plan.txt", g_plan, g_error, sizeof g_error);
}
}  // namespace

TEST_GROUP(FaultPlan){};

TEST(FaultPlan, ReadsTimesDevicesTypesAndOptionalDurationsWithComments) {
  CHECK_TEXT(parse("# a plan\n"
                   "10 camera off 5\n"
                   "\n"
                   "  12.5\tptu garbage 1.5   # a comment\r\n"
                   "30 axis-left off\n"),
             g_error);
  CHECK_EQUAL(3U, g_plan.size());
  CHECK(g_plan[0].device == FaultDevice::kCamera && g_plan[0].type == FaultType::kOff);
  CHECK_EQUAL(10000000U, g_plan[0].start_us);
  CHECK_EQUAL(5000000U, g_plan[0].duration_us);
  CHECK(g_plan[1].device == FaultDevice::kPtu && g_plan[1].type == FaultType::kGarbage);
  CHECK_EQUAL(12500000U, g_plan[1].start_us);
  CHECK_EQUAL(1500000U, g_plan[1].duration_us);
  CHECK_EQUAL(0U, g_plan[2].duration_us);  // until the end
  CHECK_EQUAL(UINT64_MAX, g_plan[2].end_us());
}

TEST(FaultPlan, EachKindOfBadLineIsReportedAsFileLineWhyAndLeavesThePlanEmpty) {
  const std::string long_line = "1 camera off #" + std::string(200, 'x') + "\n";
  const struct {
    const char* text;
    const char* error;
  } cases[] = {
      {"1 camera off\n2 toaster off\n", "plan.txt:2: unknown device"},
      {"1 camera melted\n", "plan.txt:1: unknown fault type"},
      {"1 estop garbage\n", "plan.txt:1: estop cannot be garbage"},
      {"1 camera\n", "plan.txt:1: expected AT_S DEVICE TYPE [DURATION_S]"},
      {"1 camera off 2 3 4\n", "plan.txt:1: too many words"},
      {"-1 camera off\n", "plan.txt:1: start time is not a number"},
      {"0x10 camera off\n", "plan.txt:1: start time is not a number"},
      {"nan camera off\n", "plan.txt:1: start time is not a number"},
      {"2e6 camera off\n", "plan.txt:1: start time is not a number of seconds in [0, 1e6]"},
      {"1 camera off 0\n", "plan.txt:1: duration is not a number"},
      {"1 camera off inf\n", "plan.txt:1: duration is not a number"},
      {"1 main-loop stuck\n", "plan.txt:1: a main-loop stall needs a duration"},
      {"1 main-loop stuck 61\n", "plan.txt:1: a main-loop stall is at most 60 s"},
      {"1 camera off\x01\n", "plan.txt:1: control or non-ASCII byte"},
      {"1 camera off \xc3\xa9\n", "plan.txt:1: control or non-ASCII byte"},
      {long_line.c_str(), "plan.txt:1: line longer than 160 bytes"},
  };
  for (const auto& c : cases) {
    CHECK_FALSE_TEXT(parse(c.text), c.text);
    STRCMP_CONTAINS(c.error, g_error);
    CHECK_EQUAL(0U, g_plan.size());
  }
}

TEST(FaultPlan, MoreFaultsThanItsCapacityAreRefusedWithTheLine) {
  std::string text;
  for (std::size_t i = 0; i <= FaultPlan::kMaxFaults; ++i) text += "1 camera off 1\n";
  CHECK_FALSE(parse(text));
  STRCMP_CONTAINS("plan.txt:257: more than 256 faults", g_error);
}

TEST(FaultPlan, AFileThatIsMissingOrTooLongIsRefused) {
  CHECK_FALSE(load_fault_plan("/nonexistent/plan.txt", g_plan, g_error, sizeof g_error));
  STRCMP_CONTAINS("/nonexistent/plan.txt: No such file or directory", g_error);
  CHECK_FALSE(parse(std::string(FaultPlan::kMaxFileBytes + 1, '#')));
  STRCMP_CONTAINS("plan.txt: longer than", g_error);
}

TEST(FaultPlan, AWrittenPlanReadsBackToTheSamePlan) {
  PlanGeneratorConfig config;
  config.seed = 7;
  config.count = 60;
  config.include_terminal = true;
  generate_fault_plan(config, g_other);
  CHECK(g_other.size() > 20U);
  static char text[FaultPlan::kMaxFileBytes];
  const std::size_t n = format_fault_plan(g_other, text, sizeof text);
  CHECK(n > 0U);
  CHECK_TEXT(parse(std::string(text, n)), g_error);
  CHECK_EQUAL(g_other.size(), g_plan.size());
  for (std::size_t i = 0; i < g_plan.size(); ++i) {
    CHECK(g_plan[i].device == g_other[i].device && g_plan[i].type == g_other[i].type);
    CHECK_EQUAL(g_other[i].start_us, g_plan[i].start_us);
    CHECK_EQUAL(g_other[i].duration_us, g_plan[i].duration_us);
  }
}

TEST(FaultPlan, TheGeneratorGivesTheSamePlanForTheSameSeedAndOnlyApplicablePairs) {
  PlanGeneratorConfig config;
  config.seed = 3;
  config.count = 80;
  generate_fault_plan(config, g_plan);
  generate_fault_plan(config, g_other);
  CHECK_EQUAL(g_plan.size(), g_other.size());
  bool differs_from_seed_4 = false;
  for (std::size_t i = 0; i < g_plan.size(); ++i) {
    const Fault& f = g_plan[i];
    CHECK(fault_applies(f.device, f.type));
    CHECK(f.start_us >= 60000000U && f.start_us < 7200000000U);
    CHECK(f.duration_us >= 200000U && f.duration_us <= 20000000U);
    CHECK_EQUAL(g_other[i].start_us, f.start_us);
    // Without include_terminal only the faults a mission rides out.
    CHECK(f.device == FaultDevice::kEstop || f.device == FaultDevice::kStorage ||
          f.device == FaultDevice::kCamera || f.device == FaultDevice::kMainLoop ||
          (f.device == FaultDevice::kCan && f.type == FaultType::kDelayed));
  }
  config.seed = 4;
  generate_fault_plan(config, g_other);
  for (std::size_t i = 0; i < g_plan.size() && i < g_other.size(); ++i) {
    differs_from_seed_4 = differs_from_seed_4 || g_other[i].start_us != g_plan[i].start_us;
  }
  CHECK(differs_from_seed_4);
}

TEST(FaultPlan, ThePairsThatMeanSomethingAreFortyTwo) {
  int pairs = 0;
  for (std::size_t d = 0; d < kFaultDeviceCount; ++d) {
    for (std::size_t t = 0; t < kFaultTypeCount; ++t) {
      pairs += fault_applies(static_cast<FaultDevice>(d), static_cast<FaultType>(t)) ? 1 : 0;
    }
  }
  CHECK_EQUAL(42, pairs);
  CHECK(fault_applies(FaultDevice::kCamera, FaultType::kDelayed));
  CHECK_FALSE(fault_applies(FaultDevice::kBumper, FaultType::kSlow));
  CHECK_FALSE(fault_applies(FaultDevice::kCount, FaultType::kOff));
}

TEST_GROUP(FaultInjector) {
  FaultInjector injector;
};

TEST(FaultInjector, AFaultIsActiveFromItsStartUntilItsEndAndTheLatestStartedWins) {
  CHECK(parse("1 camera off 2\n2 camera stuck 0.5\n"));
  injector.reset(1);
  injector.set_plan(g_plan);
  FaultType type = FaultType::kOff;
  CHECK_NO_ALLOCATION({
    injector.update(999999);
    CHECK_FALSE(injector.active(FaultDevice::kCamera, type));
    injector.update(1000000);
    CHECK(injector.active(FaultDevice::kCamera, type));
    CHECK(type == FaultType::kOff);
    injector.update(2100000);
    CHECK(injector.active(FaultDevice::kCamera, type));
    CHECK(type == FaultType::kStuck);
    injector.update(2600000);
    CHECK(injector.active(FaultDevice::kCamera, type));
    CHECK(type == FaultType::kOff);
    injector.update(3000000);
    CHECK_FALSE(injector.active(FaultDevice::kCamera, type));
  });
  CHECK_EQUAL(2U, injector.started());
  CHECK_EQUAL(2U, injector.ended());
  CHECK_FALSE(injector.active(FaultDevice::kPtu, type));
}

TEST(FaultInjector, AnIntermittentFaultFailsInSomeSlotsOnlyAndTheSameSeedGivesTheSameSlots) {
  CHECK(parse("0 ptu intermittent\n"));
  injector.reset(5);
  injector.set_plan(g_plan);
  FaultInjector again;
  again.reset(5);
  again.set_plan(g_plan);
  int failing = 0;
  FaultType type = FaultType::kOff;
  for (std::uint64_t slot = 0; slot < 200; ++slot) {
    injector.update(slot * FaultInjector::kSlotUs + 1);
    again.update(slot * FaultInjector::kSlotUs + 1);
    const bool f = injector.failing(FaultDevice::kPtu, type);
    CHECK_EQUAL(f, again.failing(FaultDevice::kPtu, type));
    failing += f ? 1 : 0;
  }
  CHECK(failing > 60 && failing < 140);  // a fair coin per slot
}

TEST(FaultInjector, TheConsolesFaultStartsNowAndEndsAfterItsDuration) {
  injector.reset(1);
  CHECK(injector.inject(FaultDevice::kStorage, FaultType::kWrong, 5000000, 1000000));
  FaultType type = FaultType::kOff;
  CHECK(injector.active(FaultDevice::kStorage, type));
  CHECK_EQUAL(5000000U, injector.active_since_us(FaultDevice::kStorage));
  CHECK_EQUAL(6000000U, injector.active_until_us(FaultDevice::kStorage));
  injector.update(6000000);
  CHECK_FALSE(injector.active(FaultDevice::kStorage, type));
}
