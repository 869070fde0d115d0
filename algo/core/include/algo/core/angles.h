// Angle helpers in radians: wrapping to [0, 2π) and (−π, π], degree conversion.
#pragma once

#include <cmath>
#include <numbers>

namespace boticelli::core {

template <typename T>
inline constexpr T kPi = std::numbers::pi_v<T>;
template <typename T>
inline constexpr T kTwoPi = T(2) * std::numbers::pi_v<T>;

template <typename T>
constexpr T deg_to_rad(T deg) {
  return deg * kPi<T> / T(180);
}
template <typename T>
constexpr T rad_to_deg(T rad) {
  return rad * T(180) / kPi<T>;
}

// [rad] → [0, 2π): the pan angle α of a Reading.
template <typename T>
T wrap_two_pi(T rad) {
  T w = std::fmod(rad, kTwoPi<T>);
  if (w < T(0)) {
    w += kTwoPi<T>;
  }
  return w >= kTwoPi<T> ? T(0) : w;
}

// [rad] → (−π, π]: headings and angle differences.
template <typename T>
T wrap_pi(T rad) {
  T w = wrap_two_pi(rad);
  return w > kPi<T> ? w - kTwoPi<T> : w;
}

}  // namespace boticelli::core
