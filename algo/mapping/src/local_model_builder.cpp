// Think stage of one look (see local_model_builder.h): samples, resumable fit, guard, polygon.
#include "algo/mapping/local_model_builder.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "algo/core/angles.h"
#include "algo/evidence/occupancy_model.h"
#include "algo/mapping/polygon_ops.h"

namespace boticelli::mapping {
namespace {

using evidence::horizontal_m;

// The robot's disc and its clearance margin, a little more so the shrunk polygon keeps a point:
// free at every look (the robot stands there).
float own_disc_m(const ExtractionParams& p) {
  return p.robot_radius_m + p.clearance_margin_m + 0.02F;
}

// A walk that started this much nearer than a blocked one in the same vertex ray saw the
// floor before the blocked row (two frames' bottom rows, or two columns, differ) [m].
constexpr float kBlockedTolerance_m = 0.02F;
// Evidence of an obstacle this far beyond a blocked walk's bottom-row floor point can still be
// what blocks it: a wall's features scatter about its base by the stereo's range error [m].
constexpr float kBlockedEvidenceSlack_m = 0.1F;
// ... and on the vertex rays this many either side of a blocked one.
constexpr std::size_t kBlockedEvidenceRays = 2;
// A blocked ray is followed through the prior look's free polygon in steps this long [m].
constexpr float kPriorStep_m = 0.02F;

// How far along direction θ (robot frame) from `from_m` to `to_m` the prior look's free
// polygon (standing at `prior_pose` in the robot frame) holds every step: `from_m` if it
// does not hold the first.
float prior_free_reach_m(const StarPolygon& prior_free, const core::Pose2& prior_pose,
                         float theta_rad, float from_m, float to_m) {
  const float c = std::cos(theta_rad);
  const float s = std::sin(theta_rad);
  float reach = from_m;
  for (float d = from_m; d <= to_m; d += kPriorStep_m) {
    if (!prior_free.contains(core::to_robot(prior_pose, {d * c, d * s}))) break;
    reach = d;
  }
  return reach;
}

}  // namespace

void LocalModelBuilder::start(const LocalModelParams& params,
                              std::span<const evidence::Reading> features,
                              std::span<const evidence::Reading> floor_obstacles,
                              std::span<const evidence::Reading> floor_free,
                              std::span<const float> floor_free_near_m,
                              std::span<const evidence::Reading> floor_blocked, PriorLook prior) {
  params_ = params;
  features_ = features;
  obstacles_ = floor_obstacles;
  free_ = floor_free;
  blocked_ = floor_blocked;
  prior_free_ = prior.free;
  prior_pose_ = core::compose(core::inverse(prior.here), prior.pose);
  // Out of step with the free readings: not used (every walk then counts as joined).
  free_near_ =
      floor_free_near_m.size() == floor_free.size() ? floor_free_near_m : std::span<const float>{};
  cursor_ = 0;
  ray_samples_.clear();
  samples_.clear();
  candidates_.clear();
  guard_.clear();
  stats_ = LocalModelStats{};
  map_.can_move = false;
  evidence::configure_occupancy_model(
      model_, params.model_lowest_h_m, params.model_highest_h_m, params.model_max_range_m,
      evidence::alpha_slope_bound_per_rad(params.rays.delta_r_fraction));
  phase_ = Phase::kSamples;
}

void LocalModelBuilder::add_reading_samples(const evidence::Reading& reading) {
  if (!(reading.r_m > 0.0F) || !(reading.r_m <= params_.model_max_range_m) ||
      !(reading.h_m >= params_.model_lowest_h_m && reading.h_m <= params_.model_highest_h_m)) {
    return;  // outside the model's box: the limits filter such readings before
  }
  (void)evidence::append_plausibility_samples(reading, params_.rays, ray_samples_);
}

void LocalModelBuilder::add_free_samples(const evidence::Reading& reading) {
  if (!(reading.r_m > 0.0F)) return;
  const std::size_t n = std::max<std::size_t>(params_.free_samples_per_ray, 1);
  const float r_end = std::min(reading.r_m, params_.model_max_range_m);
  for (std::size_t j = 1; j <= n; ++j) {
    // Evenly along the line of sight, the last a little short of the floor point.
    const float s = r_end * (0.95F * static_cast<float>(j) / static_cast<float>(n));
    const float h = reading.h_m * (s / reading.r_m);
    if (!ray_samples_.push_back({reading.alpha_rad, h, s, 0.0F})) return;
  }
}

bool LocalModelBuilder::run_unit() {
  ++stats_.units;
  switch (phase_) {
    case Phase::kIdle:
    case Phase::kDone:
      return phase_ == Phase::kDone;
    case Phase::kSamples: {
      // Features, then floor obstacles, then free floor rays, a few per unit.
      const std::size_t total = features_.size() + obstacles_.size() + free_.size();
      const std::size_t end = std::min(total, cursor_ + params_.readings_per_unit);
      for (; cursor_ < end; ++cursor_) {
        if (cursor_ < features_.size()) {
          add_reading_samples(features_[cursor_]);
        } else if (cursor_ < features_.size() + obstacles_.size()) {
          add_reading_samples(obstacles_[cursor_ - features_.size()]);
        } else {
          add_free_samples(free_[cursor_ - features_.size() - obstacles_.size()]);
        }
      }
      if (cursor_ == total) {
        phase_ = Phase::kSeam;
      }
      return false;
    }
    case Phase::kSeam: {
      (void)evidence::append_seam_copies(ray_samples_, params_.seam_margin_rad);
      for (const evidence::RaySample& s : ray_samples_) {
        OccupancySample a;
        a.x = Eigen::Vector3f(s.alpha_rad, s.h_m, s.r_m);
        a.y = s.occupancy;
        if (!samples_.push_back(a)) break;
      }
      stats_.samples = samples_.size();
      trainer_.configure(params_.trainer);
      if (!trainer_.start(aln::SampleSet<float, 3>(samples_.data(), samples_.size()), model_)) {
        phase_ = Phase::kGuard;  // nothing seen: no model; nothing is free
        return false;
      }
      phase_ = Phase::kTrain;
      return false;
    }
    case Phase::kTrain:
      if (trainer_.run_unit(params_.visits_per_unit)) {
        stats_.pieces = model_.piece_count();
        stats_.rms = trainer_.stats().rms;
        phase_ = Phase::kGuard;
      }
      return false;
    case Phase::kGuard:
      // The inverted model, then the feature guard (§5.4.3) in three units: the features the
      // model leaves unexplained, the floor obstacles, and their corroboration.
      stats_.model_valid =
          samples_.size() > 0 && free_range_.set_model(model_, params_.extraction.safe_occupancy);
      phase_ = Phase::kGuardFeatures;
      return false;
    case Phase::kGuardFeatures:
    case Phase::kGuardObstacles: {
      const auto occupancy = [this](float a, float h, float r) { return this->occupancy(a, h, r); };
      const bool features = phase_ == Phase::kGuardFeatures;
      const std::size_t lost =
          collect_unexplained_features(features ? features_ : obstacles_, occupancy,
                                       params_.extraction, params_.guard, candidates_, !features);
      stats_.guard_dropped += lost;
      if (!features) {
        sort_guard_candidates(candidates_.span());
      }
      phase_ = features ? Phase::kGuardObstacles : Phase::kGuardPoints;
      guard_cursor_ = 0;
      return false;
    }
    case Phase::kGuardPoints: {
      // A bounded slice of the candidates (sorted by x) per unit, each against its reach.
      const std::size_t end =
          std::min(candidates_.size(), guard_cursor_ + params_.guard_candidates_per_unit);
      const std::size_t before = guard_.size();
      if (!corroborated_points(candidates_.span(), guard_cursor_, end, params_.guard, guard_)) {
        stats_.guard_points_full = true;
      }
      stats_.guard_corroborated += guard_.size() - before;
      if (!(params_.guard_disc_m > 0.0F)) {
        // Only the points that can cut the polygon or be a vertex ray's nearest evidence
        // (exact for points; a disc's cut depends on more than its sector's nearest point).
        guard_.resize(keep_points_that_cut(guard_.span(), params_.extraction.vertex_count));
      }
      guard_cursor_ = end;
      if (guard_cursor_ == candidates_.size()) {
        stats_.guard_candidates = candidates_.size();
        stats_.guard_points = guard_.size();
        phase_ = Phase::kExtract;
      }
      return false;
    }
    case Phase::kExtract:
      extract();
      phase_ = Phase::kDone;
      return true;
  }
  return false;
}

float LocalModelBuilder::occupancy(float alpha_rad, float h_m, float r_m) const {
  if (samples_.size() == 0) return 0.0F;
  return static_cast<float>(model_(OccupancyModel::Vec(alpha_rad, h_m, r_m)));
}

void LocalModelBuilder::build_seen_free() {
  const ExtractionParams& p = params_.extraction;
  seen_free_.set_vertex_count(p.vertex_count);
  // The line of sight to a free floor point is free; so is the floor up to an obstacle's
  // base (less its range error) and the body band up to a feature seen inside it.
  auto see = [&](float alpha, float rho) {
    const std::size_t k = nearest_vertex(seen_free_, alpha);
    seen_free_.set_rho_m(k, std::max(seen_free_.rho_m(k), std::min(rho, p.bounding_radius_m)));
  };
  const float dr = params_.rays.delta_r_fraction;
  if (free_near_.empty()) {
    for (const evidence::Reading& r : free_) see(r.alpha_rad, horizontal_m(r));
    for (const evidence::Reading& r : obstacles_) see(r.alpha_rad, horizontal_m(r) * (1.0F - dr));
  } else {
    // Walks joined to the robot, outwards: a pass joins every walk that starts within reach
    // of its direction, until a pass joins none. Walks of one direction overlap (a low view
    // sees from 0.3 m to the wall), so two or three passes do; the bound keeps a unit short,
    // and a chain it cuts is left shorter (less free), never longer. A boundary walk's free
    // reading is its last floor sample, just before the base.
    constexpr std::size_t kMaxJoinPasses = 8;
    bool joined = true;
    for (std::size_t pass = 0; joined && pass < kMaxJoinPasses; ++pass) {
      joined = false;
      for (std::size_t i = 0; i < free_.size(); ++i) {
        const evidence::Reading& r = free_[i];
        const std::size_t k = nearest_vertex(seen_free_, r.alpha_rad);
        const float reach = seen_free_.rho_m(k);
        const float far = std::min(horizontal_m(r), p.bounding_radius_m);
        const float start_limit =
            std::max(params_.seen_floor_start_m, reach + params_.seen_floor_gap_m);
        if (far > reach && free_near_[i] <= start_limit) {
          seen_free_.set_rho_m(k, far);
          joined = true;
        }
      }
    }
  }
  const float h_lo = slice_height_m(p, 0);
  const float h_hi = slice_height_m(p, p.height_count == 0 ? 0 : p.height_count - 1);
  const std::span<const evidence::Reading> band_features =
      params_.features_show_free ? features_ : std::span<const evidence::Reading>{};
  for (const evidence::Reading& r : band_features) {
    if (r.h_m >= h_lo && r.h_m <= h_hi && r.m >= p.safe_occupancy) {
      see(r.alpha_rad, horizontal_m(r) * (1.0F - 2.0F * dr));
    }
  }
  // A vertex no reading fell on (a gap between image columns) takes the smaller of its
  // nearest seen neighbours when they are close; a wider gap stays unknown (0).
  constexpr std::size_t kMaxGap = 3;
  const std::size_t n = seen_free_.vertex_count();
  scratch_.set_vertex_count(n);
  for (std::size_t k = 0; k < n; ++k) scratch_.set_rho_m(k, seen_free_.rho_m(k));
  for (std::size_t k = 0; k < n; ++k) {
    if (scratch_.rho_m(k) > 0.0F) continue;
    float left = 0.0F;
    float right = 0.0F;
    std::size_t dl = 1;
    for (; dl <= kMaxGap && left <= 0.0F; ++dl) left = scratch_.rho_m((k + n - dl) % n);
    std::size_t dr_i = 1;
    for (; dr_i <= kMaxGap && right <= 0.0F; ++dr_i) right = scratch_.rho_m((k + dr_i) % n);
    if (left > 0.0F && right > 0.0F) seen_free_.set_rho_m(k, std::min(left, right));
  }
  // The robot stands on its own disc: that much is free whatever was seen (an unseen sector
  // must not pin the robot where it is; the shrink still keeps it off the unknown). After the
  // gap fill, which looks for unseen (0) vertices.
  const float own = own_disc_m(p);
  for (std::size_t k = 0; k < seen_free_.vertex_count(); ++k) {
    seen_free_.set_rho_m(k, std::max(seen_free_.rho_m(k), own));
  }
}

void LocalModelBuilder::extract() {
  const ExtractionParams& p = params_.extraction;
  if (stats_.model_valid) {
    extract_free_polygon(free_range_, p, obstacle_polygon_, scratch_);
    // The robot stands on its own disc, and the step that brought it here kept the disc and
    // its margin inside the last look's navigable polygon: a crossing of the fit nearer than
    // that is the fit's extrapolation into space no line of sight crosses (near a wall the
    // body's top slice, 0.2 m over the PTU, is in view only from 0.62 m on), not evidence.
    // Evidence still cuts nearer: guard points and floor-cue bases, below.
    const float own = own_disc_m(p);
    for (std::size_t k = 0; k < obstacle_polygon_.vertex_count(); ++k) {
      obstacle_polygon_.set_rho_m(k, std::max(obstacle_polygon_.rho_m(k), own));
    }
  } else {
    obstacle_polygon_.set_vertex_count(p.vertex_count);  // nothing known: nothing free
  }
  exclude_discs(guard_.span(), params_.guard_disc_m, obstacle_polygon_);
  // The floor cue's obstacle bases are obstacles whatever the fit says: nothing beyond a
  // base along its ray is free at the robot's lowest slice.
  for (const evidence::Reading& r : obstacles_) {
    const std::size_t k = nearest_vertex(obstacle_polygon_, r.alpha_rad);
    const float base = std::max(horizontal_m(r) - params_.base_margin_m, 0.0F);
    obstacle_polygon_.set_rho_m(k, std::min(obstacle_polygon_.rho_m(k), base));
  }
  // Nearest evidence of an obstacle per vertex ray (for the blocked walks and the map points).
  evidence_.set_vertex_count(p.vertex_count);
  evidence_.fill(std::numeric_limits<float>::infinity());
  auto evidence_at = [&](float alpha, float rho) {
    const std::size_t k = nearest_vertex(evidence_, alpha);
    evidence_.set_rho_m(k, std::min(evidence_.rho_m(k), rho));
  };
  for (const evidence::Reading& r : obstacles_) evidence_at(r.alpha_rad, horizontal_m(r));
  for (const core::Point2& g : guard_) {
    evidence_at(std::atan2(g.y_m, g.x_m), std::hypot(g.x_m, g.y_m));
  }
  const float h_lo = slice_height_m(p, 0);
  const float h_hi = slice_height_m(p, p.height_count == 0 ? 0 : p.height_count - 1);
  for (const evidence::Reading& r : features_) {
    if (r.h_m >= h_lo && r.h_m <= h_hi && r.m >= p.safe_occupancy) {
      evidence_at(r.alpha_rad, horizontal_m(r));
    }
  }
  // A walk blocked at the bottom row of a view that sees the floor from seen_floor_start_m
  // on: something stands between the robot's disc and that row, which no view sees. Its
  // vertex ray keeps only the robot's disc, unless a walk of another frame started on floor
  // nearer than the blocked row (its own base, above, then cuts where the obstacle is), or
  // evidence of an obstacle (a base, a guard point, a feature in the band) lies on the ray
  // before the row: that is what blocks it, and the ray is cut at it (the robot-radius
  // shrink keeps the clearance; cut 5 cm in front of it, the rays beside a doorway's jamb
  // left the robot no way through). Without such evidence, an earlier look (the prior) that
  // saw the ray's first stretch free keeps that stretch: the obstacle stands still, so it
  // stands beyond.
  blocked_ray_.fill(false);
  if (params_.close_blocked_rays && !blocked_.empty()) {
    scratch_.set_vertex_count(p.vertex_count);
    scratch_.fill(std::numeric_limits<float>::infinity());  // nearest walk start per ray
    for (std::size_t i = 0; i < free_near_.size(); ++i) {
      const std::size_t k = nearest_vertex(scratch_, free_[i].alpha_rad);
      scratch_.set_rho_m(k, std::min(scratch_.rho_m(k), free_near_[i]));
    }
    const float own = own_disc_m(p);
    for (const evidence::Reading& r : blocked_) {
      const float near = horizontal_m(r);
      const std::size_t k = nearest_vertex(obstacle_polygon_, r.alpha_rad);
      if (near > params_.seen_floor_start_m || scratch_.rho_m(k) < near - kBlockedTolerance_m ||
          obstacle_polygon_.rho_m(k) <= own) {
        continue;
      }
      // Features do not fall on every vertex ray: the nearest evidence of the rays around.
      const std::size_t n = evidence_.vertex_count();
      float e = evidence_.rho_m(k);
      for (std::size_t d = 1; d <= kBlockedEvidenceRays; ++d) {
        e = std::min({e, evidence_.rho_m((k + d) % n), evidence_.rho_m((k + n - d) % n)});
      }
      if (e <= near + kBlockedEvidenceSlack_m) {
        const float cut = std::max(e, own);  // the shrink keeps the robot's clearance
        obstacle_polygon_.set_rho_m(k, std::min(obstacle_polygon_.rho_m(k), cut));
      } else {
        float cut = own;
        if (prior_free_ != nullptr) {
          cut = prior_free_reach_m(*prior_free_, prior_pose_, obstacle_polygon_.angle_rad(k), own,
                                   near);
          stats_.blocked_by_prior += cut > own ? 1U : 0U;
        }
        obstacle_polygon_.set_rho_m(k, std::min(obstacle_polygon_.rho_m(k), cut));
        blocked_ray_[k] = true;
      }
      ++stats_.blocked_rays;
    }
  }
  build_seen_free();
  map_.free = obstacle_polygon_;
  if (params_.clamp_to_seen_free) {
    (void)intersect_into(map_.free, seen_free_);
  }
  open_spikes(map_.free, params_.spike_half_width);
  map_.can_move =
      shrink_for_robot(map_.free, p.robot_radius_m, p.clearance_margin_m, map_.navigable);
}

bool LocalModelBuilder::map_points(const MapPointParams& params, PointList& obstacles_robot,
                                   PointList& exploration_robot) const {
  const StarPolygon& free = map_.free;
  const std::size_t n = free.vertex_count();
  const float radius = params_.extraction.bounding_radius_m;
  const float dr = params_.rays.delta_r_fraction;
  auto vertex = [&](std::size_t k) {
    const float rho = free.rho_m(k);
    const float a = free.angle_rad(k);
    return core::Point2{rho * std::cos(a), rho * std::sin(a)};
  };
  // Each vertex: an obstacle (evidence within its range error, and the shrink's margin, of
  // the boundary), on the bounding circle, or unknown (the fit alone, or floor not seen).
  // A ray cut to the robot's disc by a blocked walk (kBlocked) has something on it nearer
  // than the lowest view's bottom row, but not where: neither an obstacle point nor a frontier.
  enum Kind : std::uint8_t { kObstacle, kCircle, kUnknown, kBlocked };
  std::array<Kind, kMaxPolygonVertices> kind{};
  for (std::size_t k = 0; k < n; ++k) {
    const float rho = free.rho_m(k);
    const float e = evidence_.rho_m(k);
    const bool backed = std::isfinite(e) && std::fabs(e - rho) <= 2.0F * dr * e + 0.1F;
    kind[k] = blocked_ray_[k]                                ? kBlocked
              : rho >= radius - params.on_circle_tolerance_m ? kCircle
              : backed                                       ? kObstacle
                                                             : kUnknown;
  }
  // An unknown stretch narrower than min_frontier_width_m (a shadow behind a box, a few
  // vertices the floor cue missed) leads the robot nowhere: no exploration points there.
  std::array<bool, kMaxPolygonVertices> frontier{};
  std::size_t first_obstacle = n;
  for (std::size_t k = 0; k < n && first_obstacle == n; ++k) {
    if (kind[k] != kUnknown) first_obstacle = k;
  }
  if (first_obstacle == n) {
    frontier.fill(true);  // unknown all round
  } else {
    for (std::size_t i = 1; i <= n; ++i) {
      const std::size_t k = (first_obstacle + i) % n;
      if (kind[k] != kUnknown) continue;
      std::size_t len = 0;  // the run of unknown vertices starting at k
      while (len < n && kind[(k + len) % n] == kUnknown) ++len;
      const float width = core::distance_m(vertex(k), vertex((k + len - 1) % n));
      for (std::size_t j = 0; j < len; ++j) {
        frontier[(k + j) % n] = width >= params.min_frontier_width_m;
      }
      i += len - 1;
    }
  }
  bool ok = true;
  core::Point2 last_obstacle{1e9F, 1e9F};
  core::Point2 last_exploration{1e9F, 1e9F};
  for (std::size_t k = 0; k < n; ++k) {
    const float rho = free.rho_m(k);
    const float a = free.angle_rad(k);
    const core::Point2 at = vertex(k);
    if (kind[k] == kObstacle) {
      if (core::distance_m(at, last_obstacle) >= params.obstacle_spacing_m) {
        ok = obstacles_robot.push_back(at) && ok;
        last_obstacle = at;
      }
    } else if ((kind[k] == kCircle || frontier[k]) && rho > params.gap_point_inset_m) {
      const float d = rho - params.gap_point_inset_m;
      const core::Point2 p{d * std::cos(a), d * std::sin(a)};
      if (core::distance_m(p, last_exploration) >= params.exploration_spacing_m) {
        ok = exploration_robot.push_back(p) && ok;
        last_exploration = p;
      }
    }
  }
  return ok;
}

}  // namespace boticelli::mapping
