// All HAL mocks in one include (include standard headers before it: it pulls in CppUTest).
#pragma once

#include "mock_base.h"
#include "mock_camera.h"
#include "mock_clock.h"
#include "mock_digital_io.h"
#include "mock_pan_tilt.h"
#include "mock_serial_port.h"
#include "mock_watchdog.h"
