// Fixed-size error text for drivers: formatting without heap allocation on the cyclic path.
#pragma once

#include <cstddef>

namespace boticelli::hal_linux {

// Writes "<what>: <strerror(err)>" (or just `what` when err == 0) into `out`, truncated.
void set_error(char* out, std::size_t size, const char* what, int err = 0);

template <std::size_t N>
void set_error(char (&out)[N], const char* what, int err = 0) {
  set_error(out, N, what, err);
}

}  // namespace boticelli::hal_linux
