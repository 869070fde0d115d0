// Ray samples of the visual sensor model: placement along the ray, seam copies and pads.
#include "algo/evidence/ray_samples.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "algo/core/angles.h"

namespace boticelli::evidence {
namespace {

bool valid(const RaySampleParams& params) {
  return params.samples_per_reading >= 3 && params.samples_per_reading <= kMaxSamplesPerReading &&
         params.line_of_sight_samples <= kMaxSamplesPerReading && params.delta_r_fraction > 0.0F &&
         params.ramp_length_delta_r > 0.0F;
}

// A sample on the reading's ray of view at distance s [m] (height scales with s/r).
RaySample on_ray(const Reading& reading, float s_m, float occupancy) {
  const float h_m = reading.r_m > 0.0F ? reading.h_m * (s_m / reading.r_m) : 0.0F;
  return {reading.alpha_rad, h_m, s_m, occupancy};
}

// Appends the plausibility samples; the caller has checked the room.
void put_plausibility(const Reading& reading, const RaySampleParams& params, RaySampleBuffer& out) {
  const float r = reading.r_m;
  const float dr = params.delta_r_fraction * r;  // δr = 0.1 r (§3.7.3)
  const std::size_t k = params.samples_per_reading - 3;
  // Two plateau samples at evidence m: the range error of Eq 3.7 around the point.
  (void)out.push_back(on_ray(reading, r + dr, reading.m));
  (void)out.push_back(on_ray(reading, r - dr, reading.m));
  // Lower samples towards the camera: occupancy falls gradually (Fig 3.8b).
  const float kf = static_cast<float>(k);
  for (std::size_t j = 1; j <= k; ++j) {
    const float jf = static_cast<float>(j);
    const float s = r - (1.0F + jf * params.ramp_length_delta_r / kf) * dr;
    const float m = reading.m * (1.0F - jf / (kf + 1.0F));
    (void)out.push_back(on_ray(reading, s > 0.0F ? s : 0.0F, m));
  }
  // The robot centre is empty (Fig 4.2b), and so is the line of sight up to the ramp's foot.
  (void)out.push_back({reading.alpha_rad, 0.0F, 0.0F, 0.0F});
  const std::size_t n = params.line_of_sight_samples;
  if (n > 0) {
    // The ramp's zero (ray_samples.h); without lower samples, the near plateau sample.
    const float reach = k == 0 ? 1.0F : 1.0F + params.ramp_length_delta_r * (kf + 1.0F) / kf;
    const float nf = static_cast<float>(n);
    if (reading.view_x_m == 0.0F && reading.view_y_m == 0.0F && reading.view_z_m == 0.0F) {
      const float foot = std::max(r - reach * dr, 0.0F);
      for (std::size_t j = 1; j <= n; ++j) {
        (void)out.push_back(on_ray(reading, foot * static_cast<float>(j) / (nf + 1.0F), 0.0F));
      }
      return;
    }
    // From the view: the point p, the view v, the foot reach·δr short of p along v → p.
    const core::Point2 p = floor_point_m(reading);
    const float dx = p.x_m - reading.view_x_m;
    const float dy = p.y_m - reading.view_y_m;
    const float dz = reading.h_m - reading.view_z_m;
    const float d = std::sqrt(dx * dx + dy * dy + dz * dz);
    const float foot = d > 0.0F ? std::max(d - reach * dr, 0.0F) / d : 0.0F;  // of v → p
    for (std::size_t j = 1; j <= n; ++j) {
      const float t = foot * static_cast<float>(j) / (nf + 1.0F);
      const float x = reading.view_x_m + t * dx;
      const float y = reading.view_y_m + t * dy;
      const float z = reading.view_z_m + t * dz;
      const Reading free = reading_at(x, y, z, 0.0F);
      (void)out.push_back({free.alpha_rad, free.h_m, free.r_m, 0.0F});
    }
  }
}

}  // namespace

std::size_t append_plausibility_samples(const Reading& reading, const RaySampleParams& params,
                                        RaySampleBuffer& out) {
  const std::size_t n = plausibility_samples_per_reading(params);
  if (!valid(params) || !(reading.r_m > 0.0F) || out.capacity() - out.size() < n) {
    return 0;
  }
  put_plausibility(reading, params, out);
  return n;
}

std::size_t append_belief_samples(const Reading& reading, const RaySampleParams& params,
                                  RaySampleBuffer& out) {
  const std::size_t n = belief_samples_per_reading(params);
  if (!valid(params) || !(reading.r_m > 0.0F) || out.capacity() - out.size() < n) {
    return 0;
  }
  put_plausibility(reading, params, out);
  const float r = reading.r_m;
  const float dr = params.delta_r_fraction * r;
  const std::size_t k = params.samples_per_reading - 3;
  const float kf = static_cast<float>(k);
  // Behind the point the evidence falls back to zero (§3.7.3): the ramp mirrored.
  for (std::size_t j = 1; j <= k; ++j) {
    const float jf = static_cast<float>(j);
    const float s = r + (1.0F + jf * params.ramp_length_delta_r / kf) * dr;
    (void)out.push_back(on_ray(reading, s, reading.m * (1.0F - jf / (kf + 1.0F))));
  }
  const float s_zero = r + (1.0F + params.ramp_length_delta_r * (kf + 1.0F) / kf) * dr;
  (void)out.push_back(on_ray(reading, s_zero, 0.0F));
  return n;
}

std::size_t append_ray_samples(std::span<const Reading> readings, const RaySampleParams& params,
                               RaySampleBuffer& out, OccupancyBound bound) {
  std::size_t fitted = 0;
  for (const Reading& reading : readings) {
    const std::size_t added = bound == OccupancyBound::kPlausibility
                                  ? append_plausibility_samples(reading, params, out)
                                  : append_belief_samples(reading, params, out);
    if (added > 0) {
      ++fitted;
    }
  }
  return fitted;
}

std::size_t append_seam_copies(RaySampleBuffer& samples, float margin_rad) {
  constexpr float kTwoPi = core::kTwoPi<float>;
  const std::size_t original = samples.size();
  std::size_t copies = 0;
  for (std::size_t i = 0; i < original; ++i) {
    const RaySample s = samples[i];
    if (s.alpha_rad < margin_rad) {
      RaySample c = s;
      c.alpha_rad += kTwoPi;
      if (!samples.push_back(c)) {
        return copies;
      }
      ++copies;
    }
    if (s.alpha_rad > kTwoPi - margin_rad) {
      RaySample c = s;
      c.alpha_rad -= kTwoPi;
      if (!samples.push_back(c)) {
        return copies;
      }
      ++copies;
    }
  }
  return copies;
}

float PadRandom::uniform() {
  // xorshift32 (Marsaglia 2003); state never becomes zero from a non-zero seed.
  if (state == 0U) {
    state = 0x9E3779B9U;
  }
  state ^= state << 13U;
  state ^= state >> 17U;
  state ^= state << 5U;
  return static_cast<float>(state >> 8U) * (1.0F / 16777216.0F);
}

namespace {
float lerp(float a, float b, float t) {
  return a + (b - a) * t;
}
}  // namespace

std::size_t append_zero_pads(const PadRegion& region, std::size_t count, PadRandom& random,
                             RaySampleBuffer& out) {
  std::size_t added = 0;
  for (; added < count; ++added) {
    const float a = lerp(region.alpha_min_rad, region.alpha_max_rad, random.uniform());
    const float h = lerp(region.h_min_m, region.h_max_m, random.uniform());
    const float r = lerp(region.r_min_m, region.r_max_m, random.uniform());
    if (!out.push_back({a, h, r, 0.0F})) {
      break;
    }
  }
  return added;
}

std::size_t append_featureless_pads(std::span<const Reading> readings, const PadRegion& region,
                                    const FeaturelessPadParams& params, PadRandom& random,
                                    RaySampleBuffer& out) {
  const std::size_t na = params.alpha_bins;
  const std::size_t ne = params.elevation_bins;
  const float alpha_span = region.alpha_max_rad - region.alpha_min_rad;
  const float el_span = params.elevation_max_rad - params.elevation_min_rad;
  if (na == 0 || ne == 0 || na > kMaxPadBins || ne > kMaxPadBins || !(alpha_span > 0.0F) ||
      !(el_span > 0.0F) || !(region.r_max_m > region.r_min_m)) {
    return 0;
  }
  std::array<bool, kMaxPadBins * kMaxPadBins> seen{};
  const float naf = static_cast<float>(na);
  const float nef = static_cast<float>(ne);
  for (const Reading& reading : readings) {
    if (!(reading.r_m > 0.0F)) {
      continue;
    }
    const float sin_el = std::clamp(reading.h_m / reading.r_m, -1.0F, 1.0F);
    const float ta = (reading.alpha_rad - region.alpha_min_rad) / alpha_span;
    const float te = (std::asin(sin_el) - params.elevation_min_rad) / el_span;
    if (ta < 0.0F || ta >= 1.0F || te < 0.0F || te >= 1.0F) {
      continue;
    }
    const auto ia = std::min(static_cast<std::size_t>(ta * naf), na - 1);
    const auto ie = std::min(static_cast<std::size_t>(te * nef), ne - 1);
    seen[ia * ne + ie] = true;
  }
  std::size_t added = 0;
  for (std::size_t ia = 0; ia < na; ++ia) {
    for (std::size_t ie = 0; ie < ne; ++ie) {
      if (seen[ia * ne + ie]) {
        continue;
      }
      for (std::size_t p = 0; p < params.pads_per_empty_cell; ++p) {
        const float a =
            region.alpha_min_rad + alpha_span * (static_cast<float>(ia) + random.uniform()) / naf;
        const float el =
            params.elevation_min_rad + el_span * (static_cast<float>(ie) + random.uniform()) / nef;
        const float sin_el = std::sin(el);
        // The farthest distance whose height stays inside [h_min, h_max].
        float r_far = region.r_max_m;
        if (sin_el > 0.0F && region.h_max_m < r_far * sin_el) {
          r_far = region.h_max_m / sin_el;
        } else if (sin_el < 0.0F && region.h_min_m > r_far * sin_el) {
          r_far = region.h_min_m / sin_el;
        }
        if (!(r_far > region.r_min_m)) {
          continue;
        }
        const float r = lerp(region.r_min_m, r_far, random.uniform());
        if (!out.push_back({a, r * sin_el, r, 0.0F})) {
          return added;
        }
        ++added;
      }
    }
  }
  return added;
}

}  // namespace boticelli::evidence
