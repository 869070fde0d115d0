// Hal: the bag of device interfaces a board wires once from static instances.
#pragma once

#include "hal/base.h"
#include "hal/camera.h"
#include "hal/clock.h"
#include "hal/digital_io.h"
#include "hal/pan_tilt.h"
#include "hal/serial_port.h"
#include "hal/watchdog.h"

namespace boticelli::hal {

// References, not owners: the board owns the instances (static storage) and outlives
// everything that uses them. A missing peripheral is wired to a do-nothing stand-in.
struct Hal {
  Camera& camera;
  PanTilt& pan_tilt;
  Base& base;
  DigitalIn& estop;
  DigitalIn& bumper;
  DigitalOut& status_led;
  SerialPort& console;
  Clock& clock;
  Watchdog& watchdog;
};

}  // namespace boticelli::hal
