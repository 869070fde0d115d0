// Parameters: lookup, range-checked assignment and the saved-parameters text (see parameters.h).
#include "firmware/common/parameters.h"

#include <cmath>
#include <cstdio>
#include <cstring>

namespace boticelli::firmware {

bool ParameterTable::add(const Parameter& p) {
  if (size_ == kCapacity || p.value == nullptr || find(p.name) != nullptr) return false;
  // A TOML bare key (the saved file) of at most 32 bytes (kMaxFileBytes allows 64 a line).
  const std::size_t length = std::strlen(p.name);
  if (length == 0 || length > 32) return false;
  for (std::size_t i = 0; i < length; ++i) {
    const char c = p.name[i];
    const bool bare = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                      c == '_' || c == '-';
    if (!bare) return false;
  }
  if (!(p.min <= p.max) || !(*p.value >= p.min && *p.value <= p.max)) return false;
  defaults_[size_] = *p.value;
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

std::size_t ParameterTable::changed_count() const {
  std::size_t n = 0;
  for (std::size_t i = 0; i < size_; ++i) n += is_default(i) ? 0U : 1U;
  return n;
}

std::size_t ParameterTable::encode_changed(char* out, std::size_t capacity) const {
  constexpr std::string_view kHeader =
      "# boticelli: the console parameters that differ from their defaults, written by\n"
      "# `param save` and loaded at start. Delete this file to go back to the defaults.\n";
  if (capacity <= kHeader.size()) return 0;
  std::memcpy(out, kHeader.data(), kHeader.size());
  std::size_t size = kHeader.size();
  for (std::size_t i = 0; i < size_; ++i) {
    if (is_default(i)) continue;
    // %.9g: every float reads back exactly.
    const int n = std::snprintf(out + size, capacity - size, "%s = %.9g\n", entries_[i].name,
                                static_cast<double>(*entries_[i].value));
    if (n < 0 || static_cast<std::size_t>(n) >= capacity - size) return 0;
    size += static_cast<std::size_t>(n);
  }
  return size;
}

}  // namespace boticelli::firmware
