// ConfigFile: TOML parsing (toml++), checks and application of the keys (see config_file.h).
#include "firmware/app/config_file.h"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cfloat>
#include <cstdarg>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include <toml++/toml.h>

namespace boticelli::firmware {
namespace {

constexpr std::size_t kMaxFileBytes = std::size_t{64} * 1024;
constexpr std::uint32_t kBaudRates[] = {1200,  2400,   4800,   9600,   19200,  38400,
                                        57600, 115200, 230400, 460800, 500000, 921600};

const char* source_name(const char* path) {
  return path != nullptr && path[0] != '\0' ? path : "<config>";
}

// "PATH:LINE: " followed by the formatted reason.
void fail_at(char* error, std::size_t size, const char* path, std::uint32_t line,
             const char* format, ...) __attribute__((format(printf, 5, 6)));
void fail_at(char* error, std::size_t size, const char* path, std::uint32_t line,
             const char* format, ...) {
  const int n = std::snprintf(error, size, "%s:%u: ", source_name(path), line);
  if (n < 0 || static_cast<std::size_t>(n) >= size) return;
  std::va_list args;
  va_start(args, format);
  std::vsnprintf(error + n, size - static_cast<std::size_t>(n), format, args);
  va_end(args);
}

std::uint32_t line_of(const toml::node& node) {
  return node.source().begin.line;
}

// A checked value, ready to be stored.
struct Value {
  std::int64_t whole = 0;
  double number = 0.0;
  bool flag = false;
  std::string_view text;
};

bool is_name_char(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
         c == '-' || c == '.';
}

// Checks `node` against `key`; on failure writes the reason (without the position).
bool check_value(const ConfigKey& key, const toml::node& node, Value& out, char* why,
                 std::size_t why_size) {
  switch (key.kind) {
    case ConfigKind::kWhole:
    case ConfigKind::kBaud: {
      const toml::value<std::int64_t>* v = node.as_integer();
      if (v == nullptr) {
        std::snprintf(why, why_size, "%s.%s must be a whole number", key.table, key.name);
        return false;
      }
      out.whole = v->get();
      if (key.kind == ConfigKind::kBaud) {
        for (const std::uint32_t rate : kBaudRates) {
          if (out.whole == static_cast<std::int64_t>(rate)) return true;
        }
        std::snprintf(why, why_size,
                      "%s.%s = %lld is not a standard baud rate (1200, 2400, 4800, 9600, 19200, "
                      "38400, 57600, 115200, 230400, 460800, 500000, 921600)",
                      key.table, key.name, static_cast<long long>(out.whole));
        return false;
      }
      const auto min = static_cast<std::int64_t>(key.min);
      const auto max = static_cast<std::int64_t>(key.max);
      if (out.whole < min || out.whole > max) {
        const char* note = out.whole < min ? key.below_min_note : key.above_max_note;
        std::snprintf(why, why_size, "%s.%s = %lld is out of range (%lld to %lld)%s%s", key.table,
                      key.name, static_cast<long long>(out.whole), static_cast<long long>(min),
                      static_cast<long long>(max), note != nullptr ? ": " : "",
                      note != nullptr ? note : "");
        return false;
      }
      if (key.multiple_of > 1 && out.whole % key.multiple_of != 0) {
        std::snprintf(why, why_size, "%s.%s = %lld must be a multiple of %u", key.table, key.name,
                      static_cast<long long>(out.whole), key.multiple_of);
        return false;
      }
      return true;
    }
    case ConfigKind::kNumber: {
      if (const toml::value<std::int64_t>* i = node.as_integer(); i != nullptr) {
        out.number = static_cast<double>(i->get());
      } else if (const toml::value<double>* d = node.as_floating_point(); d != nullptr) {
        out.number = d->get();
      } else {
        std::snprintf(why, why_size, "%s.%s must be a number", key.table, key.name);
        return false;
      }
      if (!std::isfinite(out.number)) {
        std::snprintf(why, why_size, "%s.%s must be a finite number", key.table, key.name);
        return false;
      }
      if (out.number < key.min || out.number > key.max) {
        std::snprintf(why, why_size, "%s.%s = %g is out of range (%g to %g)", key.table, key.name,
                      out.number, key.min, key.max);
        return false;
      }
      return true;
    }
    case ConfigKind::kFlag: {
      const toml::value<bool>* v = node.as_boolean();
      if (v == nullptr) {
        std::snprintf(why, why_size, "%s.%s must be true or false", key.table, key.name);
        return false;
      }
      out.flag = v->get();
      return true;
    }
    case ConfigKind::kPath:
    case ConfigKind::kName: {
      const toml::value<std::string>* v = node.as_string();
      if (v == nullptr) {
        std::snprintf(why, why_size, "%s.%s must be a string", key.table, key.name);
        return false;
      }
      out.text = v->get();
      if (out.text.empty() || out.text.size() >= key.text->size()) {
        std::snprintf(why, why_size, "%s.%s must be 1 to %zu bytes long", key.table, key.name,
                      key.text->size() - 1);
        return false;
      }
      for (const char c : out.text) {
        const bool ok = key.kind == ConfigKind::kPath ? c > 0x20 && c < 0x7F : is_name_char(c);
        if (!ok) {
          std::snprintf(why, why_size,
                        key.kind == ConfigKind::kPath
                            ? "%s.%s must be printable ASCII without spaces"
                            : "%s.%s may hold only letters, digits, '_', '-' and '.'",
                        key.table, key.name);
          return false;
        }
      }
      if (key.kind == ConfigKind::kPath && out.text[0] != '/') {
        std::snprintf(why, why_size, "%s.%s must be an absolute path", key.table, key.name);
        return false;
      }
      return true;
    }
  }
  return false;
}

void store_value(const ConfigKey& key, const Value& v) {
  switch (key.kind) {
    case ConfigKind::kWhole:
    case ConfigKind::kBaud:
      if (key.u32 != nullptr) *key.u32 = static_cast<std::uint32_t>(v.whole);
      if (key.u8 != nullptr) *key.u8 = static_cast<std::uint8_t>(v.whole);
      break;
    case ConfigKind::kNumber:
      *key.f32 = static_cast<float>(v.number);
      break;
    case ConfigKind::kFlag:
      *key.flag = v.flag;
      break;
    case ConfigKind::kPath:
    case ConfigKind::kName:
      std::memcpy(key.text->data(), v.text.data(), v.text.size());
      (*key.text)[v.text.size()] = '\0';
      break;
  }
}

// Reads a whole file (at most kMaxFileBytes) into `out`.
ConfigLoad read_file(const char* path, std::string& out, char* error, std::size_t error_size) {
  std::FILE* f = std::fopen(path, "rb");
  if (f == nullptr) {
    const bool missing = errno == ENOENT;
    std::snprintf(error, error_size, "%s: %s", path, std::strerror(errno));
    return missing ? ConfigLoad::kMissing : ConfigLoad::kInvalid;
  }
  std::array<char, 4096> chunk{};
  out.clear();
  std::size_t n = 0;
  while ((n = std::fread(chunk.data(), 1, chunk.size(), f)) > 0) {
    out.append(chunk.data(), n);
    if (out.size() > kMaxFileBytes) {
      std::fclose(f);
      std::snprintf(error, error_size, "%s: larger than %zu KiB", path, kMaxFileBytes / 1024);
      return ConfigLoad::kInvalid;
    }
  }
  const bool failed = std::ferror(f) != 0;
  std::fclose(f);
  if (failed) {
    std::snprintf(error, error_size, "%s: read error", path);
    return ConfigLoad::kInvalid;
  }
  return ConfigLoad::kLoaded;
}

// Parses TOML; on a syntax error writes "PATH:LINE: why".
bool parse_toml(std::string_view text, const char* path, toml::table& out, char* error,
                std::size_t error_size) {
  // Only ASCII reaches the library: toml++ 3.3.0 (Debian 12) reaches a TOML_UNREACHABLE
  // (undefined behaviour) on some non-ASCII code points where it looks for whitespace
  // (upstream issues #190, #295; found by fuzz_config_file). No key or value needs more.
  std::uint32_t line = 1;
  for (const char c : text) {
    const auto byte = static_cast<unsigned char>(c);
    if (byte == '\n') ++line;
    if (byte >= 0x80) {
      fail_at(error, error_size, path, line, "non-ASCII byte 0x%02X (the file must be ASCII)",
              byte);
      return false;
    }
  }
  try {
    out = toml::parse(text, std::string_view{source_name(path)});
    return true;
  } catch (const toml::parse_error& e) {
    const std::string_view what = e.description();
    fail_at(error, error_size, path, e.source().begin.line, "%.*s", static_cast<int>(what.size()),
            what.data());
    return false;
  }
}

// The fields every key has; the factories below add where its value lives and its range.
ConfigKey key_of(const char* table, const char* name, ConfigKind kind) {
  ConfigKey k;
  k.table = table;
  k.name = name;
  k.kind = kind;
  return k;
}

}  // namespace

ConfigKey ConfigKey::whole(const char* table, const char* name, std::uint32_t& value,
                           std::uint32_t min, std::uint32_t max, std::uint32_t multiple_of) {
  ConfigKey k = key_of(table, name, ConfigKind::kWhole);
  k.u32 = &value;
  k.min = min;
  k.max = max;
  k.multiple_of = multiple_of;
  return k;
}

ConfigKey ConfigKey::whole(const char* table, const char* name, std::uint8_t& value,
                           std::uint8_t min, std::uint8_t max) {
  ConfigKey k = key_of(table, name, ConfigKind::kWhole);
  k.u8 = &value;
  k.min = min;
  k.max = max;
  return k;
}

ConfigKey ConfigKey::number(const char* table, const char* name, float& value, double min,
                            double max) {
  ConfigKey k = key_of(table, name, ConfigKind::kNumber);
  k.f32 = &value;
  k.min = min;
  k.max = max;
  return k;
}

ConfigKey ConfigKey::flag_key(const char* table, const char* name, bool& value) {
  ConfigKey k = key_of(table, name, ConfigKind::kFlag);
  k.flag = &value;
  return k;
}

ConfigKey ConfigKey::baud(const char* table, const char* name, std::uint32_t& value) {
  ConfigKey k = key_of(table, name, ConfigKind::kBaud);
  k.u32 = &value;
  return k;
}

ConfigKey ConfigKey::path(const char* table, const char* name, DeviceName& value) {
  ConfigKey k = key_of(table, name, ConfigKind::kPath);
  k.text = &value;
  return k;
}

ConfigKey ConfigKey::interface_name(const char* table, const char* name, DeviceName& value) {
  ConfigKey k = key_of(table, name, ConfigKind::kName);
  k.text = &value;
  return k;
}

bool ConfigSchema::add(const ConfigKey& key) {
  if (size_ == kCapacity || find(key.table, key.name) != nullptr) return false;
  keys_[size_++] = key;
  return true;
}

const ConfigKey* ConfigSchema::find(std::string_view table, std::string_view name) const {
  for (std::size_t i = 0; i < size_; ++i) {
    if (table == keys_[i].table && name == keys_[i].name) return &keys_[i];
  }
  return nullptr;
}

bool ConfigSchema::has_table(std::string_view table) const {
  for (std::size_t i = 0; i < size_; ++i) {
    if (table == keys_[i].table) return true;
  }
  return false;
}

bool apply_config_text(std::string_view text, const char* path, const ConfigSchema& schema,
                       char* error, std::size_t error_size) {
  toml::table root;
  if (!parse_toml(text, path, root, error, error_size)) return false;
  // Every key with its table, in the file's order (the library's tables are sorted by
  // name), so the first problem reported is the first one in the file.
  struct Entry {
    std::uint32_t line;
    std::string_view table;
    std::string_view name;
    const toml::node* node;
  };
  std::vector<Entry> entries;
  for (auto&& [table_key, table_node] : root) {
    const std::string_view table_name = table_key.str();
    const toml::table* table = table_node.as_table();
    if (!schema.has_table(table_name)) {
      fail_at(error, error_size, path, table_key.source().begin.line, "unknown %s '%.*s'%s",
              table != nullptr ? "table" : "key", static_cast<int>(table_name.size()),
              table_name.data(), table != nullptr ? "" : " (keys belong in a [table])");
      return false;
    }
    if (table == nullptr) {
      fail_at(error, error_size, path, line_of(table_node), "'%.*s' must be a table",
              static_cast<int>(table_name.size()), table_name.data());
      return false;
    }
    for (auto&& [key, node] : *table) {
      entries.push_back({key.source().begin.line, table_name, key.str(), &node});
    }
  }
  std::stable_sort(entries.begin(), entries.end(),
                   [](const Entry& a, const Entry& b) { return a.line < b.line; });
  // Two passes: check everything, then store, so a refused file changes nothing.
  std::vector<Value> values(entries.size());
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const Entry& e = entries[i];
    const ConfigKey* k = schema.find(e.table, e.name);
    if (k == nullptr) {
      fail_at(error, error_size, path, e.line, "unknown key '%.*s.%.*s'",
              static_cast<int>(e.table.size()), e.table.data(), static_cast<int>(e.name.size()),
              e.name.data());
      return false;
    }
    char why[200] = "";
    if (!check_value(*k, *e.node, values[i], why, sizeof why)) {
      fail_at(error, error_size, path, line_of(*e.node), "%s", why);
      return false;
    }
  }
  for (std::size_t i = 0; i < entries.size(); ++i) {
    store_value(*schema.find(entries[i].table, entries[i].name), values[i]);
  }
  return true;
}

ConfigLoad load_config_file(const char* path, const ConfigSchema& schema, char* error,
                            std::size_t error_size) {
  std::string text;
  const ConfigLoad read = read_file(path, text, error, error_size);
  if (read != ConfigLoad::kLoaded) return read;
  return apply_config_text(text, path, schema, error, error_size) ? ConfigLoad::kLoaded
                                                                  : ConfigLoad::kInvalid;
}

ConfigLoad apply_parameters_text(std::string_view text, const char* path, ParameterTable& table,
                                 char* error, std::size_t error_size, ConfigWarning warn,
                                 void* warn_context) {
  toml::table root;
  if (!parse_toml(text, path, root, error, error_size)) return ConfigLoad::kInvalid;
  // In the file's order, so the warnings are too.
  std::vector<std::pair<const toml::key*, const toml::node*>> entries;
  for (auto&& [key, node] : root) entries.emplace_back(&key, &node);
  std::stable_sort(entries.begin(), entries.end(), [](const auto& a, const auto& b) {
    return a.first->source().begin.line < b.first->source().begin.line;
  });
  for (const auto& [key_pointer, node_pointer] : entries) {
    const toml::key& key = *key_pointer;
    const toml::node& node = *node_pointer;
    const std::string_view name = key.str();
    char message[320] = "";
    const char* why = nullptr;
    double value = 0.0;
    if (const toml::value<std::int64_t>* i = node.as_integer(); i != nullptr) {
      value = static_cast<double>(i->get());
    } else if (const toml::value<double>* d = node.as_floating_point(); d != nullptr) {
      value = d->get();
    } else {
      why = "not a number";
    }
    if (why == nullptr && table.find(name) == nullptr) why = "unknown parameter";
    if (why == nullptr && !(std::fabs(value) <= static_cast<double>(FLT_MAX))) {
      why = "value out of range";
    }
    // Saved with %.9g, so a float the table held reads back exactly.
    if (why == nullptr) why = table.set(name, static_cast<float>(value));
    if (why != nullptr) {
      fail_at(message, sizeof message, path, key.source().begin.line, "%.*s: %s; default kept",
              static_cast<int>(name.size()), name.data(), why);
      if (warn != nullptr) warn(message, warn_context);
    }
  }
  return ConfigLoad::kLoaded;
}

ConfigLoad load_parameters_file(const char* path, ParameterTable& table, char* error,
                                std::size_t error_size, ConfigWarning warn, void* warn_context) {
  std::string text;
  const ConfigLoad read = read_file(path, text, error, error_size);
  if (read != ConfigLoad::kLoaded) return read;
  return apply_parameters_text(text, path, table, error, error_size, warn, warn_context);
}

}  // namespace boticelli::firmware
