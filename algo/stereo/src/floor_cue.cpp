// Floor-appearance cue (Ulrich & Nourbakhsh 2000): floor model, column walk, ground-plane ranging.
#include "algo/stereo/floor_cue.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "algo/core/angles.h"
#include "algo/stereo/triangulation.h"

namespace boticelli::stereo {

namespace {

constexpr float kLumaBlack = 16.0F;   // BT.601 limited range: Y = 16 + 219·luminance
constexpr std::uint32_t kMaxRun = 8;  // cap of boundary_run [px]
constexpr std::uint32_t kMaxReferenceRows = 64;
constexpr std::size_t kRunBins = 101;  // runs of one colour, by whole cm up to 1 m and beyond

// Median and robust spread (1.4826 · MAD) of one channel's histogram of `count` samples.
void robust_stats(const std::array<std::uint32_t, 256>& histogram, std::size_t count, float& median,
                  float& sigma) {
  const std::size_t half = (count + 1) / 2;
  std::size_t seen = 0;
  int mid = 0;
  for (int b = 0; b < 256; ++b) {
    seen += histogram[static_cast<std::size_t>(b)];
    if (seen >= half) {
      mid = b;
      break;
    }
  }
  // Median absolute deviation: grow a window around the median until it holds half.
  std::size_t inside = histogram[static_cast<std::size_t>(mid)];
  int d = 0;
  while (inside < half && d < 255) {
    ++d;
    if (mid - d >= 0) {
      inside += histogram[static_cast<std::size_t>(mid - d)];
    }
    if (mid + d <= 255) {
      inside += histogram[static_cast<std::size_t>(mid) + static_cast<std::size_t>(d)];
    }
  }
  median = static_cast<float>(mid);
  sigma = 1.4826F * static_cast<float>(d);
}

// Median of the first n (1 ≤ n ≤ kMaxRun) values (reordered in place).
float median_of(std::array<float, kMaxRun>& values, std::uint32_t n) {
  const auto middle = values.begin() + std::min(n, kMaxRun) / 2;
  std::nth_element(values.begin(), middle, values.begin() + std::min(n, kMaxRun));
  return *middle;
}

std::uint8_t to_byte(float x) {
  return static_cast<std::uint8_t>(std::clamp(std::lround(x), 0L, 255L));
}

// The histogram bin of compensated (Y, Cb − 128, Cr − 128) values.
std::size_t bin_of(const std::array<float, 3>& values) {
  const auto luma = static_cast<std::size_t>(std::clamp(values[0], 0.0F, 255.0F)) / 16U;
  const auto chroma = [](float c) {
    return static_cast<std::size_t>(std::clamp((c + 32.0F) / 8.0F, 0.0F, 7.0F));
  };
  return (std::min(luma, kFloorLumaBins - 1) * kFloorChromaBins + chroma(values[1])) *
             kFloorChromaBins +
         chroma(values[2]);
}

// share[b]: the mass of bin b and of every bin next to it (3 × 3 × 3 bins).
void smooth_mass(const std::array<float, kFloorBins>& mass, std::array<float, kFloorBins>& share) {
  constexpr auto kL = static_cast<long>(kFloorLumaBins);
  constexpr auto kC = static_cast<long>(kFloorChromaBins);
  for (long y = 0; y < kL; ++y) {
    for (long u = 0; u < kC; ++u) {
      for (long v = 0; v < kC; ++v) {
        float sum = 0.0F;
        for (long dy = std::max(y - 1, 0L); dy <= std::min(y + 1, kL - 1); ++dy) {
          for (long du = std::max(u - 1, 0L); du <= std::min(u + 1, kC - 1); ++du) {
            for (long dv = std::max(v - 1, 0L); dv <= std::min(v + 1, kC - 1); ++dv) {
              sum += mass[static_cast<std::size_t>((dy * kC + du) * kC + dv)];
            }
          }
        }
        share[static_cast<std::size_t>((y * kC + u) * kC + v)] = sum;
      }
    }
  }
}

// Adds one walked frame's readings to a process() call's result.
void add_walk(const FloorCueResult& r, FloorCueResult& total) {
  total.obstacle_readings += r.obstacle_readings;
  total.free_readings += r.free_readings;
  total.blocked_readings += r.blocked_readings;
  total.boundaries += r.boundaries;
  total.truncated = total.truncated || r.truncated;
}

}  // namespace

FloorCue::FloorCue(const RigModel& rig, const FloorCueParams& params) : rig_(rig), params_(params) {
  params_.boundary_run = std::clamp<std::uint32_t>(params_.boundary_run, 1, kMaxRun);
  params_.column_step = std::max<std::uint32_t>(params_.column_step, 1);
  params_.obstacle_height_count = std::min<std::uint32_t>(
      params_.obstacle_height_count, static_cast<std::uint32_t>(params_.obstacle_heights_m.size()));
  params_.reference_rows_max = std::min(params_.reference_rows_max, kMaxReferenceRows);
  params_.learn_rate = std::clamp(params_.learn_rate, 0.0F, 1.0F);
}

bool FloorCue::floor_point(const CameraPose& pose, float u, float v, Eigen::Vector3f& point,
                           float& rho_m) const {
  const Eigen::Vector3f ray = RigModel::ray_ptu(pose, rig_.low_res_camera(), Eigen::Vector2f(u, v));
  if (!(ray.z() < -1e-6F)) {
    return false;  // at or above the horizon
  }
  const float floor_z = -rig_.params().ptu_height_m;  // the floor in the PTU frame [m]
  const float t = (floor_z - pose.centre_m.z()) / ray.z();
  if (!(t > 0.0F)) {
    return false;
  }
  point = pose.centre_m + t * ray;
  rho_m = std::sqrt(point.x() * point.x() + point.y() * point.y());
  return true;
}

void FloorCue::pixel_values(const image::LowResFrame& frame, std::uint32_t u, std::uint32_t v,
                            std::array<float, 3>& values) const {
  // Vignetting as a radial quadratic fall-off to (1 − vignetting) in the corners; undone so
  // the floor looks the same everywhere in the image.
  const float cx = 0.5F * static_cast<float>(frame.width - 1);
  const float cy = 0.5F * static_cast<float>(frame.height - 1);
  const float dx = static_cast<float>(u) - cx;
  const float dy = static_cast<float>(v) - cy;
  const float gain = 1.0F / (1.0F - params_.vignetting * (dx * dx + dy * dy) / (cx * cx + cy * cy));
  values[0] = kLumaBlack + (frame.y(u, v) - kLumaBlack) * gain;
  values[1] = static_cast<float>(frame.cb(u, v)) * gain;
  values[2] = static_cast<float>(frame.cr(u, v)) * gain;
}

float FloorCue::contrast_to(const FloorModel& model, const std::array<float, 3>& values) const {
  if (model.textured) {
    const float share = model.share[bin_of(values)];
    return share > 0.0F ? params_.texture_min_share / share
                        : std::numeric_limits<float>::infinity();
  }
  float worst = 0.0F;
  for (std::size_t c = 0; c < 3; ++c) {
    worst = std::max(worst, std::fabs(values[c] - model.median[c]) / model.tolerance[c]);
  }
  return worst;
}

bool FloorCue::looks_like_floor(const image::LowResFrame& frame, std::uint32_t u, std::uint32_t v,
                                float& contrast) const {
  contrast = std::numeric_limits<float>::infinity();
  if (!model_.valid || u >= frame.width || v >= frame.height) {
    return false;
  }
  std::array<float, 3> values{};
  pixel_values(frame, u, v, values);
  contrast = contrast_to(model_, values);
  return contrast <= 1.0F;
}

FloorLearn FloorCue::learn(const image::LowResFrame& frame, float pan_rad, float tilt_rad) {
  if (frame.width < 2 || frame.height < 2) {
    return FloorLearn::kNoRegion;
  }
  const CameraPose pose = rig_.camera_pose(pan_rad, tilt_rad);
  std::array<std::array<std::uint32_t, 256>, 3> histogram{};
  std::size_t count = 0;
  const std::uint32_t rows = std::min(params_.reference_rows_max, frame.height);
  for (std::uint32_t k = 0; k < rows; ++k) {
    const std::uint32_t v = frame.height - 1 - k;
    // Rows further up see the floor farther away: stop once a whole row is beyond the region.
    bool row_beyond = true;
    bool have_previous = false;  // the pixel just left of this one is in the region
    Eigen::Vector3f previous_point = Eigen::Vector3f::Zero();
    for (std::uint32_t u = 0; u < frame.width && count < kMaxReference; ++u) {
      Eigen::Vector3f point;
      float rho = 0.0F;
      if (!floor_point(pose, static_cast<float>(u), static_cast<float>(v), point, rho)) {
        have_previous = false;
        continue;
      }
      row_beyond = row_beyond && rho > params_.reference_max_m;
      if (rho < params_.reference_min_m || rho > params_.reference_max_m) {
        have_previous = false;
        continue;
      }
      std::array<float, 3> values{};
      pixel_values(frame, u, v, values);
      auto& stored = reference_[count++];
      stored = {to_byte(values[0]), to_byte(values[1] + 128.0F), to_byte(values[2] + 128.0F)};
      for (std::size_t c = 0; c < 3; ++c) {
        ++histogram[c][stored[c]];
      }
      reference_step_m_[count - 1] = have_previous ? (point - previous_point).norm() : -1.0F;
      reference_rho_m_[count - 1] = rho;
      have_previous = true;
      previous_point = point;
    }
    if (row_beyond) {
      break;
    }
  }
  if (count < params_.reference_min_pixels || count == 0) {
    return FloorLearn::kNoRegion;
  }
  FloorModel candidate;
  candidate.valid = true;
  const std::array<float, 3> min_tolerance{params_.min_tolerance_luma, params_.min_tolerance_chroma,
                                           params_.min_tolerance_chroma};
  const std::array<float, 3> max_tolerance{params_.max_tolerance_luma, params_.max_tolerance_chroma,
                                           params_.max_tolerance_chroma};
  bool uniform = true;
  for (std::size_t c = 0; c < 3; ++c) {
    float median = 0.0F;
    float sigma = 0.0F;
    robust_stats(histogram[c], count, median, sigma);
    candidate.median[c] = c == 0 ? median : median - 128.0F;
    candidate.tolerance[c] = std::max(params_.spread_factor * sigma, min_tolerance[c]);
    uniform = uniform && candidate.tolerance[c] <= max_tolerance[c];
  }
  if (!uniform) {
    // Two surfaces (or one too busy to tell from others): a textured floor, if the region
    // changes colour often, nothing is known of a plain one and textures are learned.
    if (!params_.textured || (model_.valid && !model_.textured) ||
        !textured_candidate(count, candidate)) {
      return FloorLearn::kNotUniform;
    }
  } else if (model_.valid && model_.textured) {
    // One colour in the region (a patch of the texture, or a plain thing on it): tested
    // against the textured model as it is, and blended into its histogram.
    const std::array<float, 3> tolerance = candidate.tolerance;
    (void)textured_candidate(count, candidate);
    candidate.textured = false;
    candidate.tolerance = tolerance;
  }
  // Consistency: the region must look like floor to its own model (an obstacle covering
  // part of it fails here) and to the model already known (one covering all of it).
  std::size_t own = 0;
  std::size_t known = 0;
  std::array<std::size_t, kPendingSlots> pending{};
  const auto agree = [&]() {
    own = known = 0;
    pending.fill(0);
    for (std::size_t i = 0; i < count; ++i) {
      const std::array<float, 3> values{static_cast<float>(reference_[i][0]),
                                        static_cast<float>(reference_[i][1]) - 128.0F,
                                        static_cast<float>(reference_[i][2]) - 128.0F};
      own += contrast_to(candidate, values) <= 1.0F ? 1U : 0U;
      known += model_.valid && contrast_to(model_, values) <= 1.0F ? 1U : 0U;
      for (std::size_t j = 0; j < kPendingSlots; ++j) {
        pending[j] += pending_[j].valid && pending_[j].textured == candidate.textured &&
                              contrast_to(pending_[j], values) <= 1.0F
                          ? 1U
                          : 0U;
      }
    }
  };
  agree();
  const auto needed =
      static_cast<std::size_t>(std::ceil(params_.consistency_min * static_cast<float>(count)));
  if (own < needed && uniform && params_.textured && !(model_.valid && !model_.textured) &&
      textured_candidate(count, candidate)) {
    // A median and a spread of one colour, yet much of the region lies outside its
    // tolerances: one colour holds at least half of it and the rest differ (tiles of two
    // colours; the spread is 0 when half the pixels have the median). A texture, if it is one.
    agree();
  }
  if (model_.valid && known < needed) {
    return FloorLearn::kInconsistent;
  }
  if (own < needed) {
    return FloorLearn::kNotUniform;
  }
  if (!model_.valid) {
    if (params_.confirm_separation_rad <= 0.0F) {
      model_ = candidate;
      return FloorLearn::kLearned;
    }
    // The waiting region that agrees best from far enough away, if any.
    std::size_t best = kPendingSlots;
    bool agrees_nearby = false;
    for (std::size_t j = 0; j < kPendingSlots; ++j) {
      if (!pending_[j].valid || pending[j] < needed) continue;
      if (candidate.textured) {
        // Textures agree both ways: the waiting region's colours are the candidate's too
        // (a region half floor, half wall holds all of a floor's colours, not the reverse).
        float covered = 0.0F;
        for (std::size_t b = 0; b < kFloorBins; ++b) {
          covered += candidate.share[b] >= params_.texture_min_share ? pending_[j].mass[b] : 0.0F;
        }
        if (covered < params_.consistency_min) continue;
      }
      const float apart =
          std::fabs(std::remainder(pan_rad - pending_pan_rad_[j], core::kTwoPi<float>));
      if (apart < params_.confirm_separation_rad) {
        agrees_nearby = true;
      } else if (best == kPendingSlots || pending[j] > pending[best]) {
        best = j;
      }
    }
    if (best < kPendingSlots) {
      // Two directions agree: the floor. The model starts between their two regions.
      const FloorModel& other = pending_[best];
      model_ = other;
      for (std::size_t c = 0; c < 3; ++c) {
        model_.median[c] = 0.5F * (other.median[c] + candidate.median[c]);
        model_.tolerance[c] = 0.5F * (other.tolerance[c] + candidate.tolerance[c]);
      }
      if (model_.textured) {
        for (std::size_t b = 0; b < kFloorBins; ++b) {
          model_.mass[b] = 0.5F * (other.mass[b] + candidate.mass[b]);
        }
        smooth_mass(model_.mass, model_.share);
        model_.max_run_m = 0.5F * (other.max_run_m + candidate.max_run_m);
      }
      pending_.fill(FloorModel{});
      return FloorLearn::kLearned;
    }
    if (!agrees_nearby) {
      // A region unlike every waiting one (or the first) waits too; the oldest gives way.
      pending_[pending_next_] = candidate;
      pending_pan_rad_[pending_next_] = pan_rad;
      pending_next_ = (pending_next_ + 1) % kPendingSlots;
    }
    return FloorLearn::kPending;
  }
  const float w = params_.learn_rate;
  if (model_.textured) {
    for (std::size_t b = 0; b < kFloorBins; ++b) {
      model_.mass[b] += w * (candidate.mass[b] - model_.mass[b]);
    }
    smooth_mass(model_.mass, model_.share);
    if (candidate.textured) {
      model_.max_run_m += w * (candidate.max_run_m - model_.max_run_m);
    }
    return FloorLearn::kUpdated;
  }
  for (std::size_t c = 0; c < 3; ++c) {
    model_.median[c] += w * (candidate.median[c] - model_.median[c]);
    model_.tolerance[c] += w * (candidate.tolerance[c] - model_.tolerance[c]);
  }
  return FloorLearn::kUpdated;
}

bool FloorCue::textured_candidate(std::size_t count, FloorModel& candidate) {
  candidate.mass.fill(0.0F);
  near_mass_.fill(0.0F);
  far_mass_.fill(0.0F);
  const float each = 1.0F / static_cast<float>(count);
  const float mid_m = 0.5F * (params_.reference_min_m + params_.reference_max_m);
  std::size_t near = 0;
  for (std::size_t i = 0; i < count; ++i) {
    const std::array<float, 3> values{static_cast<float>(reference_[i][0]),
                                      static_cast<float>(reference_[i][1]) - 128.0F,
                                      static_cast<float>(reference_[i][2]) - 128.0F};
    const std::size_t b = bin_of(values);
    candidate.mass[b] += each;
    const bool is_near = reference_rho_m_[i] < mid_m;
    (is_near ? near_mass_ : far_mass_)[b] += 1.0F;
    near += is_near ? 1U : 0U;
  }
  smooth_mass(candidate.mass, candidate.share);
  candidate.textured = true;
  // One texture: each half's pixels lie in colours the other half holds too.
  const auto covered = [&](const std::array<float, kFloorBins>& of, std::size_t of_n,
                           const std::array<float, kFloorBins>& by, std::size_t by_n) {
    for (std::size_t b = 0; b < kFloorBins; ++b) half_mass_[b] = by[b] / static_cast<float>(by_n);
    smooth_mass(half_mass_, half_share_);
    float inside = 0.0F;
    for (std::size_t b = 0; b < kFloorBins; ++b) {
      inside += half_share_[b] >= params_.texture_min_share ? of[b] : 0.0F;
    }
    return inside >= params_.consistency_min * static_cast<float>(of_n);
  };
  const std::size_t far = count - near;
  const bool one_texture = near > 0 && far > 0 && covered(near_mass_, near, far_mass_, far) &&
                           covered(far_mass_, far, near_mass_, near);
  const auto differ = [&](std::size_t i, std::size_t c) {
    return std::fabs(static_cast<float>(reference_[i][c]) -
                     static_cast<float>(reference_[i - 1][c]));
  };
  // A change of colour: the luma steps between row neighbours beyond the luma minimum, and
  // half their median (a patch's edge falls between pixels as often as on one, so the step
  // it makes is often split in two).
  std::array<std::uint32_t, 256> steps{};
  std::size_t step_count = 0;
  for (std::size_t i = 1; i < count; ++i) {
    const float dy = differ(i, 0);
    if (reference_step_m_[i] >= 0.0F && dy > params_.min_tolerance_luma) {
      ++steps[static_cast<std::size_t>(dy)];
      ++step_count;
    }
  }
  float luma_change = params_.min_tolerance_luma;
  for (std::size_t b = 0, seen = 0; b < steps.size() && step_count > 0; ++b) {
    seen += steps[b];
    if (2 * seen >= step_count) {
      luma_change = std::max(luma_change, 0.5F * static_cast<float>(b));
      break;
    }
  }
  candidate.tolerance = {luma_change, params_.min_tolerance_chroma, params_.min_tolerance_chroma};
  // Runs of one colour along the rows, by whole cm of floor up to 1 m and beyond, each
  // weighted by its length: the percentile is of the floor the runs cover, so the patches'
  // blurred edges (runs of a pixel or two, many of them) do not hide the large patches.
  std::array<std::uint32_t, kRunBins> runs{};
  std::size_t run_count = 0;
  std::size_t pairs = 0;
  std::size_t changes = 0;
  float run_m = 0.0F;
  const auto end_run = [&]() {
    if (run_m > 0.0F) {
      const auto cm = static_cast<std::size_t>(std::lround(100.0F * run_m));
      runs[std::min(cm, kRunBins - 1)] += static_cast<std::uint32_t>(cm);
      run_count += cm;
    }
    run_m = 0.0F;
  };
  // A run's colour is its first pixel's, as along a walk.
  std::size_t first = 0;
  const auto apart = [&](std::size_t i, std::size_t c) {
    return std::fabs(static_cast<float>(reference_[i][c]) -
                     static_cast<float>(reference_[first][c]));
  };
  for (std::size_t i = 0; i < count; ++i) {
    if (i == 0 || reference_step_m_[i] < 0.0F) {
      end_run();  // a row (or a stretch of one) begins
      first = i;
      continue;
    }
    ++pairs;
    changes += differ(i, 0) > luma_change || differ(i, 1) > params_.min_tolerance_chroma ||
                       differ(i, 2) > params_.min_tolerance_chroma
                   ? 1U
                   : 0U;
    if (apart(i, 0) > luma_change || apart(i, 1) > params_.min_tolerance_chroma ||
        apart(i, 2) > params_.min_tolerance_chroma) {
      end_run();
      first = i;
    } else {
      run_m += reference_step_m_[i];
    }
  }
  end_run();
  std::size_t p95 = 0;
  for (std::size_t seen = 0; p95 + 1 < kRunBins; ++p95) {
    seen += runs[p95];
    if (20 * seen >= 19 * run_count) break;
  }
  candidate.max_run_m = std::clamp(params_.texture_run_factor * 0.01F * static_cast<float>(p95),
                                   params_.texture_run_min_m, params_.texture_run_max_m);
  return one_texture && pairs > 0 &&
         static_cast<float>(changes) >= params_.texture_min_edges * static_cast<float>(pairs);
}

bool FloorCue::sight_floor_point(const CameraPose& pose, float azimuth_rad, float elevation_rad,
                                 Eigen::Vector3f& point, float& rho_m) const {
  if (!(elevation_rad < -1e-4F)) {
    return false;  // at or above the horizon
  }
  const float floor_z = -rig_.params().ptu_height_m;  // the floor in the PTU frame [m]
  const float s = (pose.centre_m.z() - floor_z) / std::tan(-elevation_rad);  // along the floor
  point = Eigen::Vector3f(pose.centre_m.x() + s * std::cos(azimuth_rad),
                          pose.centre_m.y() + s * std::sin(azimuth_rad), floor_z);
  rho_m = std::sqrt(point.x() * point.x() + point.y() * point.y());
  return true;
}

FloorCueResult FloorCue::process(const image::LowResFrame& frame, float pan_rad, float tilt_rad,
                                 core::FixedVectorBase<evidence::Reading>& obstacles,
                                 core::FixedVectorBase<evidence::Reading>& free,
                                 core::FixedVectorBase<float>* free_near_m,
                                 core::FixedVectorBase<evidence::Reading>* blocked) {
  const std::size_t pixels = std::size_t{frame.width} * frame.height;
  if (!model_.valid) {
    FloorCueResult result;
    if (pixels == 0) return result;
    if (deferred_count_ < kDeferredSlots && pixels <= kDeferredPixels) {
      DeferredFrame& d = deferred_[deferred_count_++];
      d.width = frame.width;
      d.height = frame.height;
      d.pan_rad = pan_rad;
      d.tilt_rad = tilt_rad;
      std::transform(frame.luma.begin(), frame.luma.begin() + static_cast<std::ptrdiff_t>(pixels),
                     d.luma.begin(), [](float y) {
                       return static_cast<std::uint8_t>(std::lround(std::clamp(y, 0.0F, 255.0F)));
                     });
      std::copy_n(frame.chroma_u.begin(), pixels, d.chroma_u.begin());
      std::copy_n(frame.chroma_v.begin(), pixels, d.chroma_v.begin());
      result.deferred = true;
    } else {
      result.deferred_dropped = true;
    }
    return result;
  }
  FloorCueResult total;
  // One kept frame per call (oldest first), so that no call walks more than two frames.
  if (deferred_next_ < deferred_count_) {
    const DeferredFrame& d = deferred_[deferred_next_++];
    const std::size_t n = std::size_t{d.width} * d.height;
    scratch_.width = d.width;
    scratch_.height = d.height;
    std::transform(d.luma.begin(), d.luma.begin() + static_cast<std::ptrdiff_t>(n),
                   scratch_.luma.begin(), [](std::uint8_t y) { return static_cast<float>(y); });
    std::copy_n(d.chroma_u.begin(), n, scratch_.chroma_u.begin());
    std::copy_n(d.chroma_v.begin(), n, scratch_.chroma_v.begin());
    add_walk(walk(scratch_, d.pan_rad, d.tilt_rad, obstacles, free, free_near_m, blocked), total);
    ++total.deferred_walked;
    if (deferred_next_ == deferred_count_) deferred_next_ = deferred_count_ = 0;
  }
  const FloorCueResult r = walk(frame, pan_rad, tilt_rad, obstacles, free, free_near_m, blocked);
  add_walk(r, total);
  total.columns = r.columns;  // the columns (and column()) are this frame's
  total.model_valid = r.model_valid;
  return total;
}

FloorCueResult FloorCue::walk(const image::LowResFrame& frame, float pan_rad, float tilt_rad,
                              core::FixedVectorBase<evidence::Reading>& obstacles,
                              core::FixedVectorBase<evidence::Reading>& free,
                              core::FixedVectorBase<float>* free_near_m,
                              core::FixedVectorBase<evidence::Reading>* blocked) {
  FloorCueResult result;
  column_count_ = 0;
  result.model_valid = model_.valid;
  if (!model_.valid || frame.width == 0 || frame.height == 0) {
    return result;
  }
  const CameraPose pose = rig_.camera_pose(pan_rad, tilt_rad);
  const CameraIntrinsics& camera = rig_.low_res_camera();
  const float floor_h = -rig_.params().ptu_height_m;
  const std::uint32_t k = params_.boundary_run;
  // One image row per step near the image centre [rad]; the walk needs at most ~2 per row.
  const float step_rad = 1.0F / camera.focal_px;
  const auto max_steps = 2U * frame.height;
  // The walks' azimuths: spread along the highest image row whose centre still sees the
  // floor within max range (vertical planes fan out upwards in a tilted-down image, so
  // walks taken from the bottom row would leave the image at its sides early).
  std::uint32_t azimuth_row = frame.height - 1;
  for (std::uint32_t v = 0; v < frame.height; ++v) {
    Eigen::Vector3f point;
    float rho = 0.0F;
    if (floor_point(pose, 0.5F * static_cast<float>(frame.width - 1), static_cast<float>(v), point,
                    rho) &&
        rho <= params_.max_range_m) {
      azimuth_row = v;
      break;
    }
  }
  // Pixel positions the walk samples: those that round to a pixel of the frame.
  const auto in_frame = [&](const Eigen::Vector2f& pixel) {
    return pixel.x() >= -0.49F && pixel.y() >= -0.49F &&
           pixel.x() <= static_cast<float>(frame.width) - 0.51F &&
           pixel.y() <= static_cast<float>(frame.height) - 0.51F;
  };
  const auto inside = [&](float azimuth, float elevation) {
    const Eigen::Vector3f dir(std::cos(elevation) * std::cos(azimuth),
                              std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
    Eigen::Vector2f pixel;
    return RigModel::project_ptu(pose, camera, pose.centre_m + dir, pixel) && in_frame(pixel);
  };
  for (std::uint32_t u = 0; u < frame.width && column_count_ < kMaxColumns;
       u += params_.column_step) {
    FloorColumn& col = columns_[column_count_++];
    col = FloorColumn{};
    col.u_px = u;
    // The walk: up the vertical plane through the optical centre and pixel (u, azimuth_row),
    // so a vertical obstacle edge stays on one side of it (image columns are not vertical
    // planes once the camera is tilted), from where that plane leaves the image below.
    const Eigen::Vector3f ray = RigModel::ray_ptu(
        pose, camera, Eigen::Vector2f(static_cast<float>(u), static_cast<float>(azimuth_row)));
    const float azimuth = std::atan2(ray.y(), ray.x());
    float elevation0 = std::atan2(ray.z(), std::hypot(ray.x(), ray.y()));
    // The plane's image is one segment of the image: bisect for its lower end.
    float outside = -1.55F;  // [rad], nearly straight down: below every image of this rig
    if (inside(azimuth, elevation0)) {
      for (int i = 0; i < 14; ++i) {
        const float mid = 0.5F * (outside + elevation0);
        (inside(azimuth, mid) ? elevation0 : outside) = mid;
      }
    }
    col.azimuth_rad = core::wrap_two_pi(azimuth);
    bool have_floor = false;  // a floor pixel connected to the bottom
    Eigen::Vector3f free_point = Eigen::Vector3f::Zero();
    Eigen::Vector3f near_point = Eigen::Vector3f::Zero();  // the walk's bottom-row floor point
    std::uint32_t run = 0;
    std::uint32_t run_start = 0;  // step of the first non-floor pixel of the run
    std::array<float, kMaxRun> run_contrast{};
    // A textured floor: the stretch of one colour the walk is in, from its first sample, and
    // the changes of colour in a row that led into it (an edge blurred over a few pixels):
    // the stretch's thing begins where they began.
    const bool textured = model_.textured;
    Eigen::Vector3f stretch_point = Eigen::Vector3f::Zero();
    std::array<float, 3> stretch_values{};
    std::array<float, 3> last_values{};
    bool last_same = false;
    std::uint32_t ramp_start = 0;
    Eigen::Vector3f free_before_ramp = Eigen::Vector3f::Zero();  // the floor seen before it
    bool floor_before_ramp = false;
    std::uint32_t stretch_base = 0;
    Eigen::Vector3f free_before_stretch = Eigen::Vector3f::Zero();
    bool floor_before_stretch = false;
    bool stretched = false;  // the walk ended at a stretch too long for the floor
    Eigen::Vector3f walked_point = Eigen::Vector3f::Zero();  // the last sample's floor point
    col.end = FloorColumn::End::kImageEdge;
    for (std::uint32_t step = 0; step < max_steps; ++step) {
      const float elevation = elevation0 + static_cast<float>(step) * step_rad;
      Eigen::Vector3f point;
      float rho = 0.0F;
      if (!sight_floor_point(pose, azimuth, elevation, point, rho) || rho > params_.max_range_m) {
        col.end = FloorColumn::End::kMaxRange;
        break;
      }
      if (step == 0) {
        col.near_rho_m = rho;
        near_point = point;
      }
      Eigen::Vector2f pixel;
      if (!RigModel::project_ptu(pose, camera, point, pixel)) {
        break;
      }
      // The two pixels either side of the walk on its row: floor only if both are, so an
      // obstacle edge within a pixel of the walk stops it (errs towards the obstacle).
      if (!in_frame(pixel)) {
        break;  // left the image: at its top or side
      }
      const long pv = std::lround(pixel.y());
      const long left =
          std::clamp(std::lround(std::floor(pixel.x())), 0L, static_cast<long>(frame.width) - 2);
      const auto row = static_cast<std::uint32_t>(pv);
      std::array<float, 3> values{};  // the left pixel's, vignetting undone
      std::array<float, 3> values_right{};
      pixel_values(frame, static_cast<std::uint32_t>(left), row, values);
      pixel_values(frame, static_cast<std::uint32_t>(left + 1), row, values_right);
      const float contrast_left = contrast_to(model_, values);
      const float contrast_right = contrast_to(model_, values_right);
      const bool floor_left = contrast_left <= 1.0F;
      const bool floor_right = contrast_right <= 1.0F;
      const float contrast = std::max(contrast_left, contrast_right);
      if (textured) {
        walked_point = point;
        // One colour: within the change tolerances of the last sample, and within twice them
        // of the stretch's first (a blurred, distant texture drifts; a plain face does not).
        bool same = step > 0;
        for (std::size_t c = 0; c < 3 && same; ++c) {
          same = std::fabs(values[c] - last_values[c]) <= model_.tolerance[c] &&
                 std::fabs(values[c] - stretch_values[c]) <= 2.0F * model_.tolerance[c];
        }
        last_values = values;
        if (!same) {
          if (last_same || step == 0) {
            ramp_start = step;
            free_before_ramp = free_point;
            floor_before_ramp = have_floor;
          }
          stretch_point = point;
          stretch_values = values;
          stretch_base = ramp_start;
          free_before_stretch = free_before_ramp;
          floor_before_stretch = floor_before_ramp;
        } else if ((point - stretch_point).norm() > model_.max_run_m) {
          // One colour for longer than the floor's patches: a plain thing stands there,
          // from where the colour began to change to it.
          run_start = stretch_base;
          free_point = free_before_stretch;
          have_floor = floor_before_stretch;
          col.end = FloorColumn::End::kBoundary;
          stretched = true;
          break;
        }
        last_same = same;
      }
      if (floor_left && floor_right) {
        run = 0;
        have_floor = true;
        free_point = point;
        continue;
      }
      if (run == 0) {
        run_start = step;
      }
      run_contrast[run++] = contrast;
      if (run >= k) {
        col.end = FloorColumn::End::kBoundary;
        break;
      }
    }
    if (textured && !stretched && col.end != FloorColumn::End::kBoundary &&
        (walked_point - stretch_point).norm() > 0.5F * model_.max_run_m) {
      // The walk ended (max range, the image's edge) in a long stretch of one colour, which
      // may yet be a plain thing: the floor is free up to where it began.
      free_point = free_before_stretch;
      have_floor = floor_before_stretch;
    }
    if (col.end == FloorColumn::End::kBoundary && run_start == 0) {
      // Not floor from the first row: the obstacle may be anywhere nearer; say nothing.
      col.end = FloorColumn::End::kBlockedAtBottom;
    }
    if (col.end == FloorColumn::End::kBoundary && stretched && !params_.texture_obstacles) {
      // The floor seen ends here; nothing is said of what stands there.
      const float elevation = elevation0 + (static_cast<float>(run_start) - 0.5F) * step_rad;
      Eigen::Vector3f base;
      float rho = 0.0F;
      if (sight_floor_point(pose, azimuth, elevation, base, rho)) col.base_rho_m = rho;
    } else if (col.end == FloorColumn::End::kBoundary) {
      // The base: between the last floor sample and the first obstacle sample.
      const float elevation = elevation0 + (static_cast<float>(run_start) - 0.5F) * step_rad;
      Eigen::Vector3f base;
      float rho = 0.0F;
      if (sight_floor_point(pose, azimuth, elevation, base, rho)) {
        const float c = stretched ? params_.clear_contrast : median_of(run_contrast, k);
        const float ramp =
            std::clamp((c - 1.0F) / std::max(params_.clear_contrast - 1.0F, 1e-3F), 0.0F, 1.0F);
        const float m =
            params_.evidence_weak + ramp * (params_.evidence_clear - params_.evidence_weak);
        col.base_rho_m = rho;
        col.evidence = m;
        ++result.boundaries;
        for (std::uint32_t i = 0; i < params_.obstacle_height_count; ++i) {
          const Eigen::Vector3f p(base.x(), base.y(), floor_h + params_.obstacle_heights_m[i]);
          if (obstacles.push_back(reading_from_point(p, m, pose.centre_m))) {
            ++result.obstacle_readings;
          } else {
            result.truncated = true;
          }
        }
      } else {
        col.end = FloorColumn::End::kBlockedAtBottom;
      }
    }
    if (col.end == FloorColumn::End::kBlockedAtBottom && blocked != nullptr) {
      // Something stands on the floor somewhere nearer than the bottom row's floor point.
      if (blocked->push_back(
              reading_from_point(near_point, params_.evidence_weak, pose.centre_m))) {
        ++result.blocked_readings;
      } else {
        result.truncated = true;
      }
    }
    if (have_floor) {
      col.free_rho_m = std::hypot(free_point.x(), free_point.y());
      // With free_near_m, the walk's near end goes with it, or neither is kept.
      if (free_near_m != nullptr && free_near_m->size() != free.size()) {
        result.truncated = true;  // the caller's lists are out of step: add to neither
      } else if (free.push_back(reading_from_point(free_point, 0.0F, pose.centre_m))) {
        if (free_near_m == nullptr || free_near_m->push_back(col.near_rho_m)) {
          ++result.free_readings;
        } else {
          free.pop_back();
          result.truncated = true;
        }
      } else {
        result.truncated = true;
      }
    }
  }
  result.columns = column_count_;
  return result;
}

bool FloorCue::floor_coverage(float tilt_rad, float& near_m, float& far_m) const {
  const CameraPose pose = rig_.camera_pose(0.0F, tilt_rad);
  const CameraIntrinsics& camera = rig_.low_res_camera();
  const std::uint32_t centre_column = camera.width_px / 2;  // the middle column, a whole pixel
  const auto u = static_cast<float>(centre_column);
  near_m = std::numeric_limits<float>::infinity();
  far_m = 0.0F;
  bool any = false;
  for (std::uint32_t v = 0; v < camera.height_px; ++v) {
    Eigen::Vector3f point;
    float rho = 0.0F;
    if (floor_point(pose, u, static_cast<float>(v), point, rho)) {
      any = true;
      near_m = std::min(near_m, rho);
      far_m = std::max(far_m, rho);
    } else {
      far_m = std::numeric_limits<float>::infinity();
    }
  }
  return any;
}

}  // namespace boticelli::stereo
