// Board: what a board folder hands the firmware — its description, its config and its HAL bag.
#pragma once

#include <cstddef>
#include <cstdint>

#include "algo/core/geometry.h"
#include "firmware/app/config_file.h"
#include "firmware/common/board_config.h"
#include "firmware/console/fault_injection.h"
#include "firmware/executive/host_clock.h"
#include "firmware/app/options.h"
#include "firmware/telemetry/truth_source.h"
#include "hal/hal.h"

namespace boticelli::firmware {

struct BoardInfo {
  const char* name;         // folder in boards/, e.g. "sim"
  const char* description;  // one line for --version
  bool simulated;           // true for the sim board (accepts --world)
};

class Board {
 public:
  virtual ~Board() = default;
  virtual const BoardInfo& info() const = 0;
  virtual const BoardConfig& config() const = 0;
  // Puts the config (and the board's device settings) back to the compiled-in defaults of
  // boards/<board>/board_config.h and adds the keys a configuration file may set, bound to
  // them (add_board_config_keys() and the board's devices). The firmware then applies the
  // file, before init().
  virtual bool reset_config(ConfigSchema& schema) = 0;
  // The configuration file read when there is no --config FILE (it may be missing), or
  // nullptr: only --config.
  virtual const char* default_config_path() const { return nullptr; }
  // Creates the devices for these options (the sim board loads --world). The firmware then
  // calls each device's init()/open() once. On failure returns false and writes a one-line
  // reason into `error`.
  virtual bool init(const Options& options, char* error, std::size_t error_size) = 0;
  // The devices; valid after a successful init().
  virtual hal::Hal& hal() = 0;
  // Ground truth, or nullptr (hardware).
  virtual const TruthSource* truth() const { return nullptr; }
  // The host clocks the executive times work with, or nullptr: the POSIX clocks as they are.
  // The sim board's leaves its own simulation work (rendering) out of the thread's CPU time.
  virtual HostClock* host_clock() { return nullptr; }
  // The console's `fault` command, or nullptr (hardware: faults cannot be injected).
  virtual FaultInjection* fault_injection() { return nullptr; }
  // A resumed mission's saved pose, in the mission's frame (the robot's pose when the mission
  // first started), called after init() and before the devices start. The sim board puts the
  // robot there (that frame being the world's start pose) and fails if the pose collides; a
  // hardware board cannot move the robot and trusts it to stand where it stopped.
  virtual bool place_robot(const core::Pose2& mission_pose, char* error, std::size_t error_size) {
    (void)mission_pose;
    (void)error;
    (void)error_size;
    return true;
  }
};

}  // namespace boticelli::firmware
