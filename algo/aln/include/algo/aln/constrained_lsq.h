// Box-constrained least squares for one linear piece: the exact optimum with weight bounds.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>

#include <Eigen/Cholesky>
#include <Eigen/Core>

namespace boticelli::aln {

// Minimises q(w) = w' C w - 2 g' w subject to lo_i <= w_i <= hi_i (bounds may be infinite),
// where C (N x N, symmetric positive definite: add a small ridge for degenerate data) and g
// are the centred normal equations of a piece's samples: C = cov(x), g = cov(x, y). The bias
// of the piece is free and has been eliminated (it is ybar - w . xbar), so this is the whole
// least-squares problem of thesis Eq 4.22 for one piece under the constraints of
// Eqs 4.27-4.28. The optimum of a strictly convex QP has some active set (each bound
// variable free, at lo or at hi); we try the unconstrained solution first and otherwise
// every active set (3^N <= 81 for N = 4), solving the reduced system for each and keeping
// the feasible one with the least q. This is exact, not a clip after the fact.
// Returns false only if no candidate was feasible (lo > hi or a non-finite system).
template <int N>
bool solve_box_constrained_lsq(const Eigen::Matrix<double, N, N>& c,
                               const Eigen::Matrix<double, N, 1>& g,
                               const std::array<double, static_cast<std::size_t>(N)>& lo,
                               const std::array<double, static_cast<std::size_t>(N)>& hi,
                               Eigen::Matrix<double, N, 1>& w) {
  using Mat = Eigen::Matrix<double, N, N>;
  using Vec = Eigen::Matrix<double, N, 1>;
  const auto inside = [&](const Vec& v) {
    for (int i = 0; i < N; ++i) {
      const auto k = static_cast<std::size_t>(i);
      if (!(v(i) >= lo[k] && v(i) <= hi[k])) return false;
    }
    return true;
  };
  const auto objective = [&](const Vec& v) { return v.dot(c * v) - 2.0 * g.dot(v); };

  // 1. Unconstrained optimum.
  const Eigen::LDLT<Mat> full(c);
  Vec free_w = full.solve(g);
  if (free_w.allFinite() && inside(free_w)) {
    w = free_w;
    return true;
  }
  // 2. Every active set: state[i] = 0 free, 1 at lo, 2 at hi.
  std::size_t combos = 1;
  for (int i = 0; i < N; ++i) combos *= 3;
  bool found = false;
  double best = 0.0;
  for (std::size_t code = 1; code < combos; ++code) {
    std::array<int, static_cast<std::size_t>(N)> state{};
    std::size_t rest = code;
    bool usable = true;
    for (int i = 0; i < N; ++i) {
      const auto k = static_cast<std::size_t>(i);
      state[k] = static_cast<int>(rest % 3);
      rest /= 3;
      if ((state[k] == 1 && !std::isfinite(lo[k])) || (state[k] == 2 && !std::isfinite(hi[k]))) {
        usable = false;
      }
    }
    if (!usable) continue;
    Vec fixed = Vec::Zero();
    for (int i = 0; i < N; ++i) {
      const auto k = static_cast<std::size_t>(i);
      if (state[k] == 1) fixed(i) = lo[k];
      if (state[k] == 2) fixed(i) = hi[k];
    }
    // Reduced system: free rows keep C, fixed rows become identity.
    Mat m = Mat::Identity();
    Vec rhs = fixed;
    for (int i = 0; i < N; ++i) {
      if (state[static_cast<std::size_t>(i)] != 0) continue;
      rhs(i) = g(i);
      for (int j = 0; j < N; ++j) {
        if (state[static_cast<std::size_t>(j)] == 0) {
          m(i, j) = c(i, j);
        } else {
          rhs(i) -= c(i, j) * fixed(j);
        }
      }
    }
    Vec v = m.ldlt().solve(rhs);
    for (int i = 0; i < N; ++i) {
      if (state[static_cast<std::size_t>(i)] != 0) v(i) = fixed(i);  // exactly on the bound
    }
    if (!v.allFinite() || !inside(v)) continue;
    const double q = objective(v);
    if (!found || q < best) {
      best = q;
      w = v;
      found = true;
    }
  }
  return found;
}

}  // namespace boticelli::aln
