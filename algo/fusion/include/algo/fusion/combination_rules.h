// Classic rules that combine two occupancy readings of one point (thesis §4.2–4.3), as baselines.
#pragma once

#include <cmath>

namespace boticelli::fusion {

// Every rule here assumes the two readings independent; §4.4.2 shows why that fails for
// a camera that sees the same bad feature again (see the tests: 0.6 ⊕ 0.6 ≈ 0.69).

// Eq 4.9 (Elfes): posterior occupancy from the prior m₁ = P(o|r₁) and the second
// reading's likelihood P(r₂|o), with P(r₂|e) taken as 1 − P(r₂|o).
inline double elfes(double prior_occupancy, double likelihood_r2_given_occupied) {
  const double p = likelihood_r2_given_occupied;
  const double num = p * prior_occupancy;
  const double den = num + (1.0 - p) * (1.0 - prior_occupancy);
  return den > 0.0 ? num / den : 0.5;
}

// Eq 4.10 independent opinion pool: m₁₊₂ = m₁m₂ / (m₁m₂ + (1 − m₁)(1 − m₂)).
inline double independent_opinion(double m1, double m2) {
  const double num = m1 * m2;
  const double den = num + (1.0 - m1) * (1.0 - m2);
  return den > 0.0 ? num / den : 0.5;
}

// Eq 4.11 linear opinion pool: m₁₊₂ = w₁m₁ + w₂m₂ with w₂ = 1 − w₁.
inline double linear_opinion(double m1, double m2, double w1 = 0.5) {
  return w1 * m1 + (1.0 - w1) * m2;
}

// Log-odds occupancy (Moravec, after Eq 4.14): l = log(P(o|r) / P(e|r)).
inline double log_odds(double occupancy) {
  return std::log(occupancy / (1.0 - occupancy));
}
inline double occupancy_from_log_odds(double l) {
  return 1.0 / (1.0 + std::exp(-l));
}
// Eq 4.15: evidence adds in log-odds.
inline double log_odds_combine(double l1, double l2) {
  return l1 + l2;
}

// Evidence masses of one point (Eq 4.16–4.18): occupied, empty, and the rest on
// "occupied or empty" (unknown); belief Bel(o) = occupied, plausibility Pl(o) = 1 − empty.
struct Masses {
  double occupied = 0.0;
  double empty = 0.0;
  [[nodiscard]] double unknown() const { return 1.0 - occupied - empty; }
  [[nodiscard]] double belief() const { return occupied; }
  [[nodiscard]] double plausibility() const { return 1.0 - empty; }
};

// Eq 4.19 Dempster-Shafer rule of combination (and its mirror for "empty"). With total
// conflict (one says surely occupied, the other surely empty) the rule is undefined; the
// result is then all unknown.
inline Masses dempster_shafer(const Masses& a, const Masses& b) {
  const double conflict = a.occupied * b.empty + b.occupied * a.empty;
  const double norm = 1.0 - conflict;
  if (!(norm > 1e-12)) {
    return {};
  }
  const double o = a.occupied * b.unknown() + b.occupied * a.unknown() + a.occupied * b.occupied;
  const double e = a.empty * b.unknown() + b.empty * a.unknown() + a.empty * b.empty;
  return {o / norm, e / norm};
}

}  // namespace boticelli::fusion
