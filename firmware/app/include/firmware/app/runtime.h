// Runtime: the firmware's fixed parts wired around a mission — state writer, executive,
// safety latch, console and the device tasks in kTaskTable's order. firmware_main runs it with
// the Mission; the sim board's fault harness with a stand-in (boards/sim/harness).
#pragma once

#include <optional>

#include "firmware/app/device_tasks.h"
#include "firmware/app/service_notify.h"
#include "firmware/common/parameters.h"
#include "firmware/console/console.h"
#include "firmware/executive/executive.h"
#include "firmware/executive/frame_consumer.h"
#include "firmware/executive/host_clock.h"
#include "firmware/safety/safety.h"
#include "firmware/state/persistence.h"
#include "firmware/state/state_saver.h"
#include "firmware/telemetry/mission_view.h"
#include "hal/hal.h"
#include "hal/serial_port.h"

namespace boticelli::firmware {

// What a mission hands the runtime: its control task (the mission task's body), its
// background work, the camera's consumer and the console's view of it.
struct MissionParts {
  Task& control;
  BackgroundWork& work;
  FrameConsumer& frames;
  MissionView& view;
};

class Runtime {
 public:
  // The parts bound to the devices; the mission is attached next (it needs the safety latch,
  // the executive and the saver made here). `console_port` is the console's line (the board's
  // console, or a capture in tests). `host` times the executive's work (Board::host_clock);
  // nullptr: the POSIX clocks (host_clock).
  Runtime(hal::Hal& hal, hal::SerialPort& console_port, StateStore& store,
          ParameterTable& parameters, HostClock* host = nullptr);
  Runtime(const Runtime&) = delete;
  Runtime& operator=(const Runtime&) = delete;

  // Binds the mission: the console on its view, the camera's frames to it, and every task in
  // kTaskTable's order with the mission's in its slot; its work in the background. False with
  // the reason in *why.
  bool attach(const MissionParts& mission, const char** why);

  ServiceNotifier notifier;
  StateSaver saver;
  // What the executive times work with on every board (unless the board gives its own),
  // beside the board's clock.
  PosixHostClock host_clock;
  Executive executive;
  Safety safety;
  EstopTask estop_task;
  BaseTask base_task;
  PanTiltTask ptu_task;
  CameraTask camera_task;
  WatchdogTask watchdog_task;
  // Made by attach(): the console reads the mission's view.
  std::optional<Console> console;
  std::optional<ConsoleTask> console_task;

 private:
  hal::SerialPort& console_port_;
  ParameterTable& parameters_;
};

}  // namespace boticelli::firmware
