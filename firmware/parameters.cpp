// Parameters: lookup and range-checked assignment (see parameters.h).
#include "firmware/parameters.h"

#include <cmath>

namespace boticelli::firmware {

bool ParameterTable::add(const Parameter& p) {
  if (size_ == kCapacity || p.value == nullptr || find(p.name) != nullptr) return false;
  if (!(p.min <= p.max) || !(*p.value >= p.min && *p.value <= p.max)) return false;
  entries_[size_++] = p;
  return true;
}

const Parameter* ParameterTable::find(std::string_view name) const {
  for (std::size_t i = 0; i < size_; ++i) {
    if (name == entries_[i].name) return &entries_[i];
  }
  return nullptr;
}

const char* ParameterTable::set(std::string_view name, float value) {
  const Parameter* p = find(name);
  if (p == nullptr) return "unknown parameter";
  if (!std::isfinite(value)) return "value is not a finite number";
  if (value < p->min || value > p->max) return "value out of range";
  if (p->whole && std::nearbyint(value) != value) return "value must be a whole number";
  *p->value = value;
  return nullptr;
}

}  // namespace boticelli::firmware
