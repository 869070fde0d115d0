// StarPolygon: vertex geometry, the exact radial function and point containment.
#include "algo/mapping/star_polygon.h"

#include <algorithm>

namespace boticelli::mapping {

void StarPolygon::set_vertex_count(std::size_t vertex_count) {
  count_ = clamped_vertex_count(vertex_count);
  fill(0.0F);
}

void StarPolygon::fill(float rho_m) {
  for (std::size_t k = 0; k < count_; ++k) {
    rho_m_[k] = rho_m;
  }
}

core::Point2 StarPolygon::vertex(std::size_t k) const {
  const float a = angle_rad(k);
  return {rho_m_[k] * std::cos(a), rho_m_[k] * std::sin(a)};
}

float StarPolygon::radius_at_m(float theta_rad) const {
  // The edge of sector k in polar form: r(θ) = ρ_k ρ_{k+1} sin Δ / (ρ_k sin(θ − θ_k) +
  // ρ_{k+1} sin(θ_{k+1} − θ)), exact for the straight segment between the two vertices.
  const double step = core::kTwoPi<double> / static_cast<double>(count_);
  const double theta = static_cast<double>(core::wrap_two_pi(theta_rad));
  auto k = static_cast<std::size_t>(theta / step);
  if (k >= count_) {
    k = count_ - 1;
  }
  const double t = theta - static_cast<double>(k) * step;
  const auto a = static_cast<double>(rho_m_[k]);
  const auto b = static_cast<double>(rho_m_[(k + 1) % count_]);
  const double den = a * std::sin(t) + b * std::sin(step - t);
  if (!(den > 0.0)) {
    return 0.0F;
  }
  return static_cast<float>(a * b * std::sin(step) / den);
}

bool StarPolygon::contains(core::Point2 p) const {
  const float d = std::hypot(p.x_m, p.y_m);
  if (d == 0.0F) {
    return true;
  }
  return d <= radius_at_m(std::atan2(p.y_m, p.x_m));
}

float StarPolygon::area_m2() const {
  const double s = std::sin(core::kTwoPi<double> / static_cast<double>(count_));
  double area = 0.0;
  for (std::size_t k = 0; k < count_; ++k) {
    area +=
        0.5 * static_cast<double>(rho_m_[k]) * static_cast<double>(rho_m_[(k + 1) % count_]) * s;
  }
  return static_cast<float>(area);
}

float StarPolygon::min_rho_m() const {
  return *std::min_element(rho_m_.begin(), rho_m_.begin() + static_cast<std::ptrdiff_t>(count_));
}

float StarPolygon::max_rho_m() const {
  return *std::max_element(rho_m_.begin(), rho_m_.begin() + static_cast<std::ptrdiff_t>(count_));
}

}  // namespace boticelli::mapping
