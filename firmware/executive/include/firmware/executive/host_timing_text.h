// Host timing text: the executive's host-clock figures as console lines (`stats`, the end of a
// run).
#pragma once

#include <cstddef>

#include "firmware/common/text_buffer.h"
#include "firmware/executive/executive.h"

namespace boticelli::firmware {

// Lines of host timings the executive has: one per task, then the background slot, then the
// frames; 0 without a HostClock.
std::size_t host_timing_line_count(const Executive& executive);
// Appends line `line` (< host_timing_line_count) without its line end [µs, one decimal]:
//   host task NAME budget_us= runs= wall_avg_us= wall_p99_us= wall_worst_us= cpu_avg_us=
//     cpu_p99_us= cpu_worst_us=
//   host background limit_us= slices= wall_p99_us= wall_worst_us= cpu_p99_us= cpu_worst_us=
//     over_limit= overshoot_worst_us= margin_us=
//   host frame frame_us= frames= work_wall_p99_us= work_wall_worst_us= work_cpu_p99_us=
//     work_cpu_worst_us= latencies= start_latency_p99_us= start_latency_worst_us=
// (latencies=0: the board's clock never waited on the host's, the sim board in lockstep).
void append_host_timing_line(TextBufferBase& out, const Executive& executive, std::size_t line);

}  // namespace boticelli::firmware
