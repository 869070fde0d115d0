// The firmware's task table: every fixed-rate task with its period and time budget.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "firmware/executive/executive.h"

namespace boticelli::firmware {

inline constexpr std::uint32_t kDefaultMinorFrameUs = 10000;  // 10 ms minor frame

// Index of each task in kTaskTable (table order is run order within a frame).
enum class TaskId : std::uint8_t {
  kEstop,
  kBase,
  kPanTilt,
  kCamera,
  kMission,
  kConsole,
  kWatchdog,
  kCount
};

inline constexpr std::size_t kTaskCount = static_cast<std::size_t>(TaskId::kCount);

// The e-stop runs first in every frame so the base is stopped within one frame whatever the
// other tasks and the background work do. Budgets are worst cases measured on the rpi4 with
// margin; the background slot gets the rest of each frame (see ExecutiveConfig).
inline constexpr std::array<TaskSpec, kTaskCount> kTaskTable{{
    {"estop", 10000, 200},      // GPIO e-stop and bumper edges → base stop
    {"base", 10000, 1000},      // ODrive setpoint re-send, encoder feedback, heartbeats
    {"ptu", 20000, 500},        // PTU-D46 command queue and replies
    {"camera", 10000, 2000},    // V4L2 dequeue / requeue (image work runs in the background)
    {"mission", 10000, 500},    // mission control: PTU scan, frames, the driven step, holds
    {"console", 10000, 1500},   // serial console: input, commands, telemetry, output
    {"watchdog", 100000, 200},  // /dev/watchdog and systemd WATCHDOG=1 unless hung or given up
}};

static_assert(task_table_valid(kTaskTable, kDefaultMinorFrameUs),
              "every period must be a multiple of the minor frame and every budget fit in it");

constexpr const TaskSpec& task_spec(TaskId id) {
  return kTaskTable[static_cast<std::size_t>(id)];
}

}  // namespace boticelli::firmware
