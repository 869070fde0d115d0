// Runtime: the firmware's fixed parts around a mission (see runtime.h).
#include "firmware/app/runtime.h"

#include "firmware/executive/task_table.h"

namespace boticelli::firmware {

Runtime::Runtime(hal::Hal& hal, hal::SerialPort& console_port, StateStore& store,
                 ParameterTable& parameters, HostClock* host)
    : saver(store),
      executive(hal.clock, host != nullptr ? host : &host_clock),
      safety(hal.estop, hal.bumper, hal.base),
      estop_task(safety),
      base_task(hal.base, safety),
      ptu_task(hal.pan_tilt),
      camera_task(hal.camera),
      watchdog_task(executive, hal.watchdog, notifier, hal.status_led),
      console_port_(console_port),
      parameters_(parameters) {}

bool Runtime::attach(const MissionParts& mission, const char** why) {
  console.emplace(console_port_, executive, safety, mission.view, parameters_);
  console_task.emplace(*console);
  camera_task.set_consumer(&mission.frames);
  watchdog_task.set_status_sources(&safety, &mission.view);
  Task* const tasks[kTaskCount] = {&estop_task,      &base_task,     &ptu_task,     &camera_task,
                                   &mission.control, &*console_task, &watchdog_task};
  for (std::size_t i = 0; i < kTaskCount; ++i) {
    if (!executive.add_task(kTaskTable[i], *tasks[i], why)) return false;
  }
  executive.set_background(&mission.work);
  return true;
}

}  // namespace boticelli::firmware
