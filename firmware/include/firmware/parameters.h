// Parameters: named, range-checked tunables that the console can get and set.
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

// A fixed table filled at init; the console looks parameters up by name.
class ParameterTable {
 public:
  static constexpr std::size_t kCapacity = 24;

  // False when full, the name is taken, or the current value is outside [min, max].
  bool add(const Parameter& parameter);
  const Parameter* find(std::string_view name) const;
  // Sets a value after the checks; nullptr on success, else the reason. Nothing changes on failure.
  const char* set(std::string_view name, float value);
  std::size_t size() const { return size_; }
  const Parameter& operator[](std::size_t i) const { return entries_[i]; }

 private:
  std::array<Parameter, kCapacity> entries_{};
  std::size_t size_ = 0;
};

}  // namespace boticelli::firmware
