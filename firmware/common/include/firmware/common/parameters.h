// Parameters: named, range-checked tunables that the console can get, set, show and save.
#pragma once

#include <array>
#include <cstddef>
#include <string_view>

namespace boticelli::firmware {

struct Parameter {
  const char* name = "";
  float* value = nullptr;  // owned by the module that registered it
  float min = 0.0F;        // accepted range, inclusive
  float max = 0.0F;
  bool whole = false;     // only whole numbers
  const char* help = "";  // one line incl. the unit
};

// A fixed table filled at init; the console looks parameters up by name. The value a
// parameter has when it is added is its default (`param show` lists what differs from it,
// `param save` saves only that).
class ParameterTable {
 public:
  static constexpr std::size_t kCapacity = 24;
  // The largest text encode_changed() writes: a header line and one line per parameter.
  static constexpr std::size_t kMaxFileBytes = 128 + kCapacity * 64;

  // False when full, the name is taken, or the current value is outside [min, max].
  bool add(const Parameter& parameter);
  const Parameter* find(std::string_view name) const;
  // Sets a value after the checks; nullptr on success, else the reason. Nothing changes on failure.
  const char* set(std::string_view name, float value);
  std::size_t size() const { return size_; }
  const Parameter& operator[](std::size_t i) const { return entries_[i]; }
  float default_value(std::size_t i) const { return defaults_[i]; }
  bool is_default(std::size_t i) const { return *entries_[i].value == defaults_[i]; }
  std::size_t changed_count() const;
  // The parameters that differ from their defaults as a TOML file (`name = value` lines
  // under a comment header), into `out`; the byte count, 0 when `capacity` is too small.
  // No allocation: the console calls it on the cyclic path.
  std::size_t encode_changed(char* out, std::size_t capacity) const;

 private:
  std::array<Parameter, kCapacity> entries_{};
  std::array<float, kCapacity> defaults_{};
  std::size_t size_ = 0;
};

}  // namespace boticelli::firmware
