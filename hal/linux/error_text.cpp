// Fixed-size error text for drivers.
#include "hal/linux/error_text.h"

#include <cstdio>
#include <cstring>

namespace boticelli::hal_linux {

void set_error(char* out, std::size_t size, const char* what, int err) {
  if (size == 0) return;
  if (err == 0) {
    std::snprintf(out, size, "%s", what);
  } else {
    char buf[96];
    // GNU strerror_r may return a static string instead of filling buf.
    const char* text = ::strerror_r(err, buf, sizeof buf);
    std::snprintf(out, size, "%s: %s", what, text);
  }
}

}  // namespace boticelli::hal_linux
