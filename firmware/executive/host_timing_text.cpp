// Host timing text (see host_timing_text.h).
#include "firmware/executive/host_timing_text.h"

namespace boticelli::firmware {
namespace {

double us(std::uint64_t ns) {
  return static_cast<double>(ns) * 1e-3;
}

constexpr std::uint32_t kP99 = 990;  // per mille

}  // namespace

std::size_t host_timing_line_count(const Executive& executive) {
  return executive.host_timed() ? executive.task_count() + 2U : 0U;
}

void append_host_timing_line(TextBufferBase& out, const Executive& executive, std::size_t line) {
  const std::size_t tasks = executive.task_count();
  if (line < tasks) {
    const TaskSpec& s = executive.spec(line);
    const HostTiming& t = executive.host_task_timing(line);
    out.appendf(
        "host task %-8s budget_us=%u runs=%llu wall_avg_us=%.1f wall_p99_us=%.1f "
        "wall_worst_us=%.1f cpu_avg_us=%.1f cpu_p99_us=%.1f cpu_worst_us=%.1f",
        s.name, s.budget_us, static_cast<unsigned long long>(t.wall.count()),
        us(t.wall.average_ns()), us(t.wall.percentile_ns(kP99)), us(t.wall.max_ns()),
        us(t.cpu.average_ns()), us(t.cpu.percentile_ns(kP99)), us(t.cpu.max_ns()));
    return;
  }
  const ExecutiveConfig& c = executive.config();
  const HostFrameStats& f = executive.host_frame_stats();
  if (line == tasks) {
    const std::uint32_t limit_us = c.background_max_slice_us != 0
                                       ? c.background_max_slice_us
                                       : c.frame_us - c.background_margin_us;
    out.appendf(
        "host background limit_us=%u slices=%llu wall_p99_us=%.1f wall_worst_us=%.1f "
        "cpu_p99_us=%.1f cpu_worst_us=%.1f over_limit=%llu overshoot_worst_us=%.1f "
        "margin_us=%u",
        limit_us, static_cast<unsigned long long>(f.slice.wall.count()),
        us(f.slice.wall.percentile_ns(kP99)), us(f.slice.wall.max_ns()),
        us(f.slice.cpu.percentile_ns(kP99)), us(f.slice.cpu.max_ns()),
        static_cast<unsigned long long>(f.slice_overruns), us(f.slice_overshoot_worst_ns),
        c.background_margin_us);
    return;
  }
  if (line == tasks + 1U) {
    out.appendf(
        "host frame frame_us=%u frames=%llu work_wall_p99_us=%.1f work_wall_worst_us=%.1f "
        "work_cpu_p99_us=%.1f work_cpu_worst_us=%.1f latencies=%llu start_latency_p99_us=%.1f "
        "start_latency_worst_us=%.1f",
        c.frame_us, static_cast<unsigned long long>(f.work.wall.count()),
        us(f.work.wall.percentile_ns(kP99)), us(f.work.wall.max_ns()),
        us(f.work.cpu.percentile_ns(kP99)), us(f.work.cpu.max_ns()),
        static_cast<unsigned long long>(f.start_latency.count()),
        us(f.start_latency.percentile_ns(kP99)), us(f.start_latency.max_ns()));
  }
}

}  // namespace boticelli::firmware
