// Unit conversions between the code's SI units and the thesis's decimetres, in one place.
#pragma once

namespace boticelli::core {

// The thesis (ch. 4, 5) measures h and r in decimetres; the code uses metres everywhere.
inline constexpr double kMetresPerDecimetre = 0.1;

constexpr double dm_to_m(double dm) {
  return dm * kMetresPerDecimetre;
}
constexpr double m_to_dm(double m) {
  return m / kMetresPerDecimetre;
}

// A slope bound given per decimetre (thesis Eqs 4.27–4.28: |a|, |b| < 1 per dm of h or r)
// becomes a bound per metre: occupancy changes 10x faster per metre than per decimetre.
constexpr double slope_per_dm_to_per_m(double per_dm) {
  return per_dm / kMetresPerDecimetre;
}

}  // namespace boticelli::core
