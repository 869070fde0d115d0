// ConfigFile: the start-up configuration (TOML) bound to the board's values, every value
// range-checked, errors as "FILE:LINE: why"; also loads the parameters `param save` wrote.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "firmware/common/parameters.h"

namespace boticelli::firmware {

struct BoardConfig;

// A device path or interface name set by the configuration file (NUL-terminated).
using DeviceName = std::array<char, 64>;

enum class ConfigKind : std::uint8_t {
  kWhole,   // TOML integer in [min, max] (and a multiple of `multiple_of`)
  kNumber,  // TOML float or integer, finite, in [min, max]
  kFlag,    // TOML boolean
  kBaud,    // TOML integer, one of the standard termios rates (1200 ... 921600)
  kPath,    // TOML string: an absolute path, printable ASCII
  kName,    // TOML string: letters, digits, '_', '-', '.' (an interface or chip name)
};

// One key of the file: `[table]` then `name = value`, bound to the value it sets.
struct ConfigKey {
  const char* table = "";
  const char* name = "";
  ConfigKind kind = ConfigKind::kWhole;
  std::uint32_t* u32 = nullptr;  // kWhole, kBaud (or u8)
  std::uint8_t* u8 = nullptr;    // kWhole
  float* f32 = nullptr;          // kNumber
  bool* flag = nullptr;          // kFlag
  DeviceName* text = nullptr;    // kPath, kName
  double min = 0.0;
  double max = 0.0;
  std::uint32_t multiple_of = 1;
  // Said after a kWhole value's range error, below the minimum or above the maximum (why the
  // range is what it is, and what to do instead; nullptr: nothing).
  const char* below_min_note = nullptr;
  const char* above_max_note = nullptr;

  static ConfigKey whole(const char* table, const char* name, std::uint32_t& value,
                         std::uint32_t min, std::uint32_t max, std::uint32_t multiple_of = 1);
  static ConfigKey whole(const char* table, const char* name, std::uint8_t& value, std::uint8_t min,
                         std::uint8_t max);
  static ConfigKey number(const char* table, const char* name, float& value, double min,
                          double max);
  static ConfigKey flag_key(const char* table, const char* name, bool& value);
  static ConfigKey baud(const char* table, const char* name, std::uint32_t& value);
  static ConfigKey path(const char* table, const char* name, DeviceName& value);
  static ConfigKey interface_name(const char* table, const char* name, DeviceName& value);
};

// The keys a board accepts, filled at start (Board::reset_config).
class ConfigSchema {
 public:
  static constexpr std::size_t kCapacity = 64;
  // False when full or when table.name is taken.
  bool add(const ConfigKey& key);
  void clear() { size_ = 0; }
  const ConfigKey* find(std::string_view table, std::string_view name) const;
  bool has_table(std::string_view table) const;
  std::size_t size() const { return size_; }
  const ConfigKey& operator[](std::size_t i) const { return keys_[i]; }

 private:
  std::array<ConfigKey, kCapacity> keys_{};
  std::size_t size_ = 0;
};

// The keys every board has, bound to `config`: camera format and intrinsics, the robot's
// and the PTU arm's dimensions, the base's limits, console baud and telemetry, watchdog.
bool add_board_config_keys(ConfigSchema& schema, BoardConfig& config);

enum class ConfigLoad : std::uint8_t { kLoaded, kMissing, kInvalid };

// Parses `text` as TOML (`path` names it in errors) and sets every key it holds. Unknown
// tables and keys, wrong types and values out of range are errors; on any error nothing is
// set and `error` says "PATH:LINE: why". Start-up only: it allocates (the TOML library).
bool apply_config_text(std::string_view text, const char* path, const ConfigSchema& schema,
                       char* error, std::size_t error_size);
// Reads `path` and applies it: kMissing (error says so) when there is no such file, kInvalid
// when it cannot be read or apply_config_text() refuses it.
ConfigLoad load_config_file(const char* path, const ConfigSchema& schema, char* error,
                            std::size_t error_size);

// Called once per saved parameter that is skipped, with "PATH:LINE: why; default kept".
using ConfigWarning = void (*)(const char* message, void* context);
// Loads a `param save` file: top-level `name = number` lines into `table`. A syntax error
// is kInvalid (nothing set, "PATH:LINE: why"); an unknown name or a value the table refuses
// (after a firmware update changed the table) is skipped with a warning, so the robot still
// starts.
ConfigLoad apply_parameters_text(std::string_view text, const char* path, ParameterTable& table,
                                 char* error, std::size_t error_size, ConfigWarning warn,
                                 void* warn_context);
ConfigLoad load_parameters_file(const char* path, ParameterTable& table, char* error,
                                std::size_t error_size, ConfigWarning warn, void* warn_context);

}  // namespace boticelli::firmware
