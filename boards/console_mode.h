// console_mode(): maps the firmware's --console choice onto the Linux HAL's ConsolePort modes.
#pragma once

#include "firmware/app/options.h"
#include "hal/linux/console_port.h"

namespace boticelli::boards {

inline hal_linux::ConsoleMode console_mode(firmware::ConsoleKind kind) {
  switch (kind) {
    case firmware::ConsoleKind::kPty:
      return hal_linux::ConsoleMode::kPty;
    case firmware::ConsoleKind::kPath:
      return hal_linux::ConsoleMode::kDevice;
    case firmware::ConsoleKind::kStdio:
      break;
  }
  return hal_linux::ConsoleMode::kStdio;
}

}  // namespace boticelli::boards
