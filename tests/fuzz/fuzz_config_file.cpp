// libFuzzer target: the configuration file (rpi4 keys) and the saved-parameters file, with
// toml++ compiled in header-only so its parser is instrumented too.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string_view>

#include "board_config.h"  // boards/rpi4: the device keys
#include "firmware/app/board.h"
#include "firmware/app/config_file.h"
#include "firmware/common/parameters.h"

namespace fw = boticelli::firmware;

namespace {

bool terminated(const fw::DeviceName& name) {
  return std::memchr(name.data(), '\0', name.size()) != nullptr;
}

// "FILE:LINE: why" with a line number from 1 on.
void check_error(const char* error) {
  constexpr std::string_view kPrefix = "fuzz.conf:";
  const std::string_view e = error;
  if (e.substr(0, kPrefix.size()) != kPrefix) std::abort();
  const char* p = error + kPrefix.size();
  if (*p < '1' || *p > '9') std::abort();
  while (*p >= '0' && *p <= '9') ++p;
  if (p[0] != ':' || p[1] != ' ' || p[2] == '\0') std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  fw::BoardConfig config = boticelli::boards::rpi4::make_config();
  boticelli::boards::rpi4::Rpi4Devices devices;
  fw::ConfigSchema schema;
  if (!fw::add_board_config_keys(schema, config) ||
      !boticelli::boards::rpi4::add_device_config_keys(schema, devices)) {
    std::abort();
  }
  char error[320] = "";
  if (fw::apply_config_text(text, "fuzz.conf", schema, error, sizeof error)) {
    // Whatever was accepted is inside its range.
    if (config.camera_width_px < 160 || config.camera_width_px > 1280 ||
        config.camera_width_px % 8 != 0 || config.camera_height_px % 4 != 0 ||
        !std::isfinite(config.focal_px) || config.focal_px < 50.0F ||
        devices.odrive_left_node_id > 63 || devices.estop_line > 57 ||
        !terminated(devices.camera_device) || !terminated(devices.can_interface) ||
        devices.camera_device[0] != '/') {
      std::abort();
    }
  } else {
    check_error(error);
  }

  float gain = 1.0F;
  float mode = 0.0F;
  fw::ParameterTable table;
  if (!table.add({"gain", &gain, -1.0F, 1.0F, false, ""}) ||
      !table.add({"mode", &mode, 0.0F, 3.0F, true, ""})) {
    std::abort();
  }
  const fw::ConfigLoad loaded = fw::apply_parameters_text(
      text, "fuzz.conf", table, error, sizeof error,
      [](const char* message, void*) { check_error(message); }, nullptr);
  if (loaded == fw::ConfigLoad::kInvalid) check_error(error);
  if (!(gain >= -1.0F && gain <= 1.0F) || !(mode >= 0.0F && mode <= 3.0F) ||
      std::nearbyint(mode) != mode) {
    std::abort();
  }
  return 0;
}
