// libFuzzer target: the sim board's fault plan file (--faults FILE): the strict line parser.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string_view>

#include "hal/sim/fault_plan.h"

namespace {
boticelli::hal::sim::FaultPlan g_plan;
boticelli::hal::sim::FaultPlan g_again;
char g_text[boticelli::hal::sim::FaultPlan::kMaxFileBytes];
char g_error[256];
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace boticelli::hal::sim;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  g_error[0] = '\0';
  if (!parse_fault_plan(text, "plan", g_plan, g_error, sizeof g_error)) {
    // A refusal is "plan:LINE: why" (or "plan: why" for the whole file) and leaves no faults.
    if (std::strncmp(g_error, "plan:", 5) != 0 || g_plan.size() != 0) std::abort();
    return 0;
  }
  // Every accepted fault is an applicable pair inside the limits, and writes back and reads
  // again to the same plan.
  for (std::size_t i = 0; i < g_plan.size(); ++i) {
    const Fault& f = g_plan[i];
    if (!fault_applies(f.device, f.type)) std::abort();
    if (f.start_us > static_cast<std::uint64_t>(FaultPlan::kMaxTimeS * 1e6)) std::abort();
    if (f.device == FaultDevice::kMainLoop && f.type == FaultType::kStuck &&
        (f.duration_us == 0 || f.duration_us > kMaxStallUs)) {
      std::abort();
    }
  }
  const std::size_t n = format_fault_plan(g_plan, g_text, sizeof g_text);
  if (g_plan.size() > 0 && n == 0) return 0;  // 256 faults of long numbers may not fit
  if (!parse_fault_plan({g_text, n}, "again", g_again, g_error, sizeof g_error)) std::abort();
  if (g_again.size() != g_plan.size()) std::abort();
  for (std::size_t i = 0; i < g_plan.size(); ++i) {
    if (g_again[i].device != g_plan[i].device || g_again[i].type != g_plan[i].type ||
        g_again[i].start_us != g_plan[i].start_us ||
        g_again[i].duration_us != g_plan[i].duration_us) {
      std::abort();
    }
  }
  return 0;
}
