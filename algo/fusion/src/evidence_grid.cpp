// Log-odds evidence grid: ray integration with a voxel walk, and cell queries.
#include "algo/fusion/evidence_grid.h"

#include <cmath>
#include <limits>

namespace boticelli::fusion {
namespace {

float log_odds_of(float occupancy) {
  return std::log(occupancy / (1.0F - occupancy));
}

}  // namespace

void EvidenceGridBase::clear() {
  for (std::size_t i = 0; i < cells(); ++i) {
    cells_[i] = 0.0F;
  }
}

void EvidenceGridBase::add(std::size_t index, float log_odds) {
  // Eq 4.15: independent evidence adds in log-odds; clamped.
  float v = cells_[index] + log_odds;
  if (v > model_.log_odds_limit) {
    v = model_.log_odds_limit;
  } else if (v < -model_.log_odds_limit) {
    v = -model_.log_odds_limit;
  }
  cells_[index] = v;
}

std::size_t EvidenceGridBase::integrate(const GridPoint& sensor, const evidence::Reading& reading) {
  if (!(reading.r_m > 0.0F) || !(box_.cell_m > 0.0F)) {
    return 0;
  }
  const float r = reading.r_m;
  const float dr = model_.delta_r_fraction * r;
  const float t_end = r + dr;
  // Direction of the ray: (α, h, r) → unit vector (ρ = √(r² − h²), §5.4.2).
  const float h_over_r = reading.h_m / r;
  const float rho_over_r = std::sqrt(std::fmax(0.0F, 1.0F - h_over_r * h_over_r));
  const std::array<float, 3> dir = {rho_over_r * std::cos(reading.alpha_rad),
                                    rho_over_r * std::sin(reading.alpha_rad), h_over_r};
  const std::array<float, 3> origin = {sensor.x_m, sensor.y_m, sensor.z_m};
  const std::array<float, 3> lo = {box_.min_corner.x_m, box_.min_corner.y_m, box_.min_corner.z_m};
  const std::array<std::size_t, 3> n = {nx_, ny_, nz_};
  const float cell = box_.cell_m;

  // Clip the segment [0, t_end] to the box (slab method).
  float t0 = 0.0F;
  float t1 = t_end;
  for (std::size_t a = 0; a < 3; ++a) {
    const float hi = lo[a] + cell * static_cast<float>(n[a]);
    if (std::fabs(dir[a]) < 1e-9F) {
      if (origin[a] < lo[a] || origin[a] >= hi) {
        return 0;
      }
      continue;
    }
    float ta = (lo[a] - origin[a]) / dir[a];
    float tb = (hi - origin[a]) / dir[a];
    if (ta > tb) {
      const float tmp = ta;
      ta = tb;
      tb = tmp;
    }
    t0 = std::fmax(t0, ta);
    t1 = std::fmin(t1, tb);
  }
  if (!(t0 < t1)) {
    return 0;
  }

  // Amanatides & Woo: the cell at t0, then step across the nearest cell boundary.
  std::array<std::ptrdiff_t, 3> idx{};
  std::array<std::ptrdiff_t, 3> step{};
  std::array<float, 3> t_next{};
  std::array<float, 3> t_delta{};
  constexpr float kInf = std::numeric_limits<float>::infinity();
  for (std::size_t a = 0; a < 3; ++a) {
    const float p = origin[a] + dir[a] * t0;
    auto i = static_cast<std::ptrdiff_t>(std::floor((p - lo[a]) / cell));
    const auto last = static_cast<std::ptrdiff_t>(n[a]) - 1;
    i = i < 0 ? 0 : (i > last ? last : i);
    idx[a] = i;
    if (dir[a] > 0.0F) {
      step[a] = 1;
      t_next[a] = (lo[a] + cell * static_cast<float>(i + 1) - origin[a]) / dir[a];
      t_delta[a] = cell / dir[a];
    } else if (dir[a] < 0.0F) {
      step[a] = -1;
      t_next[a] = (lo[a] + cell * static_cast<float>(i) - origin[a]) / dir[a];
      t_delta[a] = -cell / dir[a];
    } else {
      step[a] = 0;
      t_next[a] = kInf;
      t_delta[a] = kInf;
    }
  }

  const float free_lo = reading.m * log_odds_of(model_.free_occupancy);
  const float occ_lo = reading.m > 0.5F ? log_odds_of(reading.m) : 0.0F;
  std::size_t updated = 0;
  float t_enter = t0;
  while (t_enter < t1) {
    std::size_t axis = 0;
    if (t_next[1] < t_next[axis]) {
      axis = 1;
    }
    if (t_next[2] < t_next[axis]) {
      axis = 2;
    }
    const float t_exit = std::fmin(t_next[axis], t1);
    const auto index =
        (static_cast<std::size_t>(idx[2]) * ny_ + static_cast<std::size_t>(idx[1])) * nx_ +
        static_cast<std::size_t>(idx[0]);
    if (t_exit <= r - dr) {
      add(index, free_lo);
      ++updated;
    } else if (occ_lo != 0.0F) {
      add(index, occ_lo);
      ++updated;
    }
    idx[axis] += step[axis];
    if (idx[axis] < 0 || idx[axis] >= static_cast<std::ptrdiff_t>(n[axis])) {
      break;
    }
    t_enter = t_next[axis];
    t_next[axis] += t_delta[axis];
  }
  return updated;
}

float EvidenceGridBase::log_odds_at(const GridPoint& p) const {
  const float cell = box_.cell_m;
  const float fx = std::floor((p.x_m - box_.min_corner.x_m) / cell);
  const float fy = std::floor((p.y_m - box_.min_corner.y_m) / cell);
  const float fz = std::floor((p.z_m - box_.min_corner.z_m) / cell);
  if (fx < 0.0F || fy < 0.0F || fz < 0.0F || fx >= static_cast<float>(nx_) ||
      fy >= static_cast<float>(ny_) || fz >= static_cast<float>(nz_)) {
    return 0.0F;
  }
  const auto ix = static_cast<std::size_t>(fx);
  const auto iy = static_cast<std::size_t>(fy);
  const auto iz = static_cast<std::size_t>(fz);
  return cells_[(iz * ny_ + iy) * nx_ + ix];
}

float EvidenceGridBase::occupancy_at(const GridPoint& p) const {
  return 1.0F / (1.0F + std::exp(-log_odds_at(p)));
}

}  // namespace boticelli::fusion
